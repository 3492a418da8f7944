//! The demo scripts (grammars/*.script.json) replayed with the rules: each shows the rule it
//! was written for, and every frame leaves a valid assembly.

use std::collections::BTreeMap;
use std::sync::Arc;

use clay::{Assembly, RuleKind, Script, SolverConfig};

struct Outcome {
    fired: BTreeMap<&'static str, usize>,
    pieces: BTreeMap<String, usize>,
    components: usize,
    notes: Vec<String>,
}

fn replay(name: &str) -> Outcome {
    let dir = env!("CARGO_MANIFEST_DIR");
    let src = std::fs::read_to_string(format!("{dir}/grammars/{name}.clay")).unwrap();
    let g = clay_dsl::compile(&src, name, &clay_dsl::CompileOptions::default())
        .unwrap()
        .grammar;
    let json = std::fs::read_to_string(format!("{dir}/grammars/{name}.script.json")).unwrap();
    let script = Script::parse(&json).unwrap();
    let mut asm = Assembly::new(Arc::new(g.clone()));
    let mut session = clay::Session::new(SolverConfig::from_params(&g.solver));
    for (i, s) in script.steps.iter().enumerate() {
        session.step(&mut asm, i, s).unwrap();
        asm.data().check(&g).unwrap();
        assert!(asm.validate().is_ok(), "{:?}", asm.validate());
    }
    let mut fired = BTreeMap::new();
    for e in session.rule_log() {
        let k = match e.kind {
            RuleKind::Replace => "replace",
            RuleKind::Stretch => "stretch",
            RuleKind::Shrink => "shrink",
            RuleKind::Merge => "merge",
            RuleKind::Cut => "cut",
        };
        *fired.entry(k).or_default() += 1;
    }
    let mut pieces = BTreeMap::new();
    for i in &asm.data().instances {
        *pieces.entry(g.pieces[i.piece].name.clone()).or_default() += 1;
    }
    eprintln!(
        "{name}: fired {fired:?}, pieces {pieces:?}, notes {:?}",
        session.notes()
    );
    Outcome {
        fired,
        pieces,
        components: clay::testing::connected_components(asm.data()),
        notes: session.notes().to_vec(),
    }
}

fn count(o: &Outcome, kind: &str) -> usize {
    o.fired.get(kind).copied().unwrap_or(0)
}

#[test]
fn wall_script_grows_and_shrinks_the_wall() {
    let o = replay("wall");
    assert!(count(&o, "stretch") >= 6);
    assert!(count(&o, "shrink") >= 6);
    assert_eq!(o.pieces["brick"], 8);
}

#[test]
fn castle_script_stretches_the_east_wall() {
    let o = replay("castle");
    assert!(count(&o, "stretch") >= 3, "{:?}", o.fired);
    assert_eq!(o.pieces["tower"], 4);
    assert!(o.pieces["wall"] >= 33);
    assert_eq!(o.components, 1);
}

#[test]
fn centipede_script_grows_the_body() {
    let o = replay("centipede");
    assert!(count(&o, "stretch") >= 12, "{:?}", o.fired);
    let segments: usize = ["seg_a", "seg_b", "seg_c"]
        .iter()
        .map(|p| o.pieces.get(*p).copied().unwrap_or(0))
        .sum();
    assert!(segments >= 20);
}

#[test]
fn junction_script_merges_then_cuts_apart() {
    let o = replay("junction");
    assert_eq!(count(&o, "merge"), 1, "{:?}", o.fired);
    assert_eq!(count(&o, "cut"), 1, "{:?} {:?}", o.fired, o.notes);
    assert_eq!(o.pieces.get("tee"), None);
    assert_eq!(o.components, 2);
}

#[test]
fn streets_script_merges_the_dead_end_into_a_second_tee_and_bends_a_road() {
    let o = replay("streets");
    assert_eq!(count(&o, "merge"), 1, "{:?}", o.fired);
    assert_eq!(o.pieces["tee"], 2);
    assert_eq!(o.components, 1);
    assert!(count(&o, "replace") >= 1, "no road bent: {:?}", o.fired);
}
