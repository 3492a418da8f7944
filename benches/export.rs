//! Criterion benchmark of `clayc export` on a 100,000-part synthetic city (issue 20: under
//! 3 s and 1 GiB): building the 3D scene from the posed assembly, and encoding it as GLB and
//! as OBJ. The city is generated outside the timing. Figures are in docs/performance.md.

use std::time::Duration;

use clay::{ExportOptions, scene};
use criterion::{Criterion, criterion_group, criterion_main};

fn export(c: &mut Criterion) {
    let city = clay::synthetic::city(100_000);
    let options = ExportOptions::default();
    let mut group = c.benchmark_group("export 100k-part city");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(20));
    group.bench_function("scene + glb", |b| {
        b.iter(|| {
            clay::testing::to_glb(&scene(&city, &city.assembly, &options))
                .unwrap()
                .len()
        })
    });
    group.bench_function("scene + obj", |b| {
        b.iter(|| {
            clay::testing::to_obj(&scene(&city, &city.assembly, &options), "city.mtl")
                .0
                .len()
        })
    });
    group.finish();
}

criterion_group!(benches, export);
criterion_main!(benches);
