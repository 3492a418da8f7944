//! The rules through `clayc run --json` (the user's path): the wall doubles and comes back, and
//! paper Fig. 8's `--set norm=2` comparison.

use std::path::PathBuf;
use std::process::Command;

use serde_json::Value;

fn temp(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("clay-rules-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn run(grammar: &PathBuf, script: &str, name: &str, set: &[&str]) -> Value {
    let script = temp(name, script);
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_clayc"));
    cmd.arg("run")
        .arg(grammar)
        .arg("--script")
        .arg(&script)
        .arg("--json");
    for s in set {
        cmd.arg("--set").arg(s);
    }
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "clayc run failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn wall_clay() -> PathBuf {
    PathBuf::from(format!("{}/grammars/wall.clay", env!("CARGO_MANIFEST_DIR")))
}

fn bricks(v: &Value) -> u64 {
    v["pieces"]["brick"].as_u64().unwrap()
}

#[test]
fn clayc_run_wall_doubles_to_about_sixteen_bricks_and_back_to_eight() {
    let out = run(
        &wall_clay(),
        r#"{"steps": [{"pin": {"extreme": "west"}}, {"grab": {"extreme": "east"}},
            {"drag": {"by": [8, 0], "frames": 120}}, {"hold": {"frames": 30}}]}"#,
        "wall2x.json",
        &[],
    );
    let n = bricks(&out);
    let strain = out["max_edge_strain"].as_f64().unwrap();
    assert!((15..=17).contains(&n), "{n} bricks at 2x");
    assert!(strain <= 0.15, "max edge strain {strain}");
    assert!(out["rules_fired"]["stretch"].as_u64().unwrap() >= 7);
    let back = run(
        &wall_clay(),
        r#"{"steps": [{"pin": {"extreme": "west"}}, {"grab": {"extreme": "east"}},
            {"drag": {"by": [8, 0], "frames": 120}}, {"hold": {"frames": 30}},
            {"drag": {"by": [-8, 0], "frames": 120}}, {"hold": {"frames": 30}}]}"#,
        "wallback.json",
        &[],
    );
    let n = bricks(&back);
    assert!((7..=9).contains(&n), "{n} bricks after dragging back");
    assert_eq!(back["components"].as_u64(), Some(1));
}

#[test]
fn clayc_run_fig8_norm_two_inserts_nothing_at_fifteen_percent() {
    // wall.clay with 16 bricks: 12 are free between the two-brick handles, so 15% of the
    // wall is 20% on each of them if spread evenly (least squares), below the switch to
    // `three`; the sub-quadratic norm gathers it and inserts.
    let src = std::fs::read_to_string(wall_clay())
        .unwrap()
        .replace("chain brick x 8", "chain brick x 16");
    let grammar = temp("wall16.clay", &src);
    let script = r#"{"steps": [{"pin": {"extreme": "west"}}, {"grab": {"extreme": "east"}},
        {"drag": {"by": [2.4, 0], "frames": 60}}, {"hold": {"frames": 30}}]}"#;
    let sparse = run(&grammar, script, "fig8.json", &[]);
    let dense = run(&grammar, script, "fig8.json", &["norm=2"]);
    assert!(bricks(&sparse) >= 17, "p = 0.5: {} bricks", bricks(&sparse));
    assert_eq!(bricks(&dense), 16, "p = 2 inserted a brick");
}
