//! One truth per setting (issue 47): a grammar's `solver { }` block and `clayc run --set`
//! (`clay::apply_setting`, which the editor and the Python package call too) accept the same
//! values of every setting, the ones the settings table (`clay_dsl::settings`) allows; and a
//! session runs at every setting's bounds without panicking (`--set l2_iterations=0` with a
//! stretch indexed past the end of the pose once).

use std::sync::Arc;

use clay::{Assembly, Script, Session, SolverConfig, apply_setting, replay};
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
            let compiled = clay_dsl::compile(&text, "wall.clay").is_ok();
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

#[test]
fn a_session_runs_at_every_settings_bounds() {
    let grammar = Arc::new(clay_dsl::compile(WALL, "wall.clay").unwrap().grammar);
    let script = Script::parse(include_str!("../grammars/wall.script.json")).unwrap();
    for s in SETTINGS {
        let values: Vec<String> = match s.range {
            Range::Word(words) => words.iter().map(|w| w.to_string()).collect(),
            Range::Count { max } => vec!["0".into(), "1".into(), max.min(50).to_string()],
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
                    1e6
                } else if open_hi {
                    hi - 1e-9 * hi.abs().max(1.0)
                } else {
                    hi
                };
                vec![format!("{lo:e}"), format!("{hi:e}")]
            }
        };
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
