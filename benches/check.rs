//! Criterion benchmark of `clayc check`'s work, parse and compile (`clay_dsl::compile`), on a
//! synthetic grammar of 10,000 pieces (`clay::synthetic::grammar_text`: stretch roads, tee
//! junctions with merge and cut rules, bendable segments and posts with a second rest state,
//! and a model using them all), and on one of 1,000 pieces to show how the time grows. With
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
                let compiled = clay_dsl::compile(black_box(&text), "synthetic.clay")
                    .expect("the synthetic grammar compiles");
                assert!(compiled.warnings.is_empty());
                compiled.grammar.pieces.len()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, compile);

fn main() {
    if let Some(path) = std::env::var_os("CLAY_GRAMMAR") {
        std::fs::write(&path, synthetic::grammar_text(PIECES)).expect("write the grammar");
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
