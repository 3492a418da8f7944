//! The sculpting session is the one definition of a frame and of a rule event: a session's
//! counts are its events (that `clayc run` reports what a library session counts is
//! `cli/tests/session.rs`).

use std::collections::BTreeMap;
use std::sync::Arc;

use clay::{Assembly, RuleKind, Script, Session, SolverConfig, Step, replay};

fn grammar(name: &str) -> clay_dsl::compiled::CompiledGrammar {
    let dir = env!("CARGO_MANIFEST_DIR");
    let src = std::fs::read_to_string(format!("{dir}/grammars/{name}.clay")).unwrap();
    clay_dsl::compile(
        &src,
        &format!("grammars/{name}.clay"),
        &clay_dsl::CompileOptions::default(),
    )
    .unwrap()
    .grammar
}

fn script(name: &str) -> Script {
    let dir = env!("CARGO_MANIFEST_DIR");
    Script::parse(&std::fs::read_to_string(format!("{dir}/grammars/{name}.script.json")).unwrap())
        .unwrap()
}

#[test]
fn a_sessions_counts_are_its_events_one_replace_per_instance_and_frame() {
    let g = grammar("wall");
    let mut asm = Assembly::new(Arc::new(g.clone()));
    let mut session = Session::new(SolverConfig::from_params(&g.solver));
    replay(&mut asm, &script("wall"), &mut session).unwrap();
    let mut logged: BTreeMap<RuleKind, usize> = RuleKind::ALL.iter().map(|&k| (k, 0)).collect();
    for e in session.rule_log() {
        *logged.entry(e.kind).or_default() += 1;
    }
    assert_eq!(&logged, session.rules_fired());
    assert!(logged[&RuleKind::Stretch] >= 8, "{logged:?}");

    // Without rules the replacement rule still reports, once per instance whose state changed.
    let g = grammar("bend");
    let mut asm = Assembly::new(Arc::new(g.clone()));
    let mut s = Session::without_rules(SolverConfig::from_params(&g.solver));
    let steps = Script::parse(
        r#"{"steps": [{"pin": {"extreme": "west"}}, {"grab": {"extreme": "east"}},
            {"rotate": {"degrees": 90, "frames": 30}}, {"drag": {"by": [-3, 3], "frames": 30}},
            {"hold": {"frames": 30}}]}"#,
    )
    .unwrap();
    let mut replaced = 0;
    for (i, step) in steps.steps.iter().enumerate() {
        s.step(&mut asm, i, step).unwrap();
    }
    for _ in 0..5 {
        let f = s.frame(&mut asm).unwrap();
        let mut ids: Vec<u64> = f.events.iter().flat_map(|e| e.instances.clone()).collect();
        let n = ids.len();
        ids.dedup();
        assert_eq!(ids.len(), n, "one event per instance in a frame");
        replaced += f.events.len();
    }
    assert!(s.rules_fired()[&RuleKind::Replace] >= replaced);
    assert!(
        s.rules_fired()[&RuleKind::Replace] >= 1,
        "the bend switched a segment"
    );
    assert_eq!(s.rules_fired()[&RuleKind::Stretch], 0);
}

#[test]
fn an_unpinned_brick_follows_the_wall_again() {
    let g = grammar("wall");
    let run = |steps: &str| {
        let mut asm = Assembly::new(Arc::new(g.clone()));
        let mut s = Session::new(SolverConfig::from_params(&g.solver));
        let script = Script::parse(&format!(r#"{{"steps": [{steps}]}}"#)).unwrap();
        replay(&mut asm, &script, &mut s).unwrap();
        let west = asm.data().instances[0].vertices[0];
        (asm.data().positions[west], s.notes().to_vec())
    };
    let pin_west = r#"{"pin": {"extreme": "west"}}, {"grab": {"extreme": "east"}}"#;
    let pull = r#"{"drag": {"by": [3, 1], "frames": 20}}, {"hold": {"frames": 20}}"#;
    let (held, _) = run(&format!("{pin_west}, {pull}"));
    let (freed, notes) = run(&format!(
        r#"{pin_west}, {{"unpin": {{"extreme": "west"}}}}, {pull}"#
    ));
    assert!(
        held.length() < 1e-3,
        "pinned: the west corner stays at {held}"
    );
    assert!(
        freed.length() > 0.5,
        "unpinned: the wall follows the grab rigidly, west corner at {freed}"
    );
    assert!(notes.is_empty(), "{notes:?}");
    let (_, notes) = run(r#"{"unpin": {"extreme": "west"}}"#);
    assert!(
        notes[0].contains("unpin found no pinned instance"),
        "{notes:?}"
    );
}

/// A frame an editor's time budget stopped replays bit for bit from a `budget` step with the
/// iterations its report gave (the trials of other rest states run whole whatever the
/// budget), and only with it: the same frames run to the end land elsewhere.
#[test]
fn a_frame_the_budget_stopped_replays_from_its_iterations() {
    let g = Arc::new(grammar("wall"));
    let config = SolverConfig::from_params(&g.solver);
    let start = Script::parse(
        r#"{"steps": [{"pin": {"extreme": "west"}}, {"grab": {"extreme": "east"}},
            {"drag": {"by": [2.5, 0.8], "frames": 0}}]}"#,
    )
    .unwrap();
    // the editor: frames with no time at all, so every pass stops as early as it may
    let mut edited = Assembly::new(g.clone());
    let mut editor = Session::new(config);
    replay(&mut edited, &start, &mut editor).unwrap();
    let mut steps = start.steps.clone();
    let mut stopped = 0;
    for _ in 0..20 {
        let report = editor
            .frame_within(&mut edited, std::time::Duration::ZERO)
            .unwrap()
            .report;
        if !report.complete {
            stopped += 1;
            steps.push(Step::Budget {
                pass1: report.pass1_iterations as u64,
                pass2: report.l2_iterations as u64,
            });
        }
        steps.push(Step::Hold { frames: 1 });
    }
    assert!(stopped >= 10, "the budget stopped {stopped} of 20 frames");
    // the script with its budget steps lands exactly where the editor did
    let mut replayed = Assembly::new(g.clone());
    replay(
        &mut replayed,
        &Script {
            steps: steps.clone(),
            ..Script::default()
        },
        &mut Session::new(config),
    )
    .unwrap();
    assert_eq!(replayed.data().instances, edited.data().instances);
    assert_eq!(replayed.data().positions, edited.data().positions);
    // without them the frames run to the end, elsewhere
    steps.retain(|s| !matches!(s, Step::Budget { .. }));
    let mut whole = Assembly::new(g);
    replay(
        &mut whole,
        &Script {
            steps,
            ..Script::default()
        },
        &mut Session::new(config),
    )
    .unwrap();
    assert_ne!(whole.data().positions, edited.data().positions);
}
