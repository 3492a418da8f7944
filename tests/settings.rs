//! One truth per setting (issue 47): a grammar's `solver { }` block and `clayc run --set`
//! (`clay::testing::apply_setting`, which the editor and the Python package call too) accept the same
//! values of every setting, the ones the settings table (`clay_dsl::settings`) allows; and a
//! session runs at every setting's bounds without panicking (`--set l2_iterations=0` with a
//! stretch indexed past the end of the pose once), on the wall's whole script and the first
//! frames of three examples.

use std::sync::Arc;

use clay::testing::apply_setting;
use clay::{Assembly, Script, Session, SolverConfig, configure, replay};
use clay_dsl::settings::{Range, SETTINGS};

const WALL: &str = include_str!("../grammars/wall.clay");

/// Values either side of every bound of `range`, and a few far ones.
fn probes(range: Range) -> Vec<f64> {
    let mut out = vec![-1.0, 0.0, 0.5, 1.0, 5.0, 1e300];
    if let Range::Number { lo, hi, .. } = range {
        for b in [lo, hi].into_iter().filter(|b| b.is_finite()) {
            out.extend([b - 1e-9 * b.abs().max(1.0), b, b + 1e-9 * b.abs().max(1.0)]);
        }
    }
    if let Range::Count { max } = range {
        out.extend([f64::from(max), f64::from(max) + 1.0, 2.5]);
    }
    out
}

#[test]
fn a_grammar_and_set_accept_the_same_values() {
    for s in SETTINGS.iter().filter(|s| s.in_grammar) {
        for x in probes(s.range) {
            let text = WALL.replace(
                "solver {\n    hysteresis = 0.15\n    norm = 0.5\n}",
                &format!("solver {{\n    {} = {x:e}\n}}", s.name),
            );
            assert_ne!(text, WALL);
            let compiled =
                clay_dsl::compile(&text, "wall.clay", &clay_dsl::CompileOptions::default()).is_ok();
            let mut config = SolverConfig::default();
            let mut merge = 0.5;
            let set = apply_setting(&mut config, &mut merge, s.name, &format!("{x:e}")).is_ok();
            assert_eq!(
                (compiled, set),
                (s.range.allows(x), s.range.allows(x)),
                "{} = {x:e}: the grammar {}, --set {}",
                s.name,
                if compiled { "accepts" } else { "refuses" },
                if set { "accepts" } else { "refuses" }
            );
        }
    }
}

/// Values of `range` at its bounds that it allows: a closed bound itself, an open one a
/// billionth inside (of the bound, at least of 1), an infinite upper bound as 1e9; a count's 0,
/// 1 and its `max` (at most `count_top`); every word.
fn at_bounds(range: Range, count_top: u32) -> Vec<String> {
    let values = match range {
        Range::Word(words) => words.iter().map(|w| w.to_string()).collect(),
        Range::Count { max } => vec!["0".into(), "1".into(), max.min(count_top).to_string()],
        Range::Number {
            lo,
            hi,
            open_lo,
            open_hi,
        } => {
            let lo = if open_lo {
                lo + 1e-9 * lo.abs().max(1.0)
            } else {
                lo
            };
            let hi = if hi.is_infinite() {
                1e9
            } else if open_hi {
                hi - 1e-9 * hi.abs().max(1.0)
            } else {
                hi
            };
            vec![format!("{lo:e}"), format!("{hi:e}")]
        }
    };
    for v in &values {
        assert!(
            matches!(range, Range::Word(_)) || range.allows(v.parse().unwrap()),
            "{v} is outside {range:?}"
        );
    }
    values
}

#[test]
fn a_session_runs_at_every_settings_bounds() {
    let grammar = Arc::new(
        clay_dsl::compile(WALL, "wall.clay", &clay_dsl::CompileOptions::default())
            .unwrap()
            .grammar,
    );
    let script = Script::parse(include_str!("../grammars/wall.script.json")).unwrap();
    for s in SETTINGS {
        let values = at_bounds(s.range, 50);
        for v in values {
            let mut config = SolverConfig::default();
            let mut merge = 0.5;
            apply_setting(&mut config, &mut merge, s.name, &v).unwrap();
            let mut asm = Assembly::new(grammar.clone());
            let mut session = Session::new(config);
            let summary = replay(&mut asm, &script, &mut session)
                .unwrap_or_else(|e| panic!("{}={v}: {e}", s.name));
            assert!(summary.finite, "{}={v}: a non-finite pose", s.name);
        }
    }
}

/// The bundled examples' scripts replayed (their first [`FRAMES`] frames): a stretch chain, an
/// assembly of towers and walls, merges and cuts.
const EXAMPLES: [&str; 3] = ["wall", "castle", "junction"];

/// The frames of each example's script replayed at every bound.
const FRAMES: u64 = 80;

/// The script's first steps, up to [`FRAMES`] frames.
fn first_frames(script: &Script) -> Script {
    let mut out = Script::default();
    for step in &script.steps {
        out.steps.push(step.clone());
        if out.frame_count() >= FRAMES {
            break;
        }
    }
    out
}

/// Every setting at its bounds (counts at their documented `max`), applied as `--set` applies
/// it (`clay::configure`, over the grammar's own `solver` block), on the first frames of three
/// examples: no panic, no error, every coordinate and figure finite, every frame run.
#[test]
fn the_examples_run_at_every_settings_bounds() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("grammars");
    let mut failures = Vec::new();
    let mut replayed = 0;
    for example in EXAMPLES {
        let source = std::fs::read_to_string(root.join(format!("{example}.clay"))).unwrap();
        let text = std::fs::read_to_string(root.join(format!("{example}.script.json"))).unwrap();
        let script = first_frames(&Script::parse(&text).unwrap());
        let compiled = clay_dsl::compile(&source, example, &clay_dsl::CompileOptions::default())
            .unwrap()
            .grammar;
        for setting in &SETTINGS {
            for value in at_bounds(setting.range, u32::MAX) {
                let mut grammar = compiled.clone();
                let config = match configure(&mut grammar, [(setting.name, value.as_str())]) {
                    Ok(c) => c,
                    Err(e) => {
                        failures.push(format!("{example}: {}={value} refused: {e}", setting.name));
                        continue;
                    }
                };
                let mut assembly = Assembly::new(Arc::new(grammar));
                let mut session = Session::new(config);
                let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    replay(&mut assembly, &script, &mut session)
                }));
                let why = match outcome {
                    Err(_) => Some("panicked".to_string()),
                    Ok(Err(e)) => Some(format!("failed: {e}")),
                    Ok(Ok(s)) if !s.finite => Some(format!("not finite: {:?}", s.not_finite)),
                    Ok(Ok(s)) if s.frames as u64 != script.frame_count() => Some(format!(
                        "ran {} of {} frames",
                        s.frames,
                        script.frame_count()
                    )),
                    Ok(Ok(_)) => {
                        replayed += 1;
                        None
                    }
                };
                if let Some(why) = why {
                    failures.push(format!("{example}: {}={value} {why}", setting.name));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // every setting's bounds on every example: 3 counts x 3 values, 5 numbers x 2, 2 words
    assert_eq!(replayed, EXAMPLES.len() * 21);
}
