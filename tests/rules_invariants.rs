//! Invariants of every rewrite under random sequences of rules (proptest), and the
//! replacement rule's events.

use std::collections::HashSet;

use clay::{Judged, RuleKind, StateSwitch, testing::cut, testing::replace, testing::stretch};
use clay_dsl::compiled::{AssemblyData, CompiledGrammar, PartKind};
use glam::DVec2;
use proptest::prelude::*;

fn grammar(name: &str) -> CompiledGrammar {
    let path = format!("{}/grammars/{name}", env!("CARGO_MANIFEST_DIR"));
    let src = std::fs::read_to_string(&path).unwrap();
    clay_dsl::compile(&src, &path, &clay_dsl::CompileOptions::default())
        .unwrap()
        .grammar
}

fn initial(g: &CompiledGrammar) -> AssemblyData {
    let mut d = g.assembly.clone();
    if d.parts.is_empty() {
        d.parts = g.parts(&d);
    }
    d
}

#[derive(Clone, Debug)]
enum Op {
    Stretch(usize),
    Shrink(usize),
    Cut(f64),
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        (0usize..40).prop_map(Op::Stretch),
        (0usize..40).prop_map(Op::Shrink),
        (0.0f64..20.0).prop_map(Op::Cut),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Any sequence of stretches, shrinks and cuts on the wall keeps the assembly valid, keeps
    /// the ids of instances the event does not name, and never reuses an id.
    #[test]
    fn random_rewrites_keep_the_assembly_valid(ops in proptest::collection::vec(op(), 1..25)) {
        let g = grammar("wall.clay");
        let mut d = initial(&g);
        let mut seen: HashSet<u64> = d.instances.iter().map(|i| i.id).collect();
        for op in ops {
            let ids_before: HashSet<u64> = d.instances.iter().map(|i| i.id).collect();
            let result = match op {
                Op::Stretch(k) | Op::Shrink(k) => {
                    let stretch_parts: Vec<(usize, usize)> = d.parts.iter().filter_map(|p| match p.kind {
                        PartKind::Stretch { chain, first } => Some((chain, first)),
                        PartKind::Piece { .. } => None,
                    }).collect();
                    if stretch_parts.is_empty() {
                        continue;
                    }
                    let (chain, first) = stretch_parts[k % stretch_parts.len()];
                    let state = if matches!(op, Op::Stretch(_)) { stretch::THREE } else { stretch::ONE };
                    d.parts.iter_mut().find(|p| p.kind == PartKind::Stretch { chain, first }).unwrap().active = state;
                    let r = rewrite(&g, &mut d, (chain, first));
                    // A refused shrink leaves the part in `one`: put it back.
                    if r.is_err() {
                        for p in &mut d.parts {
                            if p.kind == (PartKind::Stretch { chain, first }) {
                                p.active = stretch::TWO;
                            }
                        }
                    }
                    r
                }
                Op::Cut(x) => cut::cut_at(&g, &mut d, DVec2::new(x, 0.25)),
            };
            prop_assert!(d.check(&g).is_ok(), "{:?}", d.check(&g));
            let ids_after: HashSet<u64> = d.instances.iter().map(|i| i.id).collect();
            match result {
                Ok(r) => {
                    let named: HashSet<u64> = r.event.instances.iter().copied().collect();
                    for id in ids_before.difference(&ids_after) {
                        prop_assert!(named.contains(id), "instance {id} vanished unannounced");
                    }
                    for id in ids_after.difference(&ids_before) {
                        prop_assert!(named.contains(id) && !seen.contains(id), "id {id} reused or unannounced");
                    }
                    prop_assert_eq!(d.parts.len(), g.parts(&d).len());
                }
                Err(_) => prop_assert_eq!(&ids_before, &ids_after),
            }
            seen.extend(ids_after);
        }
    }
}

#[test]
fn a_piece_part_switching_state_shows_it_and_reports_one_replace_event() {
    let g = grammar("bend.clay");
    let mut d = initial(&g);
    let pi = d
        .parts
        .iter()
        .position(|p| matches!(p.kind, PartKind::Piece { .. }))
        .expect("bend.clay's roads are piece parts");
    let PartKind::Piece { instance } = d.parts[pi].kind else {
        unreachable!()
    };
    // Two switches in one frame (base -> left -> right): one event, base -> right.
    d.parts[pi].active = 2;
    let switches = [
        StateSwitch {
            part: pi,
            from: 0,
            to: 1,
            judged: Judged::Shape,
        },
        StateSwitch {
            part: pi,
            from: 1,
            to: 2,
            judged: Judged::Shape,
        },
    ];
    let events = replace::replacement_events(&g, &mut d, &switches, &[]);
    assert_eq!(events.len(), 1);
    assert_eq!(events[0].kind, RuleKind::Replace);
    assert_eq!(events[0].instances, vec![d.instances[instance].id]);
    assert_eq!(d.instances[instance].state, 2);
    assert!(
        events[0].detail.contains("is now `right` (was `base`)"),
        "{}",
        events[0].detail
    );
    // Switching back within the frame is no replacement.
    d.parts[pi].active = 2;
    let back = [
        StateSwitch {
            part: pi,
            from: 2,
            to: 0,
            judged: Judged::Shape,
        },
        StateSwitch {
            part: pi,
            from: 0,
            to: 2,
            judged: Judged::Shape,
        },
    ];
    assert!(replace::replacement_events(&g, &mut d, &back, &[]).is_empty());
    d.check(&g).unwrap();
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
