//! Criterion benchmark of drawing one large polygon (issue 16): a 200,000-point ring, generated
//! here as grammar text and compiled outside the timing, is tessellated on its own and rendered
//! to a 1024 x 768 PNG the way `clayc render` does (tessellation, posing, rasterising, encoding).
//! Two rings: a circle (every edge a hundredth of a pixel) and a star whose radius alternates
//! between 1 and 0.8 (every edge some 70 pixels long: the rasteriser's worst case). Figures are
//! in docs/performance.md.

use std::fmt::Write;
use std::time::Duration;

use clay::testing::tessellate_proxy;
use clay::{RenderOptions, render_png};
use clay_dsl::compiled::CompiledGrammar;
use criterion::{Criterion, criterion_group, criterion_main};

/// The number of points of the star's ring.
const POINTS: usize = 200_000;

/// A grammar of one piece whose rigid polygon is a ring of `n` points (radii alternating 1 m
/// and `inner` m), and a model of one instance of it.
fn ring_grammar(n: usize, inner: f64) -> String {
    let mut text = String::from(
        "site type joint\npiece blob {\n    vertex a (-1, -1)\n    vertex b (1, -1)\n    \
         vertex c (1, 1)\n    vertex d (-1, 1)\n    edges a-b-c-d-a, a-c\n    \
         polygon rigid fill #b5651d {\n",
    );
    for k in 0..n {
        let r = if k % 2 == 0 { 1.0 } else { inner };
        let (s, c) = (k as f64 * std::f64::consts::TAU / n as f64).sin_cos();
        let _ = writeln!(text, "        ({:.12}, {:.12})", r * c, r * s);
    }
    text.push_str("    }\n}\nmodel { x = blob }\n");
    text
}

fn compiled(inner: f64) -> CompiledGrammar {
    clay_dsl::compile(
        &ring_grammar(POINTS, inner),
        "ring.clay",
        &clay_dsl::CompileOptions::default(),
    )
    .expect("the generated ring grammar compiles")
    .grammar
}

fn large_polygon(c: &mut Criterion) {
    let mut group = c.benchmark_group("large_polygon");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(10));
    let options = RenderOptions::default();
    for (name, inner) in [("circle", 1.0), ("star", 0.8)] {
        let grammar = compiled(inner);
        let proxy = &grammar.pieces[0].states[0].geometry[0];
        group.bench_function(format!("tessellate/{name}/200k"), |b| {
            b.iter(|| tessellate_proxy(proxy).expect("the ring tessellates"))
        });
        group.bench_function(format!("render_png/{name}/200k"), |b| {
            b.iter(|| render_png(&grammar, &grammar.assembly, &options).expect("the ring renders"))
        });
    }
    group.finish();
}

criterion_group!(benches, large_polygon);
criterion_main!(benches);
