//! Acceptance tests of the rules with the solver, through the library replay (the same path
//! `clayc run` takes): the wall grows and shrinks brick by brick (paper Fig. 8 included), the
//! dead-end street merges into a tee and a cut takes it apart, the centipede's new segments
//! follow the variant frequencies.

use std::collections::BTreeMap;
use std::sync::Arc;

use clay::testing::max_edge_strain;
use clay::{Assembly, Compass, HandleKind, Script, SolverConfig};
use clay_dsl::compiled::CompiledGrammar;

fn grammar(name: &str) -> CompiledGrammar {
    let path = format!("{}/grammars/{name}", env!("CARGO_MANIFEST_DIR"));
    let src = std::fs::read_to_string(&path).unwrap();
    match clay_dsl::compile(&src, &path, &clay_dsl::CompileOptions::default()) {
        Ok(c) => c.grammar,
        Err(d) => panic!("{name} does not compile: {d:?}"),
    }
}

/// A live session: the assembly, the replay (solver) and the rules.
struct Session {
    asm: Assembly,
    replay: clay::Session,
}

impl Session {
    fn new(g: CompiledGrammar, norm: Option<f64>) -> Self {
        let mut config = SolverConfig::from_params(&g.solver);
        if let Some(p) = norm {
            config.norm = p;
        }
        Self {
            asm: Assembly::new(Arc::new(g)),
            replay: clay::Session::new(config),
        }
    }

    fn run(&mut self, json: &str) {
        let script = Script::parse(json).unwrap();
        for (i, s) in script.steps.iter().enumerate() {
            self.replay.step(&mut self.asm, i, s).unwrap();
            self.asm.data().check(self.asm.grammar()).unwrap();
        }
    }

    fn count(&self, piece: &str) -> usize {
        let g = self.asm.grammar();
        self.asm
            .data()
            .instances
            .iter()
            .filter(|i| g.pieces[i.piece].name == piece)
            .count()
    }

    fn fired(&self, kind: clay::RuleKind) -> usize {
        self.replay
            .rule_log()
            .iter()
            .filter(|e| e.kind == kind)
            .count()
    }
}

const PIN_WEST_GRAB_EAST: &str = r#"{"pin": {"extreme": "west"}}, {"grab": {"extreme": "east"}}"#;

fn wall_to(factor: f64, frames: u64, norm: Option<f64>) -> Session {
    let mut s = Session::new(grammar("wall.clay"), norm);
    let by = 8.0 * (factor - 1.0);
    s.run(&format!(
        r#"{{"steps": [{PIN_WEST_GRAB_EAST}, {{"drag": {{"by": [{by}, 0], "frames": {frames}}}}}, {{"hold": {{"frames": 30}}}}]}}"#
    ));
    s
}

#[test]
fn wall_dragged_to_twice_its_length_has_about_twice_the_bricks() {
    let mut s = wall_to(2.0, 120, None);
    let bricks = s.count("brick");
    let strain = max_edge_strain(&s.asm);
    eprintln!(
        "2x: {bricks} bricks, strain {strain:.3}, stretch {} shrink {}",
        s.fired(clay::RuleKind::Stretch),
        s.fired(clay::RuleKind::Shrink)
    );
    assert!((15..=17).contains(&bricks), "{bricks} bricks at 2x");
    assert!(strain <= 0.15, "max edge strain {strain}");
    // And back to the original length.
    s.run(r#"{"steps": [{"drag": {"by": [-8, 0], "frames": 120}}, {"hold": {"frames": 30}}]}"#);
    let bricks = s.count("brick");
    eprintln!(
        "back: {bricks} bricks, strain {:.3}",
        max_edge_strain(&s.asm)
    );
    assert_eq!(bricks, 8, "{bricks} bricks after dragging back");
}

/// wall.clay with `n` bricks instead of 8.
fn long_wall(n: usize) -> CompiledGrammar {
    let path = format!("{}/grammars/wall.clay", env!("CARGO_MANIFEST_DIR"));
    let src = std::fs::read_to_string(&path).unwrap();
    assert!(src.contains("chain brick x 8"));
    let src = src.replace("chain brick x 8", &format!("chain brick x {n}"));
    clay_dsl::compile(&src, &path, &clay_dsl::CompileOptions::default())
        .unwrap()
        .grammar
}

/// Drags the east brick of a wall of `n` bricks out by `fraction` of its length over `frames`
/// frames (west brick pinned) and holds; returns the brick count and the frame of the first
/// insertion.
fn stretch_wall(n: usize, fraction: f64, frames: u64, norm: Option<f64>) -> (usize, Option<u64>) {
    let mut s = Session::new(long_wall(n), norm);
    let by = n as f64 * fraction;
    s.run(&format!(
        r#"{{"steps": [{PIN_WEST_GRAB_EAST}, {{"drag": {{"by": [{by}, 0], "frames": {frames}}}}}, {{"hold": {{"frames": 30}}}}]}}"#
    ));
    let first = s
        .replay
        .rule_log()
        .iter()
        .find(|e| e.kind == clay::RuleKind::Stretch)
        .map(|e| e.frame);
    (s.count("brick"), first)
}

#[test]
fn paper_fig8_a_small_stretch_inserts_a_brick_only_with_the_sub_quadratic_norm() {
    // wall.clay stretched by 15%: the handles hold one brick each, so the 6 free bricks take
    // the 1.2 m, 20% each if spread evenly (least squares), below the switch to `three`.
    let (sparse, first) = stretch_wall(8, 0.15, 30, None);
    let (dense, _) = stretch_wall(8, 0.15, 30, Some(2.0));
    eprintln!("wall.clay at 1.15x: p=0.5 {sparse} bricks (first at {first:?}), p=2 {dense}");
    assert!(sparse >= 9, "p = 0.5 inserted no brick ({sparse})");
    assert_eq!(dense, 8, "p = 2 inserted a brick");
    // 16 bricks stretched by 15%: 14 free bricks, about 17% each if spread evenly.
    let (sparse, _) = stretch_wall(16, 0.15, 60, None);
    let (dense, _) = stretch_wall(16, 0.15, 60, Some(2.0));
    eprintln!("16 bricks at 1.15x: p=0.5 {sparse} bricks, p=2 {dense} bricks");
    assert!(sparse >= 17, "p = 0.5 inserted no brick ({sparse})");
    assert_eq!(dense, 16, "p = 2 inserted a brick");
}

/// Largest relative change of an instance's edge lengths from its piece's rest shape.
fn brick_distortion(asm: &Assembly, instance: usize) -> f64 {
    let g = asm.grammar();
    let inst = &asm.data().instances[instance];
    let piece = &g.pieces[inst.piece];
    let rest = &piece.states[0].positions;
    piece
        .edges
        .iter()
        .map(|e| {
            let now = asm.data().positions[inst.vertices[e[0]]]
                .distance(asm.data().positions[inst.vertices[e[1]]]);
            (now / rest[e[0]].distance(rest[e[1]]) - 1.0).abs()
        })
        .fold(0.0, f64::max)
}

/// Doubles wall.clay with norm `p` and brings it back, checking after each that each handle
/// still holds exactly one brick: the pin the west-most, the grab the east-most, both
/// undistorted, the pinned one unmoved.
fn handles_follow_their_bricks(norm: Option<f64>) {
    let mut s = Session::new(grammar("wall.clay"), norm);
    s.run(&format!(r#"{{"steps": [{PIN_WEST_GRAB_EAST}]}}"#));
    let west_at: Vec<_> = s.asm.data().instances[0]
        .vertices
        .iter()
        .map(|&v| s.asm.data().positions[v])
        .collect();
    // One brick each, not the two-brick stretch part around it.
    for h in s.asm.handles() {
        assert_eq!(
            h.vertices().len(),
            4,
            "handle {} holds {:?}",
            h.id(),
            h.vertices()
        );
    }
    s.run(r#"{"steps": [{"drag": {"by": [8, 0], "frames": 120}}, {"hold": {"frames": 30}}]}"#);
    assert!(s.fired(clay::RuleKind::Stretch) >= 3);
    one_brick_per_handle(&s.asm, &west_at, norm);
    s.run(r#"{"steps": [{"drag": {"by": [-8, 0], "frames": 120}}, {"hold": {"frames": 30}}]}"#);
    assert!(s.fired(clay::RuleKind::Shrink) >= 1);
    one_brick_per_handle(&s.asm, &west_at, norm);
}

fn one_brick_per_handle(a: &Assembly, west_at: &[glam::DVec2], norm: Option<f64>) {
    assert_eq!(a.handles().len(), 2);
    let east = a.instance_extreme(Compass::East).unwrap();
    let west = a.instance_extreme(Compass::West).unwrap();
    for h in a.handles() {
        let ii = a
            .data()
            .instances
            .iter()
            .position(|i| i.vertices == h.vertices())
            .unwrap_or_else(|| {
                panic!(
                    "p {norm:?}: {:?} handle holds {:?}, no instance's vertices",
                    h.kind(),
                    h.vertices()
                )
            });
        let expect = match h.kind() {
            HandleKind::Pin => west,
            HandleKind::Grab => east,
        };
        assert_eq!(
            ii,
            expect,
            "p {norm:?}: {:?} handle moved off its brick",
            h.kind()
        );
        let d = brick_distortion(a, ii);
        assert!(
            d < 0.02,
            "p {norm:?}: {:?} brick distorted by {d:.3}",
            h.kind()
        );
    }
    let now = a.data().instances[west]
        .vertices
        .iter()
        .map(|&v| a.data().positions[v]);
    for (p, q) in now.zip(west_at) {
        assert!(
            p.distance(*q) < 1e-3,
            "p {norm:?}: pinned brick moved from {q} to {p}"
        );
    }
}

#[test]
fn grab_and_pin_hold_one_brick_each_across_stretches() {
    // With least squares every pair stretches evenly and the first pair (holding the pinned
    // brick) is rewritten too: its first brick gets new `to` vertices.
    handles_follow_their_bricks(None);
    handles_follow_their_bricks(Some(2.0));
}

/// The stretch part over elements `first`, `first + 1` of chain 0.
fn stretch_part(a: &Assembly, first: usize) -> usize {
    a.data()
        .parts
        .iter()
        .position(|p| p.kind == clay_dsl::compiled::PartKind::Stretch { chain: 0, first })
        .unwrap()
}

#[test]
fn handles_follow_their_bricks_when_the_rules_rewrite_the_held_pair() {
    // Forces the rewrites the drags above rarely produce: the pair holding the pinned brick
    // stretches (the brick gets new `to` vertices), and the pair holding the grabbed brick
    // shrinks with the grabbed brick removed.
    let mut s = Session::new(grammar("wall.clay"), None);
    s.run(&format!(
        r#"{{"steps": [{PIN_WEST_GRAB_EAST}, {{"hold": {{"frames": 2}}}}]}}"#
    ));
    let west_id = s.asm.data().instances[0].id;
    let west_at: Vec<_> = s.asm.data().instances[0]
        .vertices
        .iter()
        .map(|&v| s.asm.data().positions[v])
        .collect();
    let k = stretch_part(&s.asm, 0);
    assert!(s.asm.set_active_state(k, clay::testing::stretch::THREE));
    let events =
        s.replay
            .rules_mut()
            .unwrap()
            .after_frame(&mut s.asm, &clay::FrameReport::default(), &[]);
    assert!(
        events.iter().any(|e| e.kind == clay::RuleKind::Stretch),
        "{events:?}"
    );
    let pin = s
        .asm
        .handles()
        .iter()
        .find(|h| h.kind() == HandleKind::Pin)
        .unwrap();
    let west = s
        .asm
        .data()
        .instances
        .iter()
        .position(|i| i.id == west_id)
        .unwrap();
    assert_eq!(pin.vertices(), s.asm.data().instances[west].vertices);
    let targets: Vec<glam::DVec2> = (0..pin.vertices().len()).map(|k| pin.target(k)).collect();
    assert_eq!(targets, west_at, "the pin's targets changed");
    // Solve a few frames: the pinned brick is back where it was, undistorted.
    s.run(r#"{"steps": [{"hold": {"frames": 20}}]}"#);
    let now = s.asm.data().instances[west]
        .vertices
        .iter()
        .map(|&v| s.asm.data().positions[v]);
    for (p, q) in now.zip(&west_at) {
        assert!(p.distance(*q) < 1e-3, "pinned brick moved from {q} to {p}");
    }
    assert!(brick_distortion(&s.asm, west) < 0.02);

    // The east pair shrinks; the first element is kept (ties), so the grabbed brick goes.
    let n = s.asm.data().chains[0].instances.len();
    let east_id = s.asm.data().instances[s.asm.data().chains[0].instances[n - 1]].id;
    let k = stretch_part(&s.asm, n - 2);
    assert!(s.asm.set_active_state(k, clay::testing::stretch::ONE));
    let events =
        s.replay
            .rules_mut()
            .unwrap()
            .after_frame(&mut s.asm, &clay::FrameReport::default(), &[]);
    let shrink = events
        .iter()
        .find(|e| e.kind == clay::RuleKind::Shrink)
        .expect("the east pair shrank");
    assert!(shrink.instances.contains(&east_id));
    let grab = s
        .asm
        .handles()
        .iter()
        .find(|h| h.kind() == HandleKind::Grab)
        .expect("the grab survived the shrink");
    let held = grab
        .held_instance()
        .expect("the grab still holds an instance");
    let kept = s
        .asm
        .data()
        .instances
        .iter()
        .position(|i| i.id == held)
        .unwrap();
    assert_eq!(grab.vertices(), s.asm.data().instances[kept].vertices);
    assert_eq!(Some(kept), s.asm.instance_extreme(Compass::East));
    // Dragging on moves the kept brick with the handle, undistorted.
    s.run(r#"{"steps": [{"drag": {"by": [0.5, 0], "frames": 10}}, {"hold": {"frames": 20}}]}"#);
    let grab = s
        .asm
        .handles()
        .iter()
        .find(|h| h.kind() == HandleKind::Grab)
        .unwrap();
    for k in 0..grab.vertices().len() {
        let d = s.asm.data().positions[grab.vertices()[k]].distance(grab.target(k));
        assert!(d < 1e-3, "grabbed vertex {k} is {d} from its target");
    }
    assert!(brick_distortion(&s.asm, kept) < 0.02);
}

#[test]
fn the_dead_end_merges_into_a_tee_stays_merged_and_a_cut_takes_it_apart() {
    let mut s = Session::new(grammar("junction.clay"), None);
    assert_eq!(clay::testing::connected_components(s.asm.data()), 2);
    // The side street's free end is at (9, 2); the main street's north edge at y = 0.5.
    s.run(
        r#"{"steps": [{"pin": {"extreme": "west"}}, {"pin": {"at": [15, 0]}}, {"grab": {"at": [9, 3]}},
        {"drag": {"by": [0, -1.3], "frames": 40}}, {"hold": {"frames": 10}}]}"#,
    );
    assert_eq!(s.count("tee"), 1, "merged into a tee");
    assert_eq!(clay::testing::connected_components(s.asm.data()), 1);
    // Dragging on (sideways and up) does not un-merge it.
    s.run(r#"{"steps": [{"drag": {"by": [1, 1], "frames": 30}}, {"hold": {"frames": 10}}]}"#);
    assert_eq!(s.count("tee"), 1);
    assert_eq!(clay::testing::connected_components(s.asm.data()), 1);
    // Cut at the stem and pull the side street away.
    let tee = s
        .asm
        .data()
        .instances
        .iter()
        .position(|i| s.asm.grammar().pieces[i.piece].name == "tee")
        .unwrap();
    let g = s.asm.grammar();
    let stem = g.pieces[s.asm.data().instances[tee].piece]
        .sites
        .iter()
        .position(|x| x.name == "north")
        .unwrap();
    let at = clay::testing::site_centre(
        g,
        s.asm.data(),
        clay_dsl::compiled::InstanceSite {
            instance: tee,
            site: stem,
        },
    )
    .unwrap();
    s.run(&format!(
        r#"{{"steps": [{{"cut": {{"at": [{}, {}]}}}}, {{"drag": {{"by": [0, 3], "frames": 30}}}}, {{"hold": {{"frames": 10}}}}]}}"#,
        at.x, at.y
    ));
    assert_eq!(s.fired(clay::RuleKind::Cut), 1, "{:?}", s.replay.notes());
    assert_eq!(s.count("tee"), 0);
    assert_eq!(clay::testing::connected_components(s.asm.data()), 2);
}

#[test]
fn centipede_stretched_to_three_times_keeps_the_variant_mix() {
    let mut s = Session::new(grammar("centipede.clay"), None);
    // Body from x = 0 to 8 plus the head: pull the head 16 m east, tail pinned.
    s.run(
        r#"{"steps": [{"pin": {"extreme": "west"}}, {"grab": {"extreme": "east"}},
        {"drag": {"by": [16, 0], "frames": 240}}, {"hold": {"frames": 40}}]}"#,
    );
    let g = s.asm.grammar();
    let rule = &g.stretch_rules[0];
    let mut counts: BTreeMap<usize, usize> = BTreeMap::new();
    for i in &s.asm.data().instances {
        if rule.variants.iter().any(|v| v.piece == i.piece) {
            *counts.entry(i.piece).or_default() += 1;
        }
    }
    let n: usize = counts.values().sum();
    eprintln!("centipede: {n} segments {counts:?}");
    assert!(n >= 20, "only {n} segments at 3x");
    for v in &rule.variants {
        let share = *counts.get(&v.piece).unwrap_or(&0) as f64 / n as f64;
        assert!(
            (share - v.frequency).abs() <= 0.10,
            "{} share {share:.2} vs {}",
            g.pieces[v.piece].name,
            v.frequency
        );
    }
}

#[test]
fn the_generation_changes_only_when_a_rule_rewrites_the_structure() {
    let mut s = Session::new(grammar("wall.clay"), None);
    s.run(&format!(
        r#"{{"steps": [{PIN_WEST_GRAB_EAST}, {{"hold": {{"frames": 10}}}}]}}"#
    ));
    assert_eq!(s.asm.generation(), 0, "holding still rewrote something");
    s.run(r#"{"steps": [{"drag": {"by": [3, 0], "frames": 60}}, {"hold": {"frames": 10}}]}"#);
    let structural = s
        .replay
        .rule_log()
        .iter()
        .filter(|e| e.kind != clay::RuleKind::Replace)
        .count();
    assert!(structural >= 2, "{structural} rewrites for a 3 m drag");
    assert_eq!(s.asm.generation(), structural as u64);
    assert!(s.asm.validate().is_ok(), "{:?}", s.asm.validate());
}
