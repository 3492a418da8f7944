//! The fuzzer the project keeps (issue 37): seeded in-process mutation of every example and
//! fixture grammar and script, fed to the grammar parser, compiler, formatter and editor
//! analysis and to the script parser. Properties: no panic; no input that takes longer than
//! `HANG` (a hang guard, not a speed bound: a case takes milliseconds); every grammar diagnostic
//! on char boundaries of its file with a 1-based line and column, and rendered; `fmt`
//! idempotent and meaning-preserving. `CLAY_FUZZ_CASES=N` runs N cases (default 10,000),
//! `CLAY_FUZZ_SEED` another seed; a failure prints the input (escaped) to reproduce it.

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

use proptest::prelude::RngExt;
use proptest::test_runner::{RngAlgorithm, TestRng};

/// Longer than any case may take: a case over it is reported as a hang.
const HANG: Duration = Duration::from_secs(20);

/// Text that is likely to matter to the parsers: comment and bracket openers, multi-byte
/// characters, a byte-order mark, odd numbers, keywords.
const TOKENS: &[&str] = &[
    "/*",
    "*/",
    "//",
    "{",
    "}",
    "(",
    ")",
    "[",
    "]",
    ",",
    "=",
    "->",
    "\"",
    "\n",
    "\t",
    " ",
    "m²",
    "é",
    "\u{feff}",
    "🧱",
    "\r\n",
    "1e308",
    "-0",
    "0.0000001",
    "1e-320",
    "NaN",
    "inf",
    "999999999999999999999",
    "piece",
    "site",
    "vertex",
    "edges",
    "state",
    "stretch",
    "merge",
    "cut",
    "model",
    "chain",
    "x 1000000",
    "import",
    "let",
    "solver",
    "mesh",
    "hole",
    "extends",
    "bend",
    "mirror",
    "min",
    "max",
    "variants",
    "dock",
    "at",
    "rotate",
    "along",
];

fn cases() -> usize {
    std::env::var("CLAY_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(10_000)
}

fn seed() -> u64 {
    std::env::var("CLAY_FUZZ_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(37)
}

fn rng(seed: u64) -> TestRng {
    let mut bytes = [0u8; 32];
    bytes[..8].copy_from_slice(&seed.to_le_bytes());
    TestRng::from_seed(RngAlgorithm::ChaCha, &bytes)
}

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

/// One mutation of `input`: a few edits, each a byte flip, an insertion of a token or a byte,
/// a deletion, a duplication, or a splice from another corpus entry.
fn mutate(rng: &mut TestRng, input: &[u8], corpus: &[Vec<u8>]) -> Vec<u8> {
    let mut s = input.to_vec();
    for _ in 0..rng.random_range(1..=4) {
        let at = rng.random_range(0..=s.len());
        match rng.random_range(0..7) {
            0 if !s.is_empty() => {
                let i = at.min(s.len() - 1);
                s[i] ^= 1 << rng.random_range(0..8);
            }
            1 => {
                let t = TOKENS[rng.random_range(0..TOKENS.len())];
                s.splice(at..at, t.bytes());
            }
            2 => s.insert(at, rng.random()),
            3 => {
                let end = (at + rng.random_range(0..64)).min(s.len());
                s.drain(at..end);
            }
            4 => {
                let end = (at + rng.random_range(0..256)).min(s.len());
                let copy = s[at..end].to_vec();
                s.splice(at..at, copy);
            }
            5 => {
                let other = &corpus[rng.random_range(0..corpus.len())];
                let from = rng.random_range(0..=other.len());
                let end = (from + rng.random_range(0..512)).min(other.len());
                s.splice(at..at, other[from..end].iter().copied());
            }
            _ => {
                let t = TOKENS[rng.random_range(0..TOKENS.len())];
                let n = rng.random_range(1..64);
                s.splice(at..at, t.repeat(n).bytes().collect::<Vec<_>>());
            }
        }
    }
    s
}

/// Runs `check` on every case's input in a worker thread; a panic, a property that fails or
/// a case over `HANG` fails the test with the input that did it.
fn fuzz(name: &str, corpus: Vec<Vec<u8>>, check: fn(&[u8]) -> Result<(), String>) {
    let (n, seed) = (cases(), seed());
    let (tx, rx) = mpsc::channel::<(usize, Vec<u8>, Option<Result<(), String>>)>();
    std::thread::spawn(move || {
        let mut rng = rng(seed);
        for i in 0..n {
            let base = &corpus[rng.random_range(0..corpus.len())];
            let input = mutate(&mut rng, base, &corpus);
            if tx.send((i, input.clone(), None)).is_err() {
                return;
            }
            let outcome = std::panic::catch_unwind(|| check(&input))
                .unwrap_or_else(|p| Err(format!("panic: {}", panic_text(p.as_ref()))));
            if tx.send((i, input, Some(outcome))).is_err() {
                return;
            }
        }
    });
    let mut current = None;
    let mut done = 0;
    loop {
        match rx.recv_timeout(HANG) {
            Ok((_, input, None)) => current = Some(input),
            Ok((_, _, Some(Ok(())))) => done += 1,
            Ok((i, input, Some(Err(why)))) => {
                panic!(
                    "{name}, case {i} (seed {seed}): {why}\ninput: {:?}",
                    lossy(&input)
                )
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => break,
            Err(mpsc::RecvTimeoutError::Timeout) => panic!(
                "{name} (seed {seed}): a case ran over {HANG:?}\ninput: {:?}",
                current.as_deref().map(lossy)
            ),
        }
    }
    assert_eq!(done, n, "{name}: every case ran");
}

fn lossy(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn panic_text(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_default()
}

/// Every diagnostic lies on char boundaries of its file, has a 1-based line and column, and
/// the whole list renders.
fn located(diagnostics: &clay_dsl::Diagnostics, text: &str, path: &str) -> Result<(), String> {
    for d in diagnostics.iter() {
        for span in std::iter::once(&d.primary)
            .chain(&d.secondary)
            .map(|l| l.span)
        {
            let at = diagnostics.sources.locate(text, path, span);
            let ok = at.start <= at.end
                && at.end <= at.text.len()
                && at.text.is_char_boundary(at.start)
                && at.text.is_char_boundary(at.end);
            if !ok {
                return Err(format!(
                    "{} {:?}: span {:?} off its file",
                    d.code, d.message, span
                ));
            }
            let (line, col) = clay_dsl::line_col(at.text, at.start);
            if line == 0 || col == 0 {
                return Err(format!("{} at {line}:{col}", d.code));
            }
        }
    }
    let _ = clay_dsl::render(diagnostics, text, path, false);
    Ok(())
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
    match clay::script::Script::parse(text) {
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
