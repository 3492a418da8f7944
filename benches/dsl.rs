//! Criterion benchmark of the compiler's worst cases, the timing the tests leave out (a
//! wall-clock bound in a test fails on a loaded machine; the tests keep what the compiler
//! answers):
//!
//! - `dsl/extends_chain/10000`: a 10,000-deep `extends` chain, one E063
//!   (`dsl/tests/robustness.rs`, `deep_and_cyclic_extends_chains_give_one_error`);
//! - `dsl/extends_cycle/5000`: one cycle of 5,000 pieces, one E062 (the same test);
//! - `dsl/mirror_listed_piece/10000` and `/20000`: a piece of 10,000 or 20,000 vertices with a
//!   listed state and its mirror, whose time should grow near-linearly (`dsl/tests/derived_states.rs`,
//!   `mirroring_a_big_listed_piece_compiles_and_mirrors`);
//! - `dsl/instance_limit/100000`: a chain of `MAX_MODEL_INSTANCES` bricks, the largest model a
//!   grammar may declare (`a_model_at_the_instance_limit_compiles_and_one_more_is_e014`).

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group};

/// `n` pieces, each extending the one before: one error, E063 (too deep).
fn extends_chain(n: usize) -> String {
    let mut src = String::from("piece p0 { vertex a (0, 0) vertex b (1, 0) edges a-b }\n");
    for i in 1..n {
        src += &format!("piece p{i} extends p{} {{ vertex v{i} ({i}, 1) }}\n", i - 1);
    }
    src + &format!("model {{ x = p{} }}", n - 1)
}

/// `n` pieces extending each other in one cycle: one error, E062.
fn extends_cycle(n: usize) -> String {
    (0..n)
        .map(|i| format!("piece p{i} extends p{} {{ }}\n", (i + 1) % n))
        .collect()
}

/// A piece of `2 n` vertices on two rails, a listed state and its mirror.
fn mirrored_piece(n: usize) -> String {
    let mut src = String::from("site type t\npiece big {\n");
    for i in 0..n {
        src += &format!("vertex s{i} ({i}, -0.5)\nvertex n{i} ({i}, 0.5)\n");
    }
    src += &format!(
        "site west: t [n0, s0] out (-1, 0)\nsite east: t [s{0}, n{0}] out (1, 0)\naxis west -> east\n",
        n - 1
    );
    src += "state lean {\n";
    for i in 0..n {
        src += &format!("s{i} ({i}, -0.6) n{i} ({i}, 0.4)\n");
    }
    src + "}\nstate lean_back mirror lean\n}\nmodel { b = big }\n"
}

/// A stretch chain of `n` bricks.
fn chain(n: usize) -> String {
    format!(
        "site type joint
piece brick {{
    vertex sw (0, 0) vertex se (1, 0) vertex ne (1, 0.5) vertex nw (0, 0.5)
    edges sw-se-ne-nw-sw, sw-ne
    site west: joint [nw, sw] out (-1, 0)
    site east: joint [se, ne] out (1, 0)
}}
stretch brick from west to east {{ min 2 variants {{ brick 1 }} }}
model {{ wall = chain brick x {n} }}
"
    )
}

fn dsl(c: &mut Criterion) {
    let mut group = c.benchmark_group("dsl");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(5));
    let fails = |src: String, code: &'static str| {
        move || {
            let d = clay_dsl::compile(
                black_box(&src),
                "bench.clay",
                &clay_dsl::CompileOptions::default(),
            )
            .unwrap_err();
            assert_eq!(d.error_count(), 1);
            assert!(d.items.iter().any(|d| d.code == code));
        }
    };
    let deep = fails(extends_chain(10_000), "E063");
    group.bench_function("extends_chain/10000", |b| b.iter(&deep));
    let cycle = fails(extends_cycle(5_000), "E062");
    group.bench_function("extends_cycle/5000", |b| b.iter(&cycle));
    // two sizes, to show how the time grows
    for rail in [5_000, 10_000] {
        let mirrored = mirrored_piece(rail);
        group.bench_function(format!("mirror_listed_piece/{}", 2 * rail), |b| {
            b.iter(|| {
                let g = clay_dsl::compile(
                    black_box(&mirrored),
                    "bench.clay",
                    &clay_dsl::CompileOptions::default(),
                )
                .unwrap();
                g.grammar.pieces[0].states.len()
            })
        });
    }
    let limit = clay_dsl::MAX_MODEL_INSTANCES;
    let big = chain(limit);
    group.bench_function(format!("instance_limit/{limit}"), |b| {
        b.iter(|| {
            let g = clay_dsl::compile(
                black_box(&big),
                "bench.clay",
                &clay_dsl::CompileOptions::default(),
            )
            .unwrap();
            assert_eq!(g.grammar.assembly.instances.len(), limit);
        })
    });
    group.finish();
}

criterion_group!(benches, dsl);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}
