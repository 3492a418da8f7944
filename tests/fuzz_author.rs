//! The fuzzer of `clayc author` (issue 37, item 5): seeded in-process mutation of every SVG in
//! the repository and of drawings that broke authoring (self-intersecting paths, shapes drawn
//! on top of each other, clashing ids), through the steps `clayc author` and the editor run
//! (`drawing_from_svg`, then `work::compute`, plain, with `--stretch` or with a cut) and the
//! library's `author`. Properties: no panic; no case over the engine's hang guard; and either
//! an error or a grammar that `clay_dsl::compile` accepts with no error. The grammar is checked
//! as authoring makes it, before `clayc author`'s own last-line check, so a cause that check
//! would hide is found here.
//!
//! Mutations are both the engine's byte edits and edits that keep the SVG readable: numbers
//! nudged, copied, zeroed or made huge; elements copied (moved, turned), removed, or new ones
//! drawn on a coarse grid so that they share corners and edges; ids from a pool of names that
//! clash. `CLAY_FUZZ_CASES=N` runs N cases (default 10,000, which CI runs in debug),
//! `CLAY_FUZZ_SEED` another seed.

#[allow(dead_code)] // the engine's plain `fuzz` is the other targets'
mod fuzzing;

use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use clay::{
    authoring::AuthorOptions, authoring::StretchChoice, authoring::Work, authoring::author,
    authoring::compute, authoring::drawing_from_svg,
};
use glam::DVec2;
use proptest::prelude::RngExt;
use proptest::test_runner::TestRng;

/// Cases by default: CI runs this target in its debug build, where a case takes about half a
/// millisecond (10,000 cases: 6 s on two shared cores).
const DEFAULT_CASES: usize = 10_000;

fn svgs_under(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        let skip = p
            .file_name()
            .is_some_and(|n| n == "target" || n.to_string_lossy().starts_with('.'));
        if p.is_dir() && !skip {
            svgs_under(&p, out);
        } else if p.extension().is_some_and(|x| x == "svg") {
            out.push(p);
        }
    }
}

/// A closed path through `points` (SVG units).
fn path(id: &str, points: &[(f64, f64)]) -> String {
    let d: Vec<String> = points
        .iter()
        .enumerate()
        .map(|(i, (x, y))| format!("{}{x:.3} {y:.3}", if i == 0 { "M" } else { "L" }))
        .collect();
    format!("<path id=\"{id}\" d=\"{} Z\"/>", d.join(" "))
}

fn svg(body: &str) -> String {
    format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"1000\" height=\"1000\">\n{body}\n</svg>\n"
    )
}

/// A star polygon of `n` corners: every edge crosses many others.
fn star(n: usize) -> String {
    let k = n / 2 - 1;
    let pts: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * (i * k % n) as f64 / n as f64;
            (500.0 + 400.0 * a.cos(), 500.0 + 400.0 * a.sin())
        })
        .collect();
    svg(&path("star", &pts))
}

/// The drawings that broke authoring, small enough to mutate often.
fn found() -> Vec<String> {
    let rect = |id: &str, x: f64, y: f64, w: f64, h: f64| {
        format!("<rect id=\"{id}\" x=\"{x}\" y=\"{y}\" width=\"{w}\" height=\"{h}\"/>")
    };
    let zigzag: Vec<(f64, f64)> = (0..400)
        .map(|i| (i as f64 * 2.5, if i % 2 == 0 { 0.0 } else { 100.0 }))
        .chain([(1000.0, 50.0), (0.0, 50.0)])
        .collect();
    vec![
        star(201),
        svg(&path("zigzag", &zigzag)),
        // Three stacked copies and a neighbour: a site docked twice (E034).
        svg(&[
            rect("a", 0.0, 0.0, 100.0, 50.0),
            rect("b", 0.0, 0.0, 100.0, 50.0),
            rect("c", 100.0, 0.0, 100.0, 50.0),
            rect("d", 100.0, 0.0, 100.0, 50.0),
        ]
        .join("\n")),
        // A ring of bricks around a square: docks that close a loop.
        svg(&[
            rect("brick", 0.0, 0.0, 100.0, 50.0),
            rect("brick", 100.0, 0.0, 50.0, 100.0),
            rect("brick", 50.0, 100.0, 100.0, 50.0),
            rect("brick", 0.0, 50.0, 50.0, 100.0),
            rect("core", 50.0, 50.0, 50.0, 50.0),
        ]
        .join("\n")),
        // Near-congruent tiles turned by odd angles, sharing edges.
        svg("<g transform=\"rotate(17 100 100)\"><rect x=\"0\" y=\"0\" width=\"100\" height=\"50\"/><rect x=\"100\" y=\"0\" width=\"100.05\" height=\"50\"/><rect x=\"0\" y=\"50\" width=\"100.04\" height=\"50\"/><rect x=\"100.04\" y=\"50\" width=\"99.99\" height=\"50\"/></g>"),
        // Pieces of the grammar's keywords and names that clash once numbered.
        svg(&(0..14)
            .map(|i| rect(["model", "piece", "x_chain", "a1", "a"][i % 5], i as f64 * 10.0, 0.0, 10.0, 10.0 + (i % 3) as f64))
            .collect::<Vec<_>>()
            .join("\n")),
        // Pieces to splice in.
        "<rect x=\"0\" y=\"0\" width=\"100\" height=\"50\"/> <g transform=\"rotate(30)\"> </g> <path d=\"M 0 0 L 10 10 L 10 0 L 0 10 Z\"/> <circle cx=\"50\" cy=\"50\" r=\"20\"/> id=\"brick\" transform=\"scale(1e6)\"".into(),
    ]
}

fn corpus() -> Vec<Vec<u8>> {
    let mut files = Vec::new();
    svgs_under(Path::new(env!("CARGO_MANIFEST_DIR")), &mut files);
    files.sort();
    let mut corpus: Vec<Vec<u8>> = files.iter().filter_map(|f| std::fs::read(f).ok()).collect();
    assert!(
        corpus.len() >= 5,
        "the repository's SVGs are the corpus: {files:?}"
    );
    corpus.extend(found().into_iter().map(String::into_bytes));
    corpus
}

/// Byte ranges of the numbers in `text`.
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let start = i;
        if b[i] == b'-' && b.get(i + 1).is_some_and(u8::is_ascii_digit) {
            i += 1;
        }
        // Not the digits of a name (`brick1`); a path command may precede a number (`M10`).
        let in_name = start > 0
            && b[start - 1].is_ascii_alphabetic()
            && !b"MLHVCSQTAZmlhvcsqtaz".contains(&b[start - 1]);
        if b[i].is_ascii_digit() && !in_name {
            while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
                i += 1;
            }
            if i < b.len()
                && b[i] == b'e'
                && b.get(i + 1)
                    .is_some_and(|c| c.is_ascii_digit() || *c == b'-')
            {
                i += 2;
                while i < b.len() && b[i].is_ascii_digit() {
                    i += 1;
                }
            }
            out.push((start, i));
        } else {
            i = start + 1;
        }
    }
    out
}

/// Byte ranges of the drawing elements in `text` (`<rect .../>`, `<path .../>`, ...).
fn elements(text: &str) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    for tag in [
        "<rect",
        "<path",
        "<circle",
        "<ellipse",
        "<polygon",
        "<polyline",
        "<use",
    ] {
        for (at, _) in text.match_indices(tag) {
            if let Some(end) = text[at..].find("/>") {
                out.push((at, at + end + 2));
            }
        }
    }
    out.sort_unstable();
    out
}

const IDS: &[&str] = &[
    "brick", "brick1", "Brick-2", "piece", "piece1", "piece11", "model", "a1", "a", "_", "9",
    "x_chain", "base", "v0", "joint", "é",
];

/// One readable edit of an SVG.
fn edit(rng: &mut TestRng, text: &mut String) {
    let grid = |rng: &mut TestRng| rng.random_range(0..12) as f64 * 10.0;
    match rng.random_range(0..6) {
        0 | 1 => {
            let ns = numbers(text);
            if ns.is_empty() {
                return;
            }
            let (s, e) = ns[rng.random_range(0..ns.len())];
            let old: f64 = text[s..e].parse().unwrap_or(0.0);
            let new = match rng.random_range(0..9) {
                0 => "0".to_string(),
                1 => format!("{}", -old),
                2 => format!(
                    "{}",
                    old + [0.001, 0.05, 0.5, 1.0, 10.0][rng.random_range(0..5)]
                ),
                3 => "1e7".into(),
                4 => "1e-4".into(),
                5 => "NaN".into(),
                6 => {
                    let (s2, e2) = ns[rng.random_range(0..ns.len())];
                    text[s2..e2].to_string()
                }
                7 => format!("{}", old * 2.0),
                _ => format!("{}", grid(rng)),
            };
            text.replace_range(s..e, &new);
        }
        2 => {
            let es = elements(text);
            if es.is_empty() {
                return;
            }
            let (s, e) = es[rng.random_range(0..es.len())];
            let copy = text[s..e].to_string();
            let e = e.min(text.len());
            let wrapped = match rng.random_range(0..4) {
                0 => copy,
                1 => format!(
                    "<g transform=\"translate({} {})\">{copy}</g>",
                    grid(rng),
                    grid(rng)
                ),
                2 => format!(
                    "<g transform=\"rotate({} 50 50)\">{copy}</g>",
                    [90, 180, 30, 45][rng.random_range(0..4)]
                ),
                _ => format!(
                    "<g transform=\"scale({})\">{copy}</g>",
                    [2.0, 0.5, 1e-3, 1e5][rng.random_range(0..4)]
                ),
            };
            text.insert_str(e, &wrapped);
        }
        3 => {
            let es = elements(text);
            if !es.is_empty() {
                let (s, e) = es[rng.random_range(0..es.len())];
                text.replace_range(s..e, "");
            }
        }
        4 => {
            let id = IDS[rng.random_range(0..IDS.len())];
            let shape = match rng.random_range(0..3) {
                0 => {
                    let (w, h) = (grid(rng) + 10.0, grid(rng) + 10.0);
                    format!(
                        "<rect id=\"{id}\" x=\"{}\" y=\"{}\" width=\"{w}\" height=\"{h}\"/>",
                        grid(rng),
                        grid(rng)
                    )
                }
                1 => {
                    let pts: Vec<(f64, f64)> = (0..rng.random_range(3..8))
                        .map(|_| (grid(rng), grid(rng)))
                        .collect();
                    path(id, &pts)
                }
                _ => format!(
                    "<circle id=\"{id}\" cx=\"{}\" cy=\"{}\" r=\"{}\"/>",
                    grid(rng),
                    grid(rng),
                    grid(rng) + 5.0
                ),
            };
            match text.rfind("</svg>") {
                Some(at) => text.insert_str(at, &shape),
                None => text.push_str(&shape),
            }
        }
        _ => {
            let id = IDS[rng.random_range(0..IDS.len())];
            let es = elements(text);
            if !es.is_empty() {
                let (s, _) = es[rng.random_range(0..es.len())];
                let at = text[s..].find(' ').map_or(s, |k| s + k);
                text.insert_str(at, &format!(" id=\"{id}\""));
            }
        }
    }
}

/// Either the engine's byte edits or one to four readable edits.
fn mutate(rng: &mut TestRng, input: &[u8], corpus: &[Vec<u8>]) -> Vec<u8> {
    match (rng.random_range(0..4), std::str::from_utf8(input)) {
        (1.., Ok(text)) => {
            let mut text = text.to_string();
            for _ in 0..rng.random_range(1..=4) {
                edit(rng, &mut text);
            }
            text.into_bytes()
        }
        _ => fuzzing::mutate(rng, input, corpus),
    }
}

/// A compiled grammar with no error, or the codes and the first error.
fn checks(text: &str) -> Result<(), String> {
    match clay_dsl::compile(text, "authored.clay", &clay_dsl::CompileOptions::default()) {
        Ok(_) => Ok(()),
        Err(d) => {
            let rendered = clay_dsl::render(&d, text, "authored.clay", false);
            let head: String = rendered.lines().take(30).collect::<Vec<_>>().join("\n");
            Err(format!("the authored grammar does not check:\n{head}"))
        }
    }
}

/// Cases that were not an SVG, that authoring refused, and that became a grammar.
static NOT_SVG: AtomicUsize = AtomicUsize::new(0);
static REFUSED: AtomicUsize = AtomicUsize::new(0);
static AUTHORED: AtomicUsize = AtomicUsize::new(0);

/// The property of one input, in the way its bytes choose: plain, with a stretch, or cut at
/// the middle of the first stroke's first edge.
fn authoring(input: &[u8]) -> Result<(), String> {
    let Ok(drawing) = std::str::from_utf8(input)
        .map_err(|e| e.to_string())
        .and_then(|text| drawing_from_svg(text, 0.01).map_err(|e| e.to_string()))
    else {
        NOT_SVG.fetch_add(1, Ordering::Relaxed);
        return Ok(());
    };
    let how = input
        .iter()
        .fold(0u8, |h, b| h.wrapping_mul(31).wrapping_add(*b))
        % 3;
    let first = &drawing.polylines[0].points;
    let cut = (how == 2 && first.len() >= 2).then(|| (first[0] + first[1]) / 2.0);
    let work = Work {
        drawing: drawing.clone(),
        stretch: (how == 1).then_some(StretchChoice::Auto),
        cuts: cut.into_iter().collect::<Vec<DVec2>>(),
        ..Work::default()
    };
    match compute(&work) {
        // A declaration the drawing cannot take is refused by `clayc author` (exit 1).
        Ok(computed)
            if !computed
                .design
                .notes
                .iter()
                .any(|n| n.contains("no longer applies")) =>
        {
            checks(&computed.text).map_err(|e| format!("work::compute ({how}): {e}"))?;
            AUTHORED.fetch_add(1, Ordering::Relaxed);
        }
        _ => {
            REFUSED.fetch_add(1, Ordering::Relaxed);
        }
    }
    let options = AuthorOptions {
        cuts: cut.into_iter().collect(),
        stretch: (how == 1).then_some(StretchChoice::Auto),
        ..AuthorOptions::default()
    };
    if let Ok(authored) = author(&drawing, &options) {
        checks(&authored.text).map_err(|e| format!("authoring::author ({how}): {e}"))?;
    }
    Ok(())
}

#[test]
fn svgs_mutated_author_grammars_that_check_or_clear_errors() {
    fuzzing::fuzz_cases(
        "author",
        fuzzing::cases_or(DEFAULT_CASES),
        corpus(),
        mutate,
        authoring,
    );
    let count = |c: &AtomicUsize| c.load(Ordering::Relaxed);
    eprintln!(
        "author: {} not SVG or no path, {} refused with an error, {} authored and checked clean",
        count(&NOT_SVG),
        count(&REFUSED),
        count(&AUTHORED)
    );
}
