//! Merge rules weld two sites only when they face each other: their current `out` directions
//! (turned with each instance's pose and rest state) are within 45 degrees of opposite
//! (`merge::FACING_DOT`). Within reach but facing away, or across, they do not weld; a site
//! turned past the threshold stops merging; the live rules (solver frames) agree.

use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::Arc;

use clay::testing::{merge, site_centre, site_out};
use clay::{Assembly, RuleKind, SolverConfig};
use clay_dsl::compiled::{AssemblyData, CompiledGrammar, InstanceSite};
use glam::DVec2;

fn compile(src: &str) -> CompiledGrammar {
    match clay_dsl::compile(src, "test.clay", &clay_dsl::CompileOptions::default()) {
        Ok(c) => c.grammar,
        Err(d) => panic!("test grammar does not compile: {d:?}"),
    }
}

fn file(name: &str) -> CompiledGrammar {
    let path = format!("{}/grammars/{name}", env!("CARGO_MANIFEST_DIR"));
    compile(&std::fs::read_to_string(&path).unwrap())
}

/// Two loose 1 x 0.5 bricks: `a` at the origin (east site centre (1, 0.25), out +x) and `b`
/// at `(bx, 0)`, its west site (out -x) facing `a` head-on.
fn two_bricks(bx: f64) -> CompiledGrammar {
    compile(&format!(
        "site type joint
solver {{ merge_distance = 0.5 }}
piece brick {{
    vertex sw (0, 0)
    vertex se (1, 0)
    vertex ne (1, 0.5)
    vertex nw (0, 0.5)
    edges sw-se-ne-nw-sw, sw-ne
    site west: joint [nw, sw] out (-1, 0)
    site east: joint [se, ne] out (1, 0)
}}
merge brick.east onto brick.west
model {{
    a = brick at (0, 0)
    b = brick at ({bx}, 0)
}}"
    ))
}

fn data_of(g: &CompiledGrammar) -> AssemblyData {
    let mut d = g.assembly.clone();
    if d.parts.is_empty() {
        d.parts = g.parts(&d);
    }
    d.check(g).unwrap();
    d
}

fn instance(d: &AssemblyData, name: &str) -> usize {
    d.instances.iter().position(|i| i.name == name).unwrap()
}

fn site(g: &CompiledGrammar, d: &AssemblyData, inst: usize, name: &str) -> InstanceSite {
    let piece = &g.pieces[d.instances[inst].piece];
    InstanceSite {
        instance: inst,
        site: piece.sites.iter().position(|s| s.name == name).unwrap(),
    }
}

/// Turns an instance's vertices by `angle` radians about `pivot`.
fn turn(d: &mut AssemblyData, inst: usize, pivot: DVec2, angle: f64) {
    let r = DVec2::from_angle(angle);
    for v in d.instances[inst].vertices.clone() {
        d.positions[v] = pivot + r.rotate(d.positions[v] - pivot);
    }
}

fn near(a: DVec2, b: DVec2) -> bool {
    a.distance(b) < 1e-9
}

#[test]
fn the_threshold_is_45_degrees_from_head_on() {
    assert!((merge::FACING_DOT + (PI / 4.0).cos()).abs() < 1e-15);
    assert!(merge::facing(DVec2::X, -DVec2::X));
    assert!(merge::facing(DVec2::X, -DVec2::from_angle(0.7)));
    assert!(!merge::facing(DVec2::X, -DVec2::from_angle(0.9)));
    assert!(!merge::facing(DVec2::X, DVec2::Y));
    assert!(!merge::facing(DVec2::X, DVec2::X));
}

#[test]
fn sites_facing_each_other_within_reach_merge() {
    let g = two_bricks(1.3);
    let d = data_of(&g);
    let (a, b) = (instance(&d, "a"), instance(&d, "b"));
    let m = merge::find(&g, &d).expect("head-on, 0.3 m apart");
    assert_eq!(m.mover, site(&g, &d, a, "east"));
    assert_eq!(m.target, site(&g, &d, b, "west"));
    assert!((m.distance - 0.3).abs() < 1e-9);
    assert!(near(site_out(&g, &d, m.mover).unwrap(), DVec2::X));
    assert!(near(site_out(&g, &d, m.target).unwrap(), -DVec2::X));
}

#[test]
fn sites_within_reach_that_face_away_or_across_do_not_merge() {
    let g = two_bricks(1.3);
    let base = data_of(&g);
    let b = instance(&base, "b");
    let west = site(&g, &base, b, "west");
    let pivot = site_centre(&g, &base, west).unwrap();
    // Turned about its west site's centre, `b` keeps that site 0.3 m from `a`'s east site.
    for (angle, what) in [
        (PI, "facing the same way (overlapping `a`)"),
        (FRAC_PI_2, "facing across (down)"),
        (-FRAC_PI_2, "facing across (up)"),
    ] {
        let mut d = base.clone();
        turn(&mut d, b, pivot, angle);
        let c = site_centre(&g, &d, west).unwrap();
        assert!(near(c, pivot), "{what}: the site stays put");
        assert_eq!(merge::find(&g, &d), None, "{what}: no weld");
        // Only the facing test stops it: the pair is within reach.
        assert!(
            merge::find_in_reach(&g, &d, |_, _| true).is_some(),
            "{what}"
        );
    }
}

#[test]
fn a_site_turned_past_the_threshold_stops_merging() {
    let g = two_bricks(1.3);
    let base = data_of(&g);
    let (a, b) = (instance(&base, "a"), instance(&base, "b"));
    for (inst, name) in [(b, "west"), (a, "east")] {
        let s = site(&g, &base, inst, name);
        let pivot = site_centre(&g, &base, s).unwrap();
        for deg in [
            -60.0_f64, -46.0, -44.0, -20.0, 0.0, 20.0, 44.0, 46.0, 60.0, 120.0,
        ] {
            let mut d = base.clone();
            turn(&mut d, inst, pivot, deg.to_radians());
            let out = site_out(&g, &d, s).unwrap();
            let turned = if name == "west" { -DVec2::X } else { DVec2::X };
            assert!(near(
                out,
                DVec2::from_angle(deg.to_radians()).rotate(turned)
            ));
            let merges = merge::find(&g, &d).is_some();
            assert_eq!(
                merges,
                deg.abs() < 45.0,
                "{name} of instance {inst} turned {deg} degrees"
            );
        }
    }
}

#[test]
fn a_sites_direction_follows_its_rest_state_not_only_the_instance() {
    // bend.clay's road bent a quarter turn left: its east end faces +y in the piece's frame.
    let g = file("bend.clay");
    let mut d = data_of(&g);
    let road = g.pieces.iter().position(|p| p.name == "road").unwrap();
    let left = g.pieces[road]
        .states
        .iter()
        .position(|s| s.name == "left")
        .unwrap();
    let inst = (0..d.instances.len())
        .find(|&i| d.instances[i].piece == road)
        .unwrap();
    let east = site(&g, &d, inst, "east");
    let west = site(&g, &d, inst, "west");
    let r = DVec2::from_angle(30f64.to_radians());
    let shift = DVec2::new(4.0, -2.0);
    for (k, v) in d.instances[inst].vertices.clone().into_iter().enumerate() {
        d.positions[v] = r.rotate(g.pieces[road].states[left].positions[k]) + shift;
    }
    assert!(near(site_out(&g, &d, east).unwrap(), r.rotate(DVec2::Y)));
    assert!(near(site_out(&g, &d, west).unwrap(), r.rotate(-DVec2::X)));
}

#[test]
fn a_one_vertex_site_takes_its_direction_from_its_edges() {
    let g = compile(
        "site type tip
piece stick {
    vertex a (0, 0)
    vertex b (1, 0)
    edges a-b
    site end: tip [b] out (1, 0)
}
model { s = stick at (0, 0) }",
    );
    let mut d = data_of(&g);
    let end = site(&g, &d, 0, "end");
    assert!(near(site_out(&g, &d, end).unwrap(), DVec2::X));
    turn(&mut d, 0, DVec2::ZERO, FRAC_PI_2);
    assert!(near(site_out(&g, &d, end).unwrap(), DVec2::Y));
    // Collapsed onto a point, the site faces nowhere.
    for v in d.instances[0].vertices.clone() {
        d.positions[v] = DVec2::new(2.0, 2.0);
    }
    assert_eq!(site_out(&g, &d, end), None);
}

#[test]
fn junction_street_end_turned_along_the_main_street_does_not_merge() {
    // junction.clay, as its script ends a drag: the side street's free end 0.3 m above
    // main[4]'s north side. Facing down onto it, it merges into a tee; turned a quarter about
    // that end, it faces along the street and does not.
    let g = file("junction.clay");
    let mut d = data_of(&g);
    let side = d
        .chains
        .iter()
        .position(|c| c.instances.len() == 4)
        .unwrap();
    let side_instances = d.chains[side].instances.clone();
    let mut vertices: Vec<usize> = side_instances
        .iter()
        .flat_map(|&i| d.instances[i].vertices.clone())
        .collect();
    vertices.sort();
    vertices.dedup();
    for &v in &vertices {
        d.positions[v].y -= 1.2;
    }
    let end = site(&g, &d, side_instances[3], "east");
    let m = merge::find(&g, &d).expect("facing down onto the side, 0.3 m above it");
    assert_eq!(m.mover, end);
    let pivot = site_centre(&g, &d, end).unwrap();
    let r = DVec2::from_angle(FRAC_PI_2);
    for &v in &vertices {
        d.positions[v] = pivot + r.rotate(d.positions[v] - pivot);
    }
    assert!(near(site_out(&g, &d, end).unwrap(), DVec2::X));
    assert_eq!(merge::find(&g, &d), None);
}

/// Drags brick `b`, 2 m east of `a` (which is pinned), over 30 frames by `translation`, turning
/// it by `angle` about its centre; returns how many merges the rules made.
fn drag_b(translation: DVec2, angle: f64) -> usize {
    let g = two_bricks(3.0);
    let config = SolverConfig::from_params(&g.solver);
    let mut asm = Assembly::new(Arc::new(g));
    let mut session = clay::Session::new(config);
    let data = asm.data();
    let a = data.instances.iter().position(|i| i.name == "a").unwrap();
    let b = data.instances.iter().position(|i| i.name == "b").unwrap();
    clay::testing::pin(&mut asm, a).unwrap();
    session.grab(&mut asm, b).unwrap();
    let mut merges = 0;
    for k in 1..=30 {
        let t = k as f64 / 30.0;
        session.move_grab(&mut asm, t * translation, t * angle);
        let frame = session.frame(&mut asm).unwrap();
        merges += frame
            .events
            .iter()
            .filter(|e| e.kind == RuleKind::Merge)
            .count();
        asm.data().check(asm.grammar()).unwrap();
    }
    merges
}

#[test]
fn a_brick_dragged_head_on_welds_and_one_dragged_up_beside_it_does_not() {
    // Head on: b's west site ends 0.2 m from a's east site.
    assert_eq!(drag_b(DVec2::new(-1.8, 0.0), 0.0), 1);
    // Turned a quarter while coming: b ends standing beside a's east end (its west site,
    // now facing down, 0.3 m from a's east site and 0.1 m higher), clear of a.
    assert_eq!(drag_b(DVec2::new(-2.2, 0.6), FRAC_PI_2), 0);
}

#[test]
fn a_cut_pair_turned_away_and_back_within_reach_stays_apart_until_it_parts() {
    let g = two_bricks(3.0);
    let config = SolverConfig::from_params(&g.solver);
    let mut asm = Assembly::new(Arc::new(g));
    let mut session = clay::Session::new(config);
    let a = asm
        .data()
        .instances
        .iter()
        .position(|i| i.name == "a")
        .unwrap();
    let b = asm
        .data()
        .instances
        .iter()
        .position(|i| i.name == "b")
        .unwrap();
    clay::testing::pin(&mut asm, a).unwrap();
    session.grab(&mut asm, b).unwrap();
    // `b` turned by `angle` about its west site, held at (1.2, 0.25), 0.2 m from `a`'s east
    // site: its centre starts at (3.5, 0.25), half a metre east of that site.
    let turned = |angle: f64| {
        let centre = DVec2::new(1.2, 0.25) + 0.5 * DVec2::from_angle(angle);
        (centre - DVec2::new(3.5, 0.25), angle)
    };
    let mut merges = 0;
    let mut go = |session: &mut clay::Session, asm: &mut Assembly, poses: &[(DVec2, f64)]| {
        for &(translation, angle) in poses {
            session.move_grab(asm, translation, angle);
            for _ in 0..3 {
                let frame = session.frame(asm).unwrap();
                merges += frame
                    .events
                    .iter()
                    .filter(|e| e.kind == RuleKind::Merge)
                    .count();
            }
        }
        merges
    };
    let approach: Vec<(DVec2, f64)> = (0..=10)
        .map(|k| (DVec2::new(-1.8 * k as f64 / 10.0, 0.0), 0.0))
        .collect();
    assert_eq!(
        go(&mut session, &mut asm, &approach),
        1,
        "head on, it welds"
    );
    let cut = session.cut(&mut asm, DVec2::new(1.0, 0.25)).unwrap();
    assert_eq!(cut.kind, RuleKind::Cut);
    // Turned a quarter away and back, never out of reach: still the pair just cut.
    let sweep: Vec<(DVec2, f64)> = (0..=9)
        .chain((0..=9).rev())
        .map(|k| turned(k as f64 * 10f64.to_radians()))
        .collect();
    assert_eq!(
        go(&mut session, &mut asm, &sweep),
        1,
        "no weld right after the cut"
    );
    // Drawn 1 m away (out of reach) and back: parted, so it welds again.
    let away: Vec<(DVec2, f64)> = (0..=10)
        .chain((0..=10).rev())
        .map(|k| (DVec2::new(-1.8 + 0.1 * k as f64, 0.0), 0.0))
        .collect();
    assert_eq!(
        go(&mut session, &mut asm, &away),
        2,
        "parted, it welds again"
    );
}
