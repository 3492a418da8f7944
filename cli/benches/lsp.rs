//! Criterion benchmark of `clayc lsp`'s re-check after a keystroke (issue 19: within 200 ms at
//! 3,000 instances): a generated grammar of 3,000 docked instances, changed by one character,
//! analysed against the analysis of the text before (`Analysis::with_previous`, as the server
//! does) and its diagnostics converted to the protocol's (the server's own `convert` module).
//! Two changes: one that keeps the text valid (a digit of a coordinate), and one that breaks
//! its syntax in the middle of the model (the borrowed-tail path). Figures are in
//! docs/performance.md.

use std::fmt::Write;
use std::str::FromStr;
use std::time::Duration;

use clay_dsl::analysis::Analysis;
use criterion::{Criterion, criterion_group, criterion_main};

#[allow(dead_code)] // the bench uses the diagnostics' part of it
#[path = "../src/lsp/convert.rs"]
mod convert;

const ROWS: usize = 60;
const PER_ROW: usize = 50;

/// A wall of `ROWS` rows of `PER_ROW` bricks: the first of each row placed with `at`, every
/// other docked to its neighbour (3,000 instances, 2,940 docks).
fn grammar() -> String {
    let mut text = String::from(
        "// generated: 60 rows of 50 docked bricks\nsite type joint\n\npiece brick {\n    \
         vertex sw (0, 0)\n    vertex se (1, 0)\n    vertex ne (1, 0.5)\n    vertex nw (0, 0.5)\n    \
         edges sw-se-ne-nw-sw, sw-ne\n    site west: joint [nw, sw] out (-1, 0)\n    \
         site east: joint [se, ne] out (1, 0)\n    polygon rigid fill #b5651d {\n        \
         (0.03, 0.03) (0.97, 0.03) (0.97, 0.47) (0.03, 0.47)\n    }\n}\n\nmodel {\n",
    );
    for r in 0..ROWS {
        let _ = writeln!(text, "    b{r}_0 = brick at (0, {})", 2 * r);
        for i in 1..PER_ROW {
            let _ = writeln!(text, "    b{r}_{i} = brick");
            let _ = writeln!(text, "    dock b{r}_{i}.west to b{r}_{}.east", i - 1);
        }
    }
    text.push_str("}\n");
    text
}

fn bench(c: &mut Criterion) {
    let uri = lsp_types::Uri::from_str("file:///bench/wall3000.clay").unwrap();
    let text = grammar();
    let first = Analysis::new(&text, "wall3000.clay");
    assert!(first.diagnostics().is_empty(), "{:?}", first.diagnostics());
    assert!(first.parses());

    // A coordinate's digit: `at (0, 60)` -> `at (0, 61)` (still valid, one row moved).
    let valid = text.replacen("at (0, 60)", "at (0, 61)", 1);
    assert_eq!(valid.len(), text.len());
    // A dot typed mid-model: `dock b30_1.west` -> `dock b30_1..west` breaks the syntax.
    let broken = text.replacen("dock b30_1.west", "dock b30_1..west", 1);

    let mut g = c.benchmark_group("lsp_recheck_3000_instances");
    g.sample_size(20).measurement_time(Duration::from_secs(8));
    g.bench_function("valid_change", |b| {
        b.iter(|| {
            let a = Analysis::with_previous(&valid, "wall3000.clay", &first);
            convert::diagnostics(&uri, a.line_index(), a.diagnostics())
        })
    });
    g.bench_function("syntax_error", |b| {
        b.iter(|| {
            let a = Analysis::with_previous(&broken, "wall3000.clay", &first);
            let d = convert::diagnostics(&uri, a.line_index(), a.diagnostics());
            assert_eq!(d.len(), 1);
            d
        })
    });
    // The floor: what `clayc check` does with the same text (parse and compile).
    g.bench_function("compile_only", |b| {
        b.iter(|| {
            clay_dsl::compile(
                &valid,
                "wall3000.clay",
                &clay_dsl::CompileOptions::default(),
            )
            .is_ok()
        })
    });
    g.finish();

    // Issue 47: the semantic tokens of one 200 KB line (a polygon of 12,000 points written on
    // one line, with a non-ASCII comment before it) took 29 s while positions were counted
    // from the line's start; counted from the line index's marks they cost their distance.
    let long = long_line_grammar();
    assert!(long.len() > 200_000);
    let a = Analysis::new(&long, "long.clay");
    assert!(a.diagnostics().is_empty(), "{:?}", a.diagnostics());
    let mut g = c.benchmark_group("lsp_long_line");
    g.sample_size(10).measurement_time(Duration::from_secs(5));
    g.bench_function("semantic_tokens_200kb_line", |b| {
        b.iter(|| convert::semantic_tokens(a.line_index(), &a.semantic_tokens()).len())
    });
    g.finish();
}

/// A piece whose polygon's 12,000 points are on one line.
fn long_line_grammar() -> String {
    let mut points = String::new();
    for k in 0..12_000 {
        let t = k as f64 / 12_000.0 * std::f64::consts::TAU;
        let _ = write!(points, "({:.4}, {:.4}) ", t.cos(), t.sin());
    }
    format!(
        "site type joint\n\npiece disc {{\n    // a disc: é\n    vertex a (0, 0)\n    \
         vertex b (1, 0)\n    vertex c (0, 1)\n    edges a-b-c-a\n    polygon rigid fill #888888 {{ {points}}}\n}}\n\n\
         model {{\n    d = disc\n}}\n"
    )
}

criterion_group!(benches, bench);
criterion_main!(benches);
