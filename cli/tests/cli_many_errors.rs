//! `clayc check` on a file with thousands of errors (a fuzzing find: 40 s and 28 MB of
//! terminal output): the human form shows the first `clay_dsl::MAX_HUMAN_DIAGNOSTICS` and one
//! line counting the rest; `--format json` keeps every one.

use std::process::Command;

/// A model of 3,000 instances of an unknown piece: 3,000 errors (E011), one a line.
fn three_thousand_errors() -> std::path::PathBuf {
    let body: Vec<String> = (0..3_000).map(|i| format!("    i{i} = nope")).collect();
    let dir = std::env::temp_dir().join(format!("clay-cli-many-errors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("many.clay");
    std::fs::write(&path, format!("model {{\n{}\n}}\n", body.join("\n"))).unwrap();
    path
}

fn check(args: &[&str], path: &std::path::Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_clayc"))
        .env("NO_COLOR", "1")
        .arg("check")
        .args(args)
        .arg(path)
        .output()
        .unwrap()
}

#[test]
fn human_output_stops_after_its_limit_and_json_keeps_all() {
    let path = three_thousand_errors();
    let human = check(&[], &path);
    assert_eq!(human.status.code(), Some(1));
    let err = String::from_utf8_lossy(&human.stderr);
    let shown = clay_dsl::MAX_HUMAN_DIAGNOSTICS;
    assert_eq!(err.matches("error[E011]").count(), shown);
    let more = 3_000 - shown;
    assert!(
        err.contains(&format!(
            "\n... and {more} more errors (use `clayc check --format json` for all)\n"
        )),
        "{err}"
    );
    assert!(err.ends_with("check failed: 3000 errors\n"), "{err}");
    // About 200 bytes a diagnostic: the output is bounded by the limit, not the file.
    assert!(err.len() < shown * 1_000, "{} bytes", err.len());

    let json = check(&["--format", "json"], &path);
    assert_eq!(json.status.code(), Some(1));
    let all: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    assert_eq!(all.as_array().map(Vec::len), Some(3_000));
    std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
}
