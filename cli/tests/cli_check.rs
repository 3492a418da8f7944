//! `clayc check` / `clayc build` from the outside: exit codes 0/1/2, and every invalid fixture
//! reports its code at the line its header names.

use std::path::{Path, PathBuf};
use std::process::Command;

fn clayc() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_clayc"));
    c.env("NO_COLOR", "1");
    c
}

fn root() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

fn fixtures() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join("tests/fixtures/invalid"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "clay"))
        .collect();
    v.sort();
    v
}

fn write_temp(name: &str, bytes: &[u8]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("clay-cli-check-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

const VALID: &str = r#"
site type joint
piece brick {
    vertex sw (0, 0)
    vertex se (1, 0)
    vertex ne (1, 0.5)
    vertex nw (0, 0.5)
    edges sw-se-ne-nw-sw
    site west: joint [nw, sw] out (-1, 0)
    site east: joint [se, ne] out (1, 0)
}
stretch brick from west to east
model { wall = chain brick x 3 }
"#;

#[test]
fn valid_grammar_exits_0_and_builds_json() {
    let p = write_temp("valid.clay", VALID.as_bytes());
    let out = clayc().arg("check").arg(&p).output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        String::from_utf8_lossy(&out.stderr).trim(),
        "check passed: 1 file, no errors or warnings"
    );
    let out = clayc()
        .arg("build")
        .arg(&p)
        .args(["-o", "-"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    let g: clay_dsl::CompiledGrammar = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(g.assembly.instances.len(), 3);
    let target = p.with_extension("json");
    let out = clayc()
        .arg("build")
        .arg(&p)
        .arg("-o")
        .arg(&target)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    let g2: clay_dsl::CompiledGrammar =
        serde_json::from_str(&std::fs::read_to_string(&target).unwrap()).unwrap();
    assert_eq!(g, g2);
}

#[test]
fn usage_and_io_errors_exit_2_naming_the_file() {
    let out = clayc()
        .args(["check", "no/such/file.clay"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no/such/file.clay"));
    let out = clayc().arg("check").output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let out = clayc()
        .args(["build", "no/such/file.clay", "-o", "-"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn errors_exit_1_and_build_writes_nothing() {
    let bad = fixtures()
        .into_iter()
        .find(|p| p.to_string_lossy().contains("E011"))
        .unwrap();
    let out = clayc()
        .arg("build")
        .arg(&bad)
        .args(["-o", "-"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(out.stdout.is_empty());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("error[E011]") && !stderr.contains("\u{1b}["),
        "{stderr}"
    );
    let p = write_temp("latin1.clay", b"site type j // caf\xe9\n");
    let out = clayc().arg("check").arg(&p).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("E003"));
}

#[test]
fn every_fixture_reports_its_code_at_its_line() {
    let files = fixtures();
    assert!(files.len() >= 10);
    for f in files {
        let text = String::from_utf8_lossy(&std::fs::read(&f).unwrap()).into_owned();
        let header = text
            .lines()
            .next()
            .unwrap()
            .strip_prefix("// expect: ")
            .unwrap()
            .to_string();
        let mut w = header.split_whitespace();
        let code = w.next().unwrap().to_string();
        let line: u64 = w.nth(1).unwrap().parse().unwrap();
        let out = clayc()
            .args(["check", "--format", "json"])
            .arg(&f)
            .output()
            .unwrap();
        let expected_exit = if code.starts_with('E') { 1 } else { 0 };
        assert_eq!(out.status.code(), Some(expected_exit), "{}", f.display());
        let diags: Vec<serde_json::Value> = serde_json::from_slice(&out.stdout).unwrap();
        assert!(
            diags.iter().any(|d| d["code"] == code.as_str()
                && d["line"] == line
                && d["file"] == f.display().to_string().as_str()),
            "{}: no {code} at line {line} in {diags:?}",
            f.display()
        );
        // The human form names the file, line and column like rustc.
        let out = clayc().arg("check").arg(&f).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        let name = Path::new(&f).display().to_string();
        assert!(
            stderr.contains(&format!("[{code}]")) && stderr.contains(&format!("{name}:{line}:")),
            "{stderr}"
        );
    }
}

#[test]
fn several_files_are_checked_and_the_worst_exit_wins() {
    let good = write_temp("good.clay", VALID.as_bytes());
    let warn = fixtures()
        .into_iter()
        .find(|p| p.to_string_lossy().contains("W001"))
        .unwrap();
    let out = clayc().arg("check").arg(&good).arg(&warn).output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&out.stderr).contains("warning[W001]"));
    let bad = fixtures()
        .into_iter()
        .find(|p| p.to_string_lossy().contains("E033"))
        .unwrap();
    let out = clayc().arg("check").arg(&good).arg(&bad).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
}

#[test]
fn a_problem_in_an_imported_file_is_shown_in_that_file() {
    // The library has a typo in a site type; the main file is fine.
    let dir = write_temp("imports.clay", b"")
        .parent()
        .unwrap()
        .to_path_buf();
    std::fs::create_dir_all(dir.join("lib")).unwrap();
    write_temp(
        "lib/bricks.clay",
        VALID
            .replace("model { wall = chain brick x 3 }", "")
            .replace("site east: joint", "site east: jiont")
            .as_bytes(),
    );
    let main = write_temp(
        "imports.clay",
        b"import \"lib/bricks.clay\"\nmodel { wall = chain brick x 3 }\n",
    );
    let lib = main.parent().unwrap().join("lib/bricks.clay");
    let out = clayc()
        .args(["check", "--format", "json"])
        .arg(&main)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let diags: Vec<serde_json::Value> = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(diags.len(), 1, "{diags:?}");
    let d = &diags[0];
    assert_eq!(d["code"], "E011");
    assert_eq!(d["file"], lib.display().to_string().as_str());
    assert_eq!(d["line"], 10);
    assert_eq!(d["labels"][0]["file"], d["file"]);
    let out = clayc().arg("check").arg(&main).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(&format!("{}:10:16", lib.display())) && stderr.contains("jiont"),
        "{stderr}"
    );
}
