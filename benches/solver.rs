//! Criterion benchmark of one solver frame on synthetic cities of 1k, 10k and 100k parts
//! (streets, junctions and a long wall) while a corner is dragged, for the Cholesky global
//! step, and for CG at 1k. With `CLAY_PHASES=<parts>` set it instead prints where a frame's
//! time goes (local step, matrix assembly, factorisation, solve) over the same drag as
//! `clayc bench --parts` (60 frames; `CLAY_PCG`, `CLAY_IRLS`, `CLAY_L2` override the
//! preconditioned-CG cap and the iteration caps).

use std::sync::Arc;
use std::time::Duration;

use clay::{Assembly, HandleKind, Solver, SolverConfig, SolverKind, synthetic};
use criterion::{Criterion, criterion_group};
use glam::DVec2;

fn setup(parts: usize) -> (Assembly, u64) {
    let mut asm = Assembly::new(Arc::new(synthetic::city(parts)));
    let (mut lo, mut hi) = (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN));
    for p in asm.data().positions.iter().filter(|p| p.y >= 0.0) {
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
                asm.move_handle(h, DVec2::new(4.0 * t, 2.0 * t), 0.0);
                solver.frame(&mut asm).unwrap()
            })
        });
    }
    group.finish();
}

/// Per-phase breakdown of the `clayc bench --parts N` drag (same model, handles and drag).
fn phases(parts: usize) {
    let (mut asm, h) = setup(parts);
    let (lo, hi) = asm.data().positions.iter().filter(|p| p.y >= 0.0).fold(
        (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let offset = DVec2::new(0.3, 0.2) * (hi - lo).length();
    let mut config = SolverConfig::default();
    let env = |name: &str| {
        std::env::var(name)
            .ok()
            .and_then(|v| v.parse::<usize>().ok())
    };
    if let Some(k) = env("CLAY_PCG") {
        config.pcg_max_iterations = k;
    }
    if let Some(k) = env("CLAY_IRLS") {
        config.irls_iterations = k;
    }
    if let Some(k) = env("CLAY_L2") {
        config.l2_iterations = k;
    }
    let mut solver = Solver::new(config);
    let frames = 60;
    let mut reports = Vec::new();
    for k in 1..=frames {
        asm.move_handle(h, offset * (k as f64 / frames as f64), 0.0);
        reports.push(solver.frame(&mut asm).unwrap());
    }
    let later = &reports[1..];
    let mean = |f: &dyn Fn(&clay::FrameReport) -> f64| {
        later.iter().map(f).sum::<f64>() / later.len() as f64
    };
    let mut ms: Vec<f64> = later.iter().map(|r| r.ms).collect();
    ms.sort_by(f64::total_cmp);
    println!(
        "parts {} | frame median {:.1} ms max {:.1} | mean: local {:.1} assembly {:.1} \
         factorisation {:.1} solve {:.1} | irls {:.2} l2 {:.2} factorisations {:.2} pcg {:.1} \
         | converged frames {}",
        asm.data().parts.len(),
        ms[ms.len() / 2],
        ms[ms.len() - 1],
        mean(&|r| r.phases.local),
        mean(&|r| r.phases.assembly),
        mean(&|r| r.phases.factorization),
        mean(&|r| r.phases.solve),
        mean(&|r| r.pass1_iterations as f64),
        mean(&|r| r.l2_iterations as f64),
        mean(&|r| r.factorizations as f64),
        mean(&|r| r.pcg_iterations as f64),
        reports.iter().filter(|r| r.converged).count(),
    );
}

criterion_group!(benches, frames);

fn main() {
    match std::env::var("CLAY_PHASES")
        .ok()
        .and_then(|v| v.parse().ok())
    {
        Some(parts) => phases(parts),
        None => {
            benches();
            Criterion::default().configure_from_args().final_summary();
        }
    }
}
