//! Every invalid fixture in tests/fixtures/invalid/ renders its diagnostics as snapshotted
//! (no colour), and reports the code its header promises at the promised line.

use std::path::{Path, PathBuf};

use clay_dsl::{Loader, compile_bytes_with, line_col, render};

/// Reads imports of the fixtures (shown as `tests/fixtures/invalid/...`) from the workspace
/// root, whatever the test's working directory.
struct FromRoot;

impl Loader for FromRoot {
    fn load(&self, path: &str) -> std::io::Result<Vec<u8>> {
        std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(path))
    }
}

fn fixtures() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fixtures/invalid");
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

#[test]
fn fixtures_report_their_code_at_their_line_and_match_snapshots() {
    let files = fixtures();
    assert!(!files.is_empty());
    for path in files {
        let bytes = std::fs::read(&path).unwrap();
        let (code, line) = expectation(&bytes);
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        let shown = format!("tests/fixtures/invalid/{name}.clay");
        let diags = match compile_bytes_with(&bytes, &shown, &FromRoot) {
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
