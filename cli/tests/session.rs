//! `clayc run` reports what a library session counts (`clay::Session`, the one
//! definition of a frame and of a rule event): the same rules fired, parts and pieces after
//! each example's script.

use std::process::Command;
use std::sync::Arc;

use clay::{Assembly, RuleKind, Script, Session, SolverConfig, replay};

/// The repository's root, where the example grammars are.
const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/..");

fn grammar(name: &str) -> clay_dsl::compiled::CompiledGrammar {
    let src = std::fs::read_to_string(format!("{ROOT}/grammars/{name}.clay")).unwrap();
    clay_dsl::compile(
        &src,
        &format!("grammars/{name}.clay"),
        &clay_dsl::CompileOptions::default(),
    )
    .unwrap()
    .grammar
}

fn script(name: &str) -> Script {
    Script::parse(&std::fs::read_to_string(format!("{ROOT}/grammars/{name}.script.json")).unwrap())
        .unwrap()
}

#[test]
fn clayc_run_counts_what_the_session_counts() {
    for name in ["wall", "castle", "junction"] {
        let g = grammar(name);
        let mut asm = Assembly::new(Arc::new(g.clone()));
        let mut session = Session::new(SolverConfig::from_params(&g.solver));
        let summary = replay(&mut asm, &script(name), &mut session).unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_clayc"))
            .current_dir(ROOT)
            .args([
                "run",
                &format!("grammars/{name}.clay"),
                "--json",
                "--script",
            ])
            .arg(format!("grammars/{name}.script.json"))
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let cli: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        for kind in RuleKind::ALL {
            assert_eq!(
                cli["rules_fired"][kind.name()].as_u64(),
                Some(session.rules_fired()[&kind] as u64),
                "{name}: {}",
                kind.name()
            );
        }
        assert_eq!(cli["parts"].as_u64(), Some(summary.parts as u64));
        assert_eq!(
            cli["pieces"],
            serde_json::to_value(&summary.pieces).unwrap()
        );
    }
}
