//! The fuzzing engine the fuzz tests share (`tests/fuzz.rs`, `editor/tests/fuzz_sessions.rs`):
//! seeded mutation of a corpus and a runner that reports a panic, a failed property or a hang
//! with the input that did it. `CLAY_FUZZ_CASES=N` runs N cases (default 10,000, or what a
//! slower target gives [`fuzz_cases`]), `CLAY_FUZZ_SEED` another seed.

use std::sync::mpsc;
use std::time::Duration;

use proptest::prelude::RngExt;
use proptest::test_runner::{RngAlgorithm, TestRng};

/// Longer than any case may take: a case over it is reported as a hang.
pub const HANG: Duration = Duration::from_secs(20);

/// Runs `check` on its own thread: its outcome, a panic's text, or a hang when it takes
/// longer than [`HANG`].
pub fn within_hang(
    check: impl FnOnce() -> Result<(), String> + Send + 'static,
) -> Result<(), String> {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(check))
            .unwrap_or_else(|p| Err(format!("panic: {}", panic_text(p.as_ref()))));
        let _ = tx.send(outcome);
    });
    rx.recv_timeout(HANG)
        .unwrap_or_else(|_| Err(format!("ran over {HANG:?}")))
}

/// Text that is likely to matter to the parsers: comment and bracket openers, multi-byte
/// characters, a byte-order mark, odd numbers, keywords.
pub const TOKENS: &[&str] = &[
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

pub fn cases() -> usize {
    cases_or(10_000)
}

/// `CLAY_FUZZ_CASES`, else `default`.
pub fn cases_or(default: usize) -> usize {
    std::env::var("CLAY_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

pub fn seed() -> u64 {
    std::env::var("CLAY_FUZZ_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(37)
}

pub fn rng(seed: u64) -> TestRng {
    let mut bytes = [0u8; 32];
    bytes[..8].copy_from_slice(&seed.to_le_bytes());
    TestRng::from_seed(RngAlgorithm::ChaCha, &bytes)
}

/// One mutation of `input`: a few edits, each a byte flip, an insertion of a token or a byte,
/// a deletion, a duplication, or a splice from another corpus entry; rarely (issue 47: every
/// linear-time claim on long single lines) the whole input folded onto one line, or a token
/// repeated thousands of times on one.
pub fn mutate(rng: &mut TestRng, input: &[u8], corpus: &[Vec<u8>]) -> Vec<u8> {
    let mut s = input.to_vec();
    for _ in 0..rng.random_range(1..=4) {
        let at = rng.random_range(0..=s.len());
        if rng.random_range(0..64) == 0 {
            if rng.random() {
                for b in s.iter_mut().filter(|b| **b == b'\n') {
                    *b = b' ';
                }
            } else {
                let t = TOKENS[rng.random_range(0..TOKENS.len())];
                let n = rng.random_range(1000..5000);
                s.splice(at..at, t.repeat(n).bytes().collect::<Vec<_>>());
            }
            continue;
        }
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
pub fn fuzz(name: &str, corpus: Vec<Vec<u8>>, check: fn(&[u8]) -> Result<(), String>) {
    fuzz_cases(name, cases(), corpus, mutate, check);
}

/// How a case's input is made from a corpus entry (the whole corpus is there for splices).
pub type Mutator = fn(&mut TestRng, &[u8], &[Vec<u8>]) -> Vec<u8>;

/// [`fuzz`] over `n` cases (say `cases_or(500)` for a slow target) with a mutator that may
/// know the inputs' structure. A failing input is also written to a file in the temporary
/// folder, whose path the message gives: the message shows binary input only lossily.
pub fn fuzz_cases(
    name: &str,
    n: usize,
    corpus: Vec<Vec<u8>>,
    mutate: Mutator,
    check: fn(&[u8]) -> Result<(), String>,
) {
    let seed = seed();
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
                    "{name}, case {i} (seed {seed}): {why}\ninput: {:?}\nsaved: {}",
                    lossy(&input),
                    keep(name, seed, i, &input)
                )
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => break,
            Err(mpsc::RecvTimeoutError::Timeout) => panic!(
                "{name} (seed {seed}): a case ran over {HANG:?}\ninput: {:?}\nsaved: {}",
                current.as_deref().map(lossy),
                keep(name, seed, done, current.as_deref().unwrap_or_default())
            ),
        }
    }
    assert_eq!(done, n, "{name}: every case ran");
}

/// Writes a failing input to a file, byte for byte; where.
fn keep(name: &str, seed: u64, case: usize, input: &[u8]) -> String {
    let path = std::env::temp_dir().join(format!("clay-fuzz-{name}-{seed}-{case}.bin"));
    match std::fs::write(&path, input) {
        Ok(()) => path.display().to_string(),
        Err(e) => format!("nowhere ({e})"),
    }
}

pub fn lossy(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

pub fn panic_text(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_default()
}
