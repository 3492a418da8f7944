//! Criterion benchmark of `clayc check`'s work, parse and compile (`clay_dsl::compile`), on a
//! synthetic grammar of 10,000 pieces (`clay::synthetic::grammar_text`: stretch roads, tee
//! junctions with merge and cut rules, bendable segments and posts with a second rest state,
//! and a model using them all), and on one of 1,000 pieces to show how the time grows; and on
//! one piece of 10,000 and of 100,000 vertices (a ladder: each vertex, edge and state position
//! found by name; issue 47 measured 29 s for 100,000, quadratic, before the lookups). With
//! `CLAY_GRAMMAR=<path>` set it instead writes the 10,000-piece grammar there (to time
//! `clayc check` on it) and exits.

use std::hint::black_box;
use std::time::Duration;

use clay::synthetic;
use criterion::{Criterion, Throughput, criterion_group};

const PIECES: usize = 10_000;

fn compile(c: &mut Criterion) {
    let mut group = c.benchmark_group("compile");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(8));
    for pieces in [1_000, PIECES] {
        let text = synthetic::grammar_text(pieces);
        group.throughput(Throughput::Bytes(text.len() as u64));
        group.bench_function(format!("pieces/{pieces}"), |b| {
            b.iter(|| {
                let compiled = clay_dsl::compile(
                    black_box(&text),
                    "synthetic.clay",
                    &clay_dsl::CompileOptions::default(),
                )
                .expect("the synthetic grammar compiles");
                assert!(compiled.warnings.is_empty());
                compiled.grammar.pieces.len()
            })
        });
    }
    group.finish();
}

/// A ladder piece of `rungs` rungs (two vertices each), every bay braced, with a state that
/// lists every vertex.
fn ladder(rungs: usize) -> String {
    let mut s = String::from("site type joint\npiece big {\n");
    for i in 0..rungs {
        s += &format!("    vertex b{i} ({i}, 0)\n    vertex t{i} ({i}, 1)\n");
    }
    let bottom: Vec<String> = (0..rungs).map(|i| format!("b{i}")).collect();
    let top: Vec<String> = (0..rungs).rev().map(|i| format!("t{i}")).collect();
    s += &format!("    edges {}-{}-b0", bottom.join("-"), top.join("-"));
    for i in 0..rungs - 1 {
        s += &format!(", b{i}-t{}", i + 1);
    }
    s += "\n    state lifted {\n";
    for i in 0..rungs {
        s += &format!("        b{i} ({i}, 1)\n        t{i} ({i}, 2)\n");
    }
    s += "    }\n}\nmodel {\n    a = big\n}\n";
    s
}

fn large_piece(c: &mut Criterion) {
    let mut group = c.benchmark_group("large piece");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(5));
    for vertices in [10_000, 100_000] {
        let text = ladder(vertices / 2);
        group.throughput(Throughput::Elements(vertices as u64));
        group.bench_function(format!("vertices/{vertices}"), |b| {
            b.iter(|| {
                let compiled = clay_dsl::compile(
                    black_box(&text),
                    "big.clay",
                    &clay_dsl::CompileOptions::default(),
                )
                .expect("the ladder compiles");
                compiled.grammar.pieces[0].vertices.len()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, compile, large_piece);

fn main() {
    if let Some(path) = std::env::var_os("CLAY_GRAMMAR") {
        std::fs::write(&path, synthetic::grammar_text(PIECES)).expect("write the grammar");
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
