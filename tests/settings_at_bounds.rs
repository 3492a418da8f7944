//! Every solver setting at its documented bounds (issue 47, item 3: `--set l2_iterations=0`
//! with a stretch once panicked). The one table (`clay_dsl::settings::SETTINGS`) gives each
//! setting's range; each bound, or the nearest value inside an open one, is applied as `--set`
//! applies it (`clay::configure`), and the bundled examples' scripts are replayed (their first
//! frames): no panic, no error, every coordinate and figure finite.

use std::sync::Arc;

use clay::{Assembly, Script, Session, configure, replay};
use clay_dsl::settings::{Range, SETTINGS};

/// The examples replayed: a stretch chain, an assembly of towers and walls, merges and cuts.
const EXAMPLES: [&str; 3] = ["wall", "castle", "junction"];

/// The frames of each example's script replayed (its first steps up to this many frames).
const FRAMES: u64 = 80;

/// The values at a range's bounds that the range allows: a closed bound itself, an open one
/// moved inside by a millionth (of the bound, at least of 1), an infinite upper bound as 1e9;
/// every word of a word setting.
fn bound_values(range: Range) -> Vec<String> {
    match range {
        Range::Number {
            lo,
            hi,
            open_lo,
            open_hi,
        } => {
            let inside = |x: f64, up: bool| {
                let step = 1e-6 * x.abs().max(1.0);
                if up { x + step } else { x - step }
            };
            let low = if open_lo { inside(lo, true) } else { lo };
            let high = if hi.is_infinite() {
                1e9
            } else if open_hi {
                inside(hi, false)
            } else {
                hi
            };
            assert!(range.allows(low) && range.allows(high), "{range:?}");
            vec![low.to_string(), high.to_string()]
        }
        Range::Count { max } => vec!["0".into(), max.to_string()],
        Range::Word(words) => words.iter().map(|w| w.to_string()).collect(),
    }
}

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

#[test]
fn every_setting_at_its_bounds_replays_the_examples_finitely() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("grammars");
    let mut failures = Vec::new();
    let mut replayed = 0;
    for example in EXAMPLES {
        let source = std::fs::read_to_string(root.join(format!("{example}.clay"))).unwrap();
        let text = std::fs::read_to_string(root.join(format!("{example}.script.json"))).unwrap();
        let script = first_frames(&Script::parse(&text).unwrap());
        let compiled = clay_dsl::compile(&source, example).unwrap().grammar;
        for setting in &SETTINGS {
            for value in bound_values(setting.range) {
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
    // every setting's bounds on every example: 8 numeric settings x 2 bounds + 2 words
    assert_eq!(replayed, EXAMPLES.len() * 18);
}
