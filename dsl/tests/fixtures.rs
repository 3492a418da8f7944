//! Every invalid fixture in tests/fixtures/invalid/ renders its diagnostics as snapshotted
//! (no colour), and reports the code its header promises at the promised line. The fixtures in
//! tests/fixtures/overrides/ do the same when compiled with the parameter values of their
//! second line (`// params: NAME=VALUE, ...`): their mistakes are in the values, not the text.

use std::path::{Path, PathBuf};

use clay_dsl::{CompileOptions, Loader, compile, decode_utf8, line_col, render};

/// Reads imports of the fixtures (shown as `tests/fixtures/invalid/...`) from the workspace
/// root, whatever the test's working directory.
struct FromRoot;

impl Loader for FromRoot {
    fn load(&self, path: &str) -> std::io::Result<Vec<u8>> {
        std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(path))
    }
}

fn fixtures() -> Vec<PathBuf> {
    fixtures_in("invalid")
}

fn fixtures_in(folder: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/fixtures")
        .join(folder);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("fixture directory")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "clay"))
        .collect();
    files.sort();
    files
}

/// `// expect: E011 line 18` on the first line.
fn expectation(bytes: &[u8]) -> (String, usize) {
    let text = String::from_utf8_lossy(bytes);
    let first = text.lines().next().unwrap_or_default();
    let rest = first
        .strip_prefix("// expect: ")
        .expect("fixture starts with `// expect: CODE line N`");
    let mut words = rest.split_whitespace();
    let code = words.next().expect("code").to_string();
    assert_eq!(words.next(), Some("line"));
    let line = words.next().expect("line").parse().expect("line number");
    (code, line)
}

#[test]
fn there_is_a_fixture_for_every_code() {
    let names: Vec<String> = fixtures()
        .iter()
        .chain(&fixtures_in("overrides"))
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    assert!(names.len() >= 30, "only {} fixtures", names.len());
    let doc =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/language.md"))
            .unwrap();
    // Every code documented in the table has a fixture.
    for line in doc
        .lines()
        .filter(|l| l.starts_with("| `E") || l.starts_with("| `W"))
    {
        let code = &line[3..7];
        if code == "E999" {
            continue;
        }
        assert!(
            names.iter().any(|n| n.starts_with(code)),
            "no fixture for documented code {code}"
        );
    }
}

/// `// params: bays=20, width=1.5` on the second line.
fn overrides(bytes: &[u8]) -> Vec<(String, clay_dsl::compiled::ParamValue)> {
    let text = String::from_utf8_lossy(bytes);
    let second = text.lines().nth(1).unwrap_or_default();
    let list = second
        .strip_prefix("// params: ")
        .expect("an override fixture's second line is `// params: NAME=VALUE, ...`");
    list.split(", ")
        .map(|pair| {
            let (name, value) = pair.split_once('=').expect("NAME=VALUE");
            (
                name.to_string(),
                clay_dsl::compiled::ParamValue::parse(value),
            )
        })
        .collect()
}

#[test]
fn fixtures_report_their_code_at_their_line_and_match_snapshots() {
    check_fixtures("invalid", |_| Vec::new());
}

#[test]
fn override_fixtures_report_their_code_at_their_line_and_match_snapshots() {
    check_fixtures("overrides", overrides);
}

fn check_fixtures(
    folder: &str,
    params: fn(&[u8]) -> Vec<(String, clay_dsl::compiled::ParamValue)>,
) {
    let files = fixtures_in(folder);
    assert!(!files.is_empty());
    for path in files {
        let bytes = std::fs::read(&path).unwrap();
        let (code, line) = expectation(&bytes);
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        let shown = format!("tests/fixtures/{folder}/{name}.clay");
        let options = CompileOptions {
            loader: &FromRoot,
            params: params(&bytes),
        };
        let diags = match decode_utf8(&bytes).and_then(|s| compile(s, &shown, &options)) {
            Ok(c) => c.warnings,
            Err(d) => d,
        };
        let source = String::from_utf8_lossy(&bytes);
        let hit = diags
            .iter()
            .any(|d| d.code == code && line_col(&source, d.primary.span.start).0 == line);
        assert!(
            hit,
            "{name}: expected {code} at line {line}, got {:?}",
            diags
                .iter()
                .map(|d| (d.code, line_col(&source, d.primary.span.start).0))
                .collect::<Vec<_>>()
        );
        // Errors fail the compile; warning fixtures still compile.
        assert_eq!(code.starts_with('E'), diags.has_errors(), "{name}");
        for d in &diags {
            assert!(
                d.hints.len() + d.secondary.len() > 0 || d.code == "E001",
                "{name}: {} has neither hint nor secondary label",
                d.code
            );
        }
        let rendered = render(&diags, &source, &shown, false);
        insta::assert_snapshot!(name, rendered);
    }
}
