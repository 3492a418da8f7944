//! The fuzzer the project keeps (issue 37): seeded in-process mutation of every example and
//! fixture grammar and script, fed to the grammar parser, compiler, formatter and editor
//! analysis and to the script parser. Properties: no panic; no input that takes longer than
//! `HANG` (a hang guard, not a speed bound: a case takes milliseconds); every grammar diagnostic
//! on char boundaries of its file with a 1-based line and column, and rendered; `fmt`
//! idempotent and meaning-preserving. `CLAY_FUZZ_CASES=N` runs N cases (default 10,000),
//! `CLAY_FUZZ_SEED` another seed; a failure prints the input (escaped) to reproduce it.

mod fuzzing;
#[path = "fuzzing/located.rs"]
mod located;

use std::path::{Path, PathBuf};

use fuzzing::fuzz;
use located::located;

fn files_under(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            files_under(&p, ext, out);
        } else if p.extension().is_some_and(|x| x == ext) {
            out.push(p);
        }
    }
}

/// Every example and fixture of `ext` in the repository, and `extra`.
fn corpus(ext: &str, extra: &[&str]) -> Vec<Vec<u8>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for dir in ["grammars", "tests/fixtures", "dsl/tests", "docs"] {
        files_under(&root.join(dir), ext, &mut files);
    }
    files.sort();
    let mut corpus: Vec<Vec<u8>> = files.iter().filter_map(|f| std::fs::read(f).ok()).collect();
    corpus.extend(extra.iter().map(|s| s.as_bytes().to_vec()));
    assert!(
        corpus.len() > extra.len(),
        "the corpus has the repository's {ext} files"
    );
    corpus
}

/// The grammar properties of one input (an input that is not UTF-8 is an E003 diagnostic).
fn grammar(input: &[u8]) -> Result<(), String> {
    let text = match std::str::from_utf8(input) {
        Ok(t) => t,
        Err(_) => return Ok(()),
    };
    let path = "fuzz.clay";
    let compiled = clay_dsl::compile(text, path);
    match &compiled {
        Ok(c) => located(&c.warnings, text, path)?,
        Err(d) => located(d, text, path)?,
    }
    let _ = clay_dsl::analysis::Analysis::new(text, path);
    if let Ok(formatted) = clay_dsl::format(text) {
        match clay_dsl::format(&formatted) {
            Ok(again) if again == formatted => {}
            Ok(_) => return Err("fmt is not idempotent".into()),
            Err(_) => return Err("fmt's output does not parse".into()),
        }
        let before = compiled.as_ref().map(|c| &c.grammar).ok();
        let after = clay_dsl::compile(&formatted, path);
        match (before, after.as_ref().map(|c| &c.grammar).ok()) {
            (Some(a), Some(b)) if a != b => {
                return Err("fmt changed the compiled grammar".into());
            }
            (Some(_), None) => return Err("fmt's output does not compile".into()),
            (None, Some(_)) => return Err("fmt's output compiles where the input did not".into()),
            _ => {}
        }
    }
    Ok(())
}

/// The script parser: an error has a 1-based position when it has one.
fn script(input: &[u8]) -> Result<(), String> {
    let Ok(text) = std::str::from_utf8(input) else {
        return Ok(());
    };
    match clay::Script::parse(text) {
        Ok(_) => Ok(()),
        Err(e) => match e.position {
            Some((line, col)) if line == 0 || col == 0 => {
                Err(format!("error at {line}:{col}: {e}"))
            }
            _ => Ok(()),
        },
    }
}

#[test]
fn grammars_mutated_never_panic_hang_or_misplace_a_diagnostic() {
    let found = [
        "solver {\n    merge_distance = // in m²\n}\n",
        "piece\u{feff}x",
        &"/* ".repeat(30),
    ];
    fuzz("grammar", corpus("clay", &found), grammar);
}

#[test]
fn scripts_mutated_never_panic_or_hang() {
    let found = [
        "",
        " ",
        "{\"steps\": [{\"drag\": {\"by\": [1e308, -1e308], \"frames\": 18446744073709551615}}]}",
    ];
    fuzz("script", corpus("json", &found), script);
}
