//! The rules as pure rewrites of small assemblies (no solver): stretch, shrink, merge (weld and
//! junction), cut (plain and junction), and their invariants (check passes, untouched ids and
//! states survive, every rewrite reports an event).

use std::collections::BTreeMap;

use clay::{RuleKind, testing::cut, testing::merge, testing::stretch};
use clay_dsl::compiled::{AssemblyData, CompiledGrammar, InstanceSite, PartKind};
use glam::DVec2;

fn compile(src: &str) -> CompiledGrammar {
    match clay_dsl::compile(src, "test.clay", &clay_dsl::CompileOptions::default()) {
        Ok(c) => c.grammar,
        Err(d) => panic!("test grammar does not compile: {d:?}"),
    }
}

fn wall(n: usize, min: usize) -> CompiledGrammar {
    compile(&format!(
        "site type joint
piece brick {{
    vertex sw (0, 0)
    vertex se (1, 0)
    vertex ne (1, 0.5)
    vertex nw (0, 0.5)
    edges sw-se-ne-nw-sw, sw-ne
    site west: joint [nw, sw] out (-1, 0)
    site east: joint [se, ne] out (1, 0)
}}
stretch brick from west to east {{ min {min} }}
model {{
    wall = chain brick x {n} at (0, 0)
}}"
    ))
}

fn file(name: &str) -> CompiledGrammar {
    let path = format!("{}/grammars/{name}", env!("CARGO_MANIFEST_DIR"));
    let src = std::fs::read_to_string(&path).unwrap();
    compile(&src)
}

/// The compiled initial assembly with its parts.
fn data_of(g: &CompiledGrammar) -> AssemblyData {
    let mut d = g.assembly.clone();
    if d.parts.is_empty() {
        d.parts = g.parts(&d);
    }
    d.check(g).unwrap();
    d
}

fn set_state(d: &mut AssemblyData, chain: usize, first: usize, state: usize) {
    let p = d
        .parts
        .iter_mut()
        .find(|p| p.kind == PartKind::Stretch { chain, first })
        .unwrap();
    p.active = state;
}

fn state_of(d: &AssemblyData, chain: usize, first: usize) -> usize {
    d.parts
        .iter()
        .find(|p| p.kind == PartKind::Stretch { chain, first })
        .unwrap()
        .active
}

fn ids(d: &AssemblyData, chain: usize) -> Vec<u64> {
    d.chains[chain]
        .instances
        .iter()
        .map(|&i| d.instances[i].id)
        .collect()
}

fn centre(g: &CompiledGrammar, d: &AssemblyData, instance: usize, site: usize) -> DVec2 {
    clay::testing::site_centre(g, d, InstanceSite { instance, site }).unwrap()
}

#[test]
fn stretch_replaces_two_elements_by_three_over_the_same_span() {
    let g = wall(6, 2);
    let mut d = data_of(&g);
    // Pull the wall to 1.5x so elements 2, 3 span 3 m.
    for p in &mut d.positions {
        p.x *= 1.5;
    }
    set_state(&mut d, 0, 0, 0); // far from the rewrite: must keep its state
    set_state(&mut d, 0, 2, stretch::THREE);
    let before_ids = ids(&d, 0);
    let next_id = d.next_id;
    let (ia, ib) = (d.chains[0].instances[2], d.chains[0].instances[3]);
    let a_from = d.instances[ia].vertices.clone();
    let b_to_centre = centre(&g, &d, ib, 1);
    let a_from_centre = centre(&g, &d, ia, 0);

    let r = rewrite(&g, &mut d, (0, 2)).unwrap();
    d.check(&g).unwrap();
    assert_eq!(r.event.kind, RuleKind::Stretch);
    assert_eq!(
        r.event.instances,
        vec![before_ids[2], before_ids[3], next_id]
    );
    assert_eq!(d.next_id, next_id + 1);
    let after = ids(&d, 0);
    assert_eq!(after.len(), 7);
    assert_eq!(
        after,
        [&before_ids[..3], &[next_id], &before_ids[3..]].concat(),
        "the new element goes between the two, every other id stays"
    );
    // Outer sites keep their global vertices and positions; the three new elements share the
    // 3 m span evenly (each 1 m, the rest length).
    let ia = d.chains[0].instances[2];
    let ib = d.chains[0].instances[4];
    assert_eq!(d.instances[ia].vertices[3], a_from[3]);
    assert_eq!(d.instances[ia].vertices[0], a_from[0]);
    assert!(centre(&g, &d, ib, 1).distance(b_to_centre) < 1e-12);
    for k in 2..5 {
        let i = d.chains[0].instances[k];
        let len = centre(&g, &d, i, 1).distance(centre(&g, &d, i, 0));
        assert!((len - 1.0).abs() < 1e-9, "element {k} is {len} m long");
    }
    assert!(centre(&g, &d, ia, 0).distance(a_from_centre) < 1e-12);
    assert_eq!(
        state_of(&d, 0, 0),
        0,
        "an untouched part keeps its active state"
    );
    for first in 1..5 {
        assert_eq!(
            state_of(&d, 0, first),
            stretch::TWO,
            "part {first} is rebuilt in two"
        );
    }
    assert_eq!(d.parts.len(), 6);
    assert_eq!(r.vertex_map.len(), 14, "the map covers the old vertices");
    assert!(r.vertex_map.iter().all(Option::is_some));
    assert_eq!(
        d.positions.len(),
        16,
        "7 bricks have 8 pairs of site vertices"
    );
}

#[test]
fn shrink_replaces_two_elements_by_one_and_drops_their_vertices() {
    let g = wall(6, 2);
    let mut d = data_of(&g);
    for p in &mut d.positions {
        p.x *= 0.5;
    }
    set_state(&mut d, 0, 3, stretch::ONE);
    let before_ids = ids(&d, 0);
    let (ia, ib) = (d.chains[0].instances[3], d.chains[0].instances[4]);
    let span = (centre(&g, &d, ia, 0), centre(&g, &d, ib, 1));
    let r = rewrite(&g, &mut d, (0, 3)).unwrap();
    d.check(&g).unwrap();
    assert_eq!(r.event.kind, RuleKind::Shrink);
    assert_eq!(r.event.instances, vec![before_ids[3], before_ids[4]]);
    let after = ids(&d, 0);
    assert_eq!(after, [&before_ids[..4], &before_ids[5..]].concat());
    assert_eq!(d.positions.len(), 14 - 2);
    assert_eq!(r.vertex_map.iter().filter(|m| m.is_none()).count(), 2);
    let k = d.chains[0].instances[3];
    assert!(centre(&g, &d, k, 0).distance(span.0) < 1e-12);
    assert!(centre(&g, &d, k, 1).distance(span.1) < 1e-12);
    assert_eq!(d.parts.len(), 4);
}

#[test]
fn shrink_stops_at_the_rules_minimum_and_leaves_the_data_alone() {
    let g = wall(3, 3);
    let mut d = data_of(&g);
    set_state(&mut d, 0, 0, stretch::ONE);
    assert!(stretch::candidates(&g, &d).is_empty());
    let before = d.clone();
    assert!(rewrite(&g, &mut d, (0, 0)).is_err());
    assert_eq!(d, before);
}

#[test]
fn stretch_then_shrink_round_trips_the_element_count() {
    let g = wall(4, 2);
    let mut d = data_of(&g);
    set_state(&mut d, 0, 1, stretch::THREE);
    rewrite(&g, &mut d, (0, 1)).unwrap();
    assert_eq!(d.chains[0].instances.len(), 5);
    set_state(&mut d, 0, 2, stretch::ONE);
    rewrite(&g, &mut d, (0, 2)).unwrap();
    d.check(&g).unwrap();
    assert_eq!(d.chains[0].instances.len(), 4);
    assert_eq!(d.positions.len(), 10);
}

#[test]
fn inserted_variants_follow_the_rules_frequencies() {
    let g = file("centipede.clay");
    let mut d = data_of(&g);
    let body = (0..d.chains.len())
        .max_by_key(|&c| d.chains[c].instances.len())
        .unwrap();
    for _ in 0..24 {
        let n = d.chains[body].instances.len();
        set_state(&mut d, body, n / 2, stretch::THREE);
        rewrite(&g, &mut d, (body, n / 2)).unwrap();
        d.check(&g).unwrap();
    }
    let rule = &g.stretch_rules[d.chains[body].rule];
    let n = d.chains[body].instances.len() as f64;
    assert_eq!(n, 32.0);
    let mut counts: BTreeMap<usize, usize> = BTreeMap::new();
    for &i in &d.chains[body].instances {
        *counts.entry(d.instances[i].piece).or_default() += 1;
    }
    for v in &rule.variants {
        let share = *counts.get(&v.piece).unwrap_or(&0) as f64 / n;
        assert!(
            (share - v.frequency).abs() <= 0.05,
            "variant {} has share {share}, frequency {}",
            g.pieces[v.piece].name,
            v.frequency
        );
    }
}

#[test]
fn a_free_street_end_near_a_side_merges_into_a_tee_and_a_cut_undoes_it() {
    let g = file("junction.clay");
    let mut d = data_of(&g);
    assert_eq!(clay::testing::connected_components(&d), 2);
    assert!(
        merge::find(&g, &d).is_none(),
        "the dead end starts out of reach"
    );
    let side = d
        .chains
        .iter()
        .position(|c| c.instances.len() == 4)
        .unwrap();
    let side_ids = ids(&d, side);
    let main_ids = ids(&d, 1 - side);
    // Move the side street 1.2 m down: its free end is 0.3 m from main[4]'s north side.
    let side_vertices: Vec<usize> = d.chains[side]
        .instances
        .iter()
        .flat_map(|&i| d.instances[i].vertices.clone())
        .collect();
    let mut moved = vec![false; d.positions.len()];
    for v in side_vertices {
        if !moved[v] {
            d.positions[v].y -= 1.2;
            moved[v] = true;
        }
    }
    let m = merge::find(&g, &d).expect("the end is within the merge distance");
    assert_eq!(d.instances[m.mover.instance].id, side_ids[3]);
    assert_eq!(d.instances[m.target.instance].id, main_ids[4]);
    assert!((m.distance - 0.3).abs() < 1e-9);
    let docks = d.docks.len();
    let r = merge::apply(&g, &mut d, &m).unwrap();
    d.check(&g).unwrap();
    assert_eq!(r.event.kind, RuleKind::Merge);
    assert_eq!(clay::testing::connected_components(&d), 1);
    assert_eq!(d.docks.len(), docks + 1);
    let tee = g.pieces.iter().position(|p| p.name == "tee").unwrap();
    let tees: Vec<usize> = (0..d.instances.len())
        .filter(|&i| d.instances[i].piece == tee)
        .collect();
    assert_eq!(tees.len(), 1);
    assert!(
        !d.instances.iter().any(|i| i.id == main_ids[4]),
        "the target was replaced"
    );
    // The main street is split at the tee; the side street is unchanged.
    let mut lens: Vec<usize> = d.chains.iter().map(|c| c.instances.len()).collect();
    lens.sort();
    assert_eq!(lens, vec![3, 4, 4]);
    assert!(merge::find(&g, &d).is_none(), "nothing more to merge");
    for id in main_ids
        .iter()
        .chain(&side_ids)
        .filter(|&&id| id != main_ids[4])
    {
        assert!(
            d.instances.iter().any(|i| i.id == *id),
            "instance {id} kept its id"
        );
    }

    // Cut at the tee's stem: the tee turns back into a road, the main street is one chain
    // again, and the side street hangs free.
    let stem = g.pieces[tee]
        .sites
        .iter()
        .position(|s| s.name == "north")
        .unwrap();
    let at = centre(&g, &d, tees[0], stem);
    let r = cut::cut_at(&g, &mut d, at + DVec2::new(0.1, 0.1)).unwrap();
    d.check(&g).unwrap();
    assert_eq!(r.event.kind, RuleKind::Cut);
    assert_eq!(clay::testing::connected_components(&d), 2);
    assert!(!d.instances.iter().any(|i| i.piece == tee));
    let mut lens: Vec<usize> = d.chains.iter().map(|c| c.instances.len()).collect();
    lens.sort();
    assert_eq!(lens, vec![4, 8]);
    assert_eq!(d.docks.len(), docks);
}

#[test]
fn a_plain_cut_splits_a_chain_and_duplicates_the_shared_vertices() {
    let g = wall(6, 2);
    let mut d = data_of(&g);
    let n = d.positions.len();
    let r = cut::cut_at(&g, &mut d, DVec2::new(3.1, 0.2)).unwrap();
    d.check(&g).unwrap();
    assert_eq!(r.event.kind, RuleKind::Cut);
    assert_eq!(d.positions.len(), n + 2);
    assert_eq!(clay::testing::connected_components(&d), 2);
    let mut lens: Vec<usize> = d.chains.iter().map(|c| c.instances.len()).collect();
    lens.sort();
    assert_eq!(lens, vec![3, 3]);
    assert_eq!(d.parts.len(), 4);
}

#[test]
fn a_cut_with_nothing_near_changes_nothing() {
    let g = wall(4, 2);
    let mut d = data_of(&g);
    let before = d.clone();
    let err = cut::cut_at(&g, &mut d, DVec2::new(50.0, 50.0)).unwrap_err();
    assert!(err.contains("nothing to cut"), "{err}");
    assert_eq!(d, before);
}

#[test]
fn two_free_ends_within_reach_weld_directly() {
    let g = compile(
        "site type joint
solver { merge_distance = 0.5 }
piece brick {
    vertex sw (0, 0)
    vertex se (1, 0)
    vertex ne (1, 0.5)
    vertex nw (0, 0.5)
    edges sw-se-ne-nw-sw, sw-ne
    site west: joint [nw, sw] out (-1, 0)
    site east: joint [se, ne] out (1, 0)
}
stretch brick from west to east { min 2 }
merge brick.east onto brick.west
model {
    a = chain brick x 3 at (0, 0)
    b = chain brick x 3 at (3.3, 0)
}",
    );
    let mut d = data_of(&g);
    assert_eq!(d.chains.len(), 2);
    let m = merge::find(&g, &d).expect("the ends are 0.3 m apart");
    assert!((m.distance - 0.3).abs() < 1e-9);
    let n = d.positions.len();
    let r = merge::apply(&g, &mut d, &m).unwrap();
    d.check(&g).unwrap();
    assert_eq!(r.event.kind, RuleKind::Merge);
    assert_eq!(d.positions.len(), n - 2);
    assert_eq!(clay::testing::connected_components(&d), 1);
    assert_eq!(d.chains.len(), 1, "welded chain ends make one chain");
    assert_eq!(d.chains[0].instances.len(), 6);
    assert_eq!(d.parts.len(), 5);
    assert!(merge::find(&g, &d).is_none());
}

/// The paper's rewrite of a stretch part (two elements to three in `three`, to one in `one`),
/// with no held element.
fn rewrite(
    g: &clay_dsl::compiled::CompiledGrammar,
    d: &mut clay_dsl::compiled::AssemblyData,
    at: (usize, usize),
) -> Result<clay::testing::Rewrite, String> {
    let state = d
        .parts
        .iter()
        .find(|p| {
            p.kind
                == clay_dsl::compiled::PartKind::Stretch {
                    chain: at.0,
                    first: at.1,
                }
        })
        .map(|p| p.active);
    let elements = if state == Some(stretch::ONE) { 1 } else { 3 };
    stretch::rewrite_part(g, d, at, elements, &Default::default())
}
