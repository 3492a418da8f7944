//! Criterion benchmark of one solver frame on synthetic cities of 1k, 10k and 100k parts
//! (streets, junctions and a long wall) while a corner is dragged, for the Cholesky global
//! step, and for CG at 1k.

use std::sync::Arc;
use std::time::Duration;

use clay::assembly::{Assembly, HandleKind};
use clay::solver::{Solver, SolverConfig, SolverKind};
use clay::synthetic;
use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec2;

fn setup(parts: usize) -> (Assembly, u64) {
    let mut asm = Assembly::new(Arc::new(synthetic::city(parts)));
    let (mut lo, mut hi) = (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN));
    for p in asm.data.positions.iter().filter(|p| p.y >= 0.0) {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let pin = asm.part_nearest(lo).unwrap();
    asm.hold_part(pin, HandleKind::Pin);
    let grab = asm.part_nearest(hi).unwrap();
    let h = asm.hold_part(grab, HandleKind::Grab).unwrap();
    (asm, h)
}

fn frames(c: &mut Criterion) {
    let mut group = c.benchmark_group("frame");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    for (parts, kind) in [
        (1_000, SolverKind::Cholesky),
        (1_000, SolverKind::Cg),
        (10_000, SolverKind::Cholesky),
        (100_000, SolverKind::Cholesky),
    ] {
        let (mut asm, h) = setup(parts);
        let mut solver = Solver::new(SolverConfig {
            kind,
            ..SolverConfig::default()
        });
        solver.frame(&mut asm).unwrap(); // symbolic analysis happens here, outside the timing
        let mut k = 0u64;
        group.bench_function(format!("{kind:?}/{parts}"), |b| {
            b.iter(|| {
                k += 1;
                // a slow back-and-forth drag keeps every frame doing real work
                let t = (k as f64 * 0.05).sin();
                asm.handle_mut(h).unwrap().translation = DVec2::new(4.0 * t, 2.0 * t);
                solver.frame(&mut asm).unwrap()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, frames);
criterion_main!(benches);
