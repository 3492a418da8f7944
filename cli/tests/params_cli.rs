//! `--param NAME=VALUE` (issue 39) on `clayc check`, `build`, `run`, `render` and `export`, run
//! as a user runs them: the real binary over the override fixtures (tests/fixtures/overrides/),
//! whose grammar is a wall of `bays` bricks `width` metres wide (defaults 4 and 1). A value
//! changes the model built; an unknown name and a value outside the range are the compiler's
//! E070 and E071, naming the parameter, its range and the known names, with exit code 1; a
//! malformed flag is a usage error (exit code 2) naming the flag.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
const WALL: &str = "tests/fixtures/overrides/E071-param-out-of-range.clay";
const UNKNOWN: &str = "tests/fixtures/overrides/E070-unknown-param.clay";

fn clayc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_clayc"))
        .current_dir(ROOT)
        .args(args)
        .output()
        .unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// `// params: bays=20` (the fixture's second line) as `--param` flags.
fn fixture_params(fixture: &str) -> Vec<String> {
    let text = std::fs::read_to_string(Path::new(ROOT).join(fixture)).unwrap();
    let line = text.lines().nth(1).unwrap();
    let list = line
        .strip_prefix("// params: ")
        .expect("a `// params:` line");
    list.split(", ")
        .flat_map(|pair| ["--param".to_string(), pair.to_string()])
        .collect()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("clay-params-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `clayc run --json` of the wall with `flags`.
fn run_json(flags: &[&str]) -> serde_json::Value {
    let mut args = vec!["run", WALL, "--json"];
    args.extend_from_slice(flags);
    let out = clayc(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn run_builds_the_model_the_parameters_say() {
    let default = run_json(&[]);
    assert_eq!(default["pieces"]["brick"], 4, "{default}");
    assert_eq!(default["bbox"][2].as_f64(), Some(4.0), "{default}");

    let longer = run_json(&["--param", "bays=8"]);
    assert_eq!(longer["pieces"]["brick"], 8, "{longer}");
    assert_eq!(longer["bbox"][2].as_f64(), Some(8.0), "{longer}");

    // Two parameters at once; of two values of one name the last counts.
    let wide = run_json(&[
        "--param",
        "bays=2",
        "--param",
        "width=1.5",
        "--param",
        "bays=3",
    ]);
    assert_eq!(wide["pieces"]["brick"], 3, "{wide}");
    assert_eq!(wide["bbox"][2].as_f64(), Some(4.5), "{wide}");
    // The ends of the range are allowed.
    assert_eq!(run_json(&["--param", "bays=12"])["pieces"]["brick"], 12);
}

#[test]
fn build_records_the_value_used_and_check_passes_with_it() {
    let out = clayc(&["build", WALL, "-o", "-", "--param", "width=0.5"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let grammar: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let width = (grammar["params"].as_array().unwrap().iter())
        .find(|p| p["name"] == "width")
        .unwrap();
    assert_eq!(width["value"].as_f64(), Some(0.5), "{width}");
    assert_eq!(width["default"].as_f64(), Some(1.0), "{width}");

    let out = clayc(&["check", WALL, "--param", "bays=5"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("check passed"), "{}", stderr(&out));
}

#[test]
fn render_and_export_draw_the_model_the_parameters_say() {
    let dir = scratch("draw");
    let svg = |name: &str, flags: &[&str]| -> String {
        let path = dir.join(name);
        let mut args = vec![
            "render",
            WALL,
            "-o",
            path.to_str().unwrap(),
            "--overlay",
            "graph",
        ];
        args.extend_from_slice(flags);
        let out = clayc(&args);
        assert!(out.status.success(), "{}", stderr(&out));
        std::fs::read_to_string(&path).unwrap()
    };
    // The graph overlay draws a dot per vertex: a wall of n bricks has 2n + 2.
    let dots = |svg: &str| svg.matches("<circle").count();
    assert_eq!(dots(&svg("4.svg", &[])), 10);
    assert_eq!(dots(&svg("9.svg", &["--param", "bays=9"])), 20);

    let objects = |name: &str, flags: &[&str]| -> usize {
        let path = dir.join(name);
        let mut args = vec!["export", WALL, "-o", path.to_str().unwrap()];
        args.extend_from_slice(flags);
        let out = clayc(&args);
        assert!(out.status.success(), "{}", stderr(&out));
        let obj = std::fs::read_to_string(&path).unwrap();
        obj.lines().filter(|l| l.starts_with("o ")).count()
    };
    assert_eq!(objects("4.obj", &[]), 4);
    assert_eq!(objects("7.obj", &["--param", "bays=7"]), 7);
}

#[test]
fn a_value_out_of_range_is_e071_naming_the_parameter_and_its_range_everywhere() {
    let dir = scratch("range");
    let out_png = dir.join("x.png");
    let out_glb = dir.join("x.glb");
    let params = fixture_params(WALL);
    assert_eq!(params, ["--param", "bays=20"]);
    let commands: [Vec<&str>; 5] = [
        vec!["check", WALL],
        vec!["build", WALL, "-o", "-"],
        vec!["run", WALL],
        vec!["render", WALL, "-o", out_png.to_str().unwrap()],
        vec!["export", WALL, "-o", out_glb.to_str().unwrap()],
    ];
    for mut args in commands {
        let sub = args[0];
        args.extend(params.iter().map(String::as_str));
        let out = clayc(&args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{sub}: {err}");
        assert!(err.contains("E071"), "{sub}: {err}");
        assert!(err.contains("`bays`"), "{sub}: {err}");
        assert!(err.contains("2..12"), "{sub}: {err}");
        // At the parameter's declaration: the file, line 4, column 7.
        assert!(err.contains(&format!("{WALL}:4:7")), "{sub}: {err}");
        if sub == "build" {
            assert!(out.stdout.is_empty(), "no grammar is written");
        }
    }
    assert!(!out_png.exists() && !out_glb.exists(), "nothing is drawn");
}

#[test]
fn an_unknown_name_is_e070_listing_the_parameters_everywhere() {
    let dir = scratch("unknown");
    let out_svg = dir.join("x.svg");
    let out_obj = dir.join("x.obj");
    let params = fixture_params(UNKNOWN);
    assert_eq!(params, ["--param", "bys=6"]);
    let commands: [Vec<&str>; 5] = [
        vec!["check", UNKNOWN],
        vec!["build", UNKNOWN, "-o", "-"],
        vec!["run", UNKNOWN, "--json"],
        vec!["render", UNKNOWN, "-o", out_svg.to_str().unwrap()],
        vec!["export", UNKNOWN, "-o", out_obj.to_str().unwrap()],
    ];
    for mut args in commands {
        let sub = args[0];
        args.extend(params.iter().map(String::as_str));
        let out = clayc(&args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{sub}: {err}");
        assert!(err.contains("E070"), "{sub}: {err}");
        assert!(err.contains("`bys`"), "{sub}: {err}");
        assert!(err.contains("did you mean `bays`"), "{sub}: {err}");
        assert!(err.contains("`bays`, `width`"), "{sub}: {err}");
        assert!(out.stdout.is_empty(), "{sub}: nothing on stdout");
    }
    assert!(!out_svg.exists() && !out_obj.exists(), "nothing is written");
}

#[test]
fn check_gives_the_values_to_every_file_and_reports_json_too() {
    let out = clayc(&["check", "--format", "json", WALL, "--param", "width=3"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let diags: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let codes: Vec<&str> = (diags.as_array().unwrap().iter())
        .map(|d| d["code"].as_str().unwrap())
        .collect();
    assert_eq!(codes, ["E071"], "{diags}");
    assert_eq!(diags[0]["line"], 5, "width is declared on line 5: {diags}");
    assert!(
        diags[0]["message"].as_str().unwrap().contains("0.5..2"),
        "{diags}"
    );
}

#[test]
fn a_malformed_flag_is_a_usage_error_naming_the_flag() {
    for (bad, says) in [
        ("bays", "no `=`"),
        ("bays=", "must be a number"),
        ("bays=inf", "finite"),
        ("bays=NaN", "finite"),
        ("=4", "not a parameter name"),
    ] {
        for sub in [
            vec!["check", WALL],
            vec!["build", WALL, "-o", "-"],
            vec!["run", WALL],
            vec!["render", WALL, "-o", "-"],
            vec!["export", WALL, "-o", "-"],
        ] {
            let mut args = sub.clone();
            args.extend(["--param", bad]);
            let out = clayc(&args);
            let err = stderr(&out);
            assert_eq!(out.status.code(), Some(2), "{sub:?} {bad}: {err}");
            assert!(err.contains("--param"), "{sub:?} {bad}: {err}");
            assert!(err.contains(says), "{sub:?} {bad}: {err}");
            assert!(out.stdout.is_empty(), "{sub:?} {bad}");
        }
    }
}

#[test]
fn a_compiled_grammar_takes_no_parameters() {
    let dir = scratch("compiled");
    let json = dir.join("wall.json");
    let out = clayc(&["build", WALL, "-o", json.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let png = dir.join("wall.png");
    let out = clayc(&[
        "render",
        json.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--param",
        "bays=5",
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--param") && err.contains("compiled already"),
        "{err}"
    );
    assert!(!png.exists());
}

/// Issue 48, item 3: a script says the parameters it was recorded with; on the grammar compiled
/// with other values its gestures would grab other parts and fold the model, so `run`,
/// `render` and `export` refuse it, naming the values to use (exit 1), and take it with them.
#[test]
fn a_script_recorded_with_other_parameters_is_refused_with_the_values_to_use() {
    let dir = scratch("script-params");
    let script = dir.join("pull.script.json");
    std::fs::write(
        &script,
        "{\"params\": {\"bays\": 6}, \"steps\": [{\"pin\": {\"extreme\": \"west\"}}, \
         {\"grab\": {\"extreme\": \"east\"}}, {\"drag\": {\"by\": [2, 0], \"frames\": 10}}]}\n",
    )
    .unwrap();
    let s = script.display().to_string();
    let out = clayc(&["run", WALL, "--script", &s, "--json"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains("recorded with bays = 6 (the grammar has 4)"),
        "{err}"
    );
    assert!(err.contains("--param bays=6"), "{err}");
    let png = dir.join("w.png").display().to_string();
    let out = clayc(&["render", WALL, "--script", &s, "-o", &png]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("bays = 6"), "{}", stderr(&out));
    assert!(!dir.join("w.png").exists());
    // With the values it names, it replays.
    let ran = run_json(&["--script", &s, "--param", "bays=6"]);
    assert!(ran["pieces"]["brick"].as_u64().unwrap() >= 6, "{ran}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn typed_values_switch_and_pick_and_a_wrong_type_is_e073_at_the_parameter() {
    // keep.clay: `donjon` a bool, `gate` a choice of two pieces.
    let out = clayc(&[
        "run",
        "grammars/keep.clay",
        "--json",
        "--param",
        "donjon=false",
        "--param",
        "gate=gatehouse",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(summary["pieces"]["gatehouse"], 1, "{summary}");
    assert!(summary["pieces"].get("donjon").is_none(), "{summary}");
    assert!(summary["pieces"].get("great_gate").is_none(), "{summary}");
    for (flag, line, says) in [
        ("gate=gatehose", 24, "did you mean \"gatehouse\"?"),
        ("donjon=2", 26, "set `donjon` to `true` or `false`"),
        ("wall_height=tall", 22, "set `wall_height` to a number"),
    ] {
        let out = clayc(&[
            "check",
            "--format",
            "json",
            "grammars/keep.clay",
            "--param",
            flag,
        ]);
        assert_eq!(out.status.code(), Some(1), "{flag}: {}", stderr(&out));
        let diags: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(diags.as_array().unwrap().len(), 1, "{flag}: {diags}");
        assert_eq!(diags[0]["code"], "E073", "{flag}: {diags}");
        assert_eq!(diags[0]["line"], line, "{flag}: {diags}");
        let hints: Vec<&str> = (diags[0]["hints"].as_array().unwrap().iter())
            .map(|h| h.as_str().unwrap())
            .collect();
        assert!(hints.contains(&says), "{flag}: {diags}");
    }
}
