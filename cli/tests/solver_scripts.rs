//! `clayc run` and the script library: summaries of scripted sessions, adversarial scripts
//! that must stay finite, and malformed scripts, grammars and settings rejected with the right
//! exit code and a message naming the problem.

use std::path::PathBuf;
use std::process::Command;
use std::sync::Arc;

use clay::{Assembly, Script, Session, SolverConfig, replay, synthetic};
use serde_json::Value;

fn grammar_path(name: &str) -> String {
    format!("{}/../grammars/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn temp_file(name: &str, contents: &str) -> PathBuf {
    let path =
        std::env::temp_dir().join(format!("clay-solver-scripts-{}-{name}", std::process::id()));
    std::fs::write(&path, contents).unwrap();
    path
}

fn clayc(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_clayc"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn run_json(grammar: &str, script: &str, extra: &[&str]) -> Value {
    let s = temp_file(&format!("{}.json", script.len()), script);
    let g = grammar_path(grammar);
    let mut args = vec!["run", g.as_str(), "--script", s.to_str().unwrap(), "--json"];
    args.extend_from_slice(extra);
    let (code, out, err) = clayc(&args);
    assert_eq!(code, 0, "stderr: {err}");
    serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}: {out}"))
}

#[test]
fn an_empty_script_reports_the_initial_assembly() {
    let v = run_json("wall.clay", r#"{"steps": []}"#, &[]);
    assert_eq!(v["frames"], 0);
    assert_eq!(v["pieces"]["brick"], 8);
    assert_eq!(v["states"]["brick"]["base"], 8);
    assert_eq!(v["components"], 1);
    assert_eq!(v["finite"], true);
    assert!(v["energy"].as_f64().unwrap() < 1e-12);
    assert!(v["max_edge_strain"].as_f64().unwrap() < 1e-9);
    let bbox: Vec<f64> = v["bbox"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert!((bbox[2] - bbox[0] - 8.0).abs() < 1e-9, "{bbox:?}");
    for k in ["replace", "stretch", "shrink", "merge", "cut"] {
        assert_eq!(v["rules_fired"][k], 0);
    }
}

#[test]
fn a_drag_moves_the_bounding_box_and_counts_frames() {
    let v = run_json(
        "wall.clay",
        r#"{"steps": [{"grab": {"extreme": "east"}}, {"drag": {"to": [20, 5], "frames": 12}}, {"hold": {"frames": 3}}]}"#,
        &[],
    );
    assert_eq!(v["frames"], 15);
    // nothing pinned: the whole wall follows, its east end near x = 20 + half a brick pair
    let max_x = v["bbox"][2].as_f64().unwrap();
    assert!(max_x > 19.0, "bbox {}", v["bbox"]);
    assert!(v["frame_ms"]["max"].as_f64().unwrap() >= v["frame_ms"]["median"].as_f64().unwrap());
}

#[test]
fn adversarial_scripts_stay_finite() {
    let scripts = [
        r#"{"steps": [{"pin": {"extreme": "west"}}, {"grab": {"extreme": "east"}}, {"drag": {"by": [1000000, 0], "frames": 3}}]}"#,
        r#"{"steps": [{"grab": {"at": [4, 0]}}, {"rotate": {"degrees": 720, "frames": 2}}, {"hold": {"frames": 2}}]}"#,
        r#"{"steps": [{"grab": {"extreme": "north"}}, {"drag": {"by": [3, 3], "frames": 0}}, {"rotate": {"degrees": 45, "frames": 0}}, {"hold": {"frames": 2}}]}"#,
        r#"{"steps": [{"pin": {"at": [4, 0]}}, {"grab": {"at": [4, 0]}}, {"drag": {"by": [2, 1], "frames": 4}}, {"release": {}}, {"hold": {"frames": 2}}]}"#,
        r#"{"steps": [{"drag": {"by": [1, 1], "frames": 2}}, {"release": {}}, {"rotate": {"degrees": 90, "frames": 1}}, {"cut": {"at": [0, 0]}}]}"#,
    ];
    for grammar in ["wall.clay", "bend.clay", "castle.clay"] {
        for script in scripts {
            let v = run_json(grammar, script, &[]);
            assert_eq!(v["finite"], true, "{grammar}: {script}");
            assert!(v["energy"].is_number(), "{grammar}: {script}: {v}");
        }
    }
}

#[test]
fn grabbing_on_an_empty_model_does_nothing_and_stays_finite() {
    let mut asm = Assembly::new(Arc::new(synthetic::wall(0)));
    let script = Script::parse(
        r#"{"steps": [{"grab": {"at": [0, 0]}}, {"pin": {"extreme": "west"}}, {"drag": {"by": [1, 0], "frames": 3}}, {"rotate": {"degrees": 30, "frames": 2}}]}"#,
    )
    .unwrap();
    let mut session = Session::without_rules(SolverConfig::default());
    let summary = replay(&mut asm, &script, &mut session).unwrap();
    assert!(summary.finite);
    assert_eq!(summary.frames, 5);
    assert_eq!(summary.parts, 0);
    assert_eq!(summary.components, 0);
    assert!(
        session.notes().iter().any(|n| n.starts_with("step 0")),
        "{:?}",
        session.notes()
    );
}

#[test]
fn malformed_scripts_name_the_step_and_exit_1() {
    let cases = [
        (
            r#"{"steps": [{"grab": {"extreme": "east"}}, {"drag": {"by": [1, 0]}}]}"#,
            "step 1",
            "frames",
        ),
        (r#"{"steps": [{"jump": {}}]}"#, "step 0", "unknown step"),
        (
            r#"{"steps": [{"grab": {"extreme": "up"}}]}"#,
            "step 0",
            "extreme",
        ),
        (
            r#"{"steps": [{"hold": {"frames": -1}}]}"#,
            "step 0",
            "frames",
        ),
        (
            r#"{"steps": [{"grab": {"at": [1]}}]}"#,
            "step 0",
            "two numbers",
        ),
        (
            r#"{"steps": [{"drag": {"by": [1, 0], "to": [1, 1], "frames": 2}}]}"#,
            "step 0",
            "exactly one",
        ),
        (r#"{"steps": {}}"#, "steps", "array"),
        ("not json", "JSON", "JSON"),
    ];
    let g = grammar_path("wall.clay");
    for (i, (script, needle, what)) in cases.iter().enumerate() {
        let s = temp_file(&format!("bad{i}.json"), script);
        let (code, out, err) = clayc(&["run", &g, "--script", s.to_str().unwrap(), "--json"]);
        assert_eq!(code, 1, "{script}: {err}");
        assert!(out.is_empty(), "{script}: printed {out}");
        assert!(
            err.contains(needle) && err.contains(what),
            "{script}: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[test]
fn missing_files_exit_2_and_bad_grammars_exit_1_with_diagnostics() {
    let (code, _, err) = clayc(&["run", "/nonexistent/model.clay"]);
    assert_eq!(code, 2, "{err}");
    let g = grammar_path("wall.clay");
    let (code, _, err) = clayc(&["run", &g, "--script", "/nonexistent/script.json"]);
    assert_eq!(code, 2, "{err}");
    let bad = temp_file("bad.clay", "piece brick {\n  vertex a (0, 0\n}\n");
    let (code, _, err) = clayc(&["run", bad.to_str().unwrap()]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("error"), "{err}");
}

#[test]
fn settings_are_validated_and_applied() {
    let g = grammar_path("wall.clay");
    for bad in [
        "norm=3",
        "hysteresis=1.5",
        "colour=red",
        "norm",
        "irls_iterations=2.5",
        "irls_iterations=-1",
        "l2_anderson=17",
        "l2_anderson=0.5",
        "solver=lu",
        "pass1=irls",
    ] {
        let (code, _, err) = clayc(&["run", &g, "--set", bad]);
        assert_eq!(code, 2, "--set {bad}: {err}");
        assert!(err.contains("--set"), "{err}");
    }
    let script = r#"{"steps": [{"pin": {"extreme": "west"}}, {"grab": {"extreme": "east"}}, {"drag": {"by": [0.5, 1], "frames": 4}}]}"#;
    let cg = run_json(
        "wall.clay",
        script,
        &["--set", "solver=cg", "--set", "norm=2"],
    );
    let ch = run_json("wall.clay", script, &["--set", "norm=2"]);
    assert_eq!(cg["finite"], true);
    for k in 0..4 {
        let (a, b) = (
            cg["bbox"][k].as_f64().unwrap(),
            ch["bbox"][k].as_f64().unwrap(),
        );
        // CG stops at a relative residual of 1e-6, which the 1e6 handle rows dominate: the
        // positions agree to centimetres, not to round-off (the clay crate's
        // tests/solver_behaviour.rs compares the two tightly).
        assert!((a - b).abs() < 0.1, "bbox {k}: cg {a} cholesky {b}");
    }
}

#[test]
fn the_human_summary_names_frames_and_pieces() {
    let g = grammar_path("castle.clay");
    let (code, out, err) = clayc(&["run", &g]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("0 frames") && out.contains("tower"), "{out}");
}

/// Every JSON number of `v`, with the path to it; fails on `null` anywhere.
fn numbers(v: &Value, at: &str, out: &mut Vec<(String, f64)>) {
    match v {
        Value::Null => panic!("{at} is null"),
        Value::Number(n) => out.push((at.to_string(), n.as_f64().unwrap())),
        Value::Array(a) => a
            .iter()
            .enumerate()
            .for_each(|(i, x)| numbers(x, &format!("{at}[{i}]"), out)),
        Value::Object(o) => o
            .iter()
            .for_each(|(k, x)| numbers(x, &format!("{at}.{k}"), out)),
        _ => {}
    }
}

#[test]
fn figures_that_are_not_finite_are_flagged_and_never_null() {
    let grammar = Arc::new(synthetic::wall(4));
    let config = SolverConfig::default();
    let summarize = |asm: &Assembly| {
        replay(
            &mut asm.clone(),
            &Script::default(),
            &mut Session::without_rules(config),
        )
        .unwrap()
    };
    // Huge but finite coordinates: lengths and the energy overflow, the extent does not.
    let mut huge = Assembly::new(grammar.clone());
    for p in huge.positions_mut() {
        *p *= 1e300;
    }
    let s = summarize(&huge);
    assert!(!s.finite, "{s:?}");
    assert!(s.not_finite.contains(&"energy"), "{:?}", s.not_finite);
    assert!(!s.not_finite.contains(&"positions"), "{:?}", s.not_finite);
    let json = serde_json::to_value(&s).unwrap();
    let mut all = Vec::new();
    numbers(&json, "summary", &mut all);
    assert!(all.iter().all(|(_, x)| x.is_finite()), "{all:?}");
    assert_eq!(json["finite"], false);
    assert_eq!(
        json["not_finite"],
        serde_json::json!(["max_edge_strain", "energy"])
    );
    assert_eq!(json["energy"].as_f64(), Some(f64::MAX));
    // The text form writes the extent as 1.000e300, never as a 300-digit number.
    let text = s.human();
    let longest_digits = text
        .split(|c: char| !c.is_ascii_digit())
        .map(str::len)
        .max()
        .unwrap_or(0);
    assert!(longest_digits < 20, "{text}");
    assert!(
        text.contains("e300") && text.contains("WARNING: not finite: max_edge_strain, energy"),
        "{text}"
    );
    // A coordinate that is not a number: every figure it touches is named, none is null.
    let mut nan = Assembly::new(grammar);
    nan.positions_mut()[0].x = f64::NAN;
    let s = summarize(&nan);
    assert!(!s.finite);
    assert_eq!(
        s.not_finite.first(),
        Some(&"positions"),
        "{:?}",
        s.not_finite
    );
    let json = serde_json::to_value(&s).unwrap();
    numbers(&json, "summary", &mut Vec::new());
    assert!(!serde_json::to_string(&s).unwrap().contains("null"));
    // A finite session has no `not_finite` key at all.
    let v = run_json("wall.clay", r#"{"steps": []}"#, &[]);
    assert!(v.get("not_finite").is_none(), "{v}");
}
