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

/// A mistake 200,000 columns into a line (issue 47: every diagnostic reprinted its whole
/// line, 13.5 MB of stderr for fifty on a 270 KB line): shown as a window round the label,
/// with the original line and column.
#[test]
fn a_mistake_on_a_very_long_line_shows_a_window_with_the_true_column() {
    let dir = std::env::temp_dir().join(format!("clay-cli-long-line-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("long.clay");
    let pad = " ".repeat(200_000);
    std::fs::write(
        &path,
        format!("piece w {{\n    vertex a (0, 0) {pad}nonsense\n}}\n"),
    )
    .unwrap();
    let out = check(&[], &path);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.len() < 2_000, "{} bytes of stderr", err.len());
    assert!(err.contains("long.clay:2:200021"), "{err}");
    assert!(err.contains("… ") && err.contains("nonsense"), "{err}");
}
