//! `clayc bench`: times solver frames on synthetic assemblies. `--parts N` drags a corner of a
//! city of about N parts (streets, junctions, a long wall); `--arap-grid K` runs classic ARAP
//! iterations on a K x K triangulated grid (left column fixed, right column dragged). The rules run
//! after every frame, as in a live session, and are timed apart from the solver.

use std::sync::Arc;

use crate::out;
use clay::{Assembly, FrameReport, HandleKind, Session, SolverConfig, SolverKind, synthetic};
use glam::DVec2;
use serde::Serialize;

#[derive(clap::Args)]
pub struct BenchArgs {
    /// Approximate number of parts of the synthetic city.
    #[arg(long, default_value_t = 10_000, conflicts_with = "arap_grid")]
    pub parts: usize,
    /// Run classic ARAP on a K x K grid instead of the city.
    #[arg(long, value_name = "K")]
    pub arap_grid: Option<usize>,
    /// Linear solver of the global step.
    #[arg(long, value_enum, default_value_t = SolverArg::Cholesky)]
    pub solver: SolverArg,
    /// Frames to time.
    #[arg(long, default_value_t = 30)]
    pub frames: usize,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
    /// Most IRLS (pass 1) iterations per frame (default: the solver's).
    #[arg(long)]
    pub irls_iterations: Option<usize>,
    /// Most least-squares (pass 2) iterations per frame (default: the solver's).
    #[arg(long)]
    pub l2_iterations: Option<usize>,
    /// Pass 2's Anderson window (0: off).
    #[arg(long)]
    pub l2_anderson: Option<usize>,
    /// Threads of the solver's local step (0: every core; the results are the same).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SolverArg {
    Cholesky,
    Cg,
}

#[derive(Serialize)]
struct Ms {
    median: f64,
    max: f64,
}

#[derive(Serialize)]
struct BenchResult {
    model: String,
    parts: usize,
    vertices: usize,
    matrix_nonzeros: usize,
    /// Values stored by the Cholesky factor (0 with `--solver cg`).
    factor_values: usize,
    solver: &'static str,
    frames: usize,
    /// Mean pass-1 (IRLS) and least-squares (pass 2) iterations per frame.
    pass1_iterations: f64,
    l2_iterations: f64,
    factorizations_per_frame: f64,
    cg_iterations_per_frame: f64,
    /// The first frame, which includes the symbolic analysis.
    first_frame_ms: f64,
    /// Frames after the first.
    frame_ms: Ms,
    /// The rule checks after each frame (stretch/shrink candidates, the merge proximity
    /// query, replacement), timed apart from the solver; includes any rewrite that fired.
    rules_ms: Ms,
    /// Rewrites that fired during the run.
    rules_fired: usize,
    /// ARAP only: time of one local + global iteration.
    #[serde(skip_serializing_if = "Option::is_none")]
    iteration_ms: Option<Ms>,
    converged_frames: usize,
    /// Mean milliseconds per frame (after the first) by solver phase; `other` is what no
    /// phase timer saw (the timers themselves, the pass loops).
    phases_ms: Phases,
    /// The last frame's elastic energy and the sum of every vertex's coordinates at the end:
    /// two runs that give the same figures here computed the same frames (to compare
    /// builds).
    energy: f64,
    checksum: f64,
    /// The mean over frames of the displayed pose's objective (how close the frames come to
    /// their least-squares minimum: lower is closer).
    objective_mean: f64,
}

#[derive(Serialize)]
struct Phases {
    local: f64,
    assembly: f64,
    factorization: f64,
    solve: f64,
    bookkeeping: f64,
    other: f64,
}

/// Mean phase times of `reports` (the frames after the first).
fn phases(reports: &[FrameReport]) -> Phases {
    let n = reports.len().max(1) as f64;
    let mean = |f: &dyn Fn(&FrameReport) -> f64| reports.iter().map(f).sum::<f64>() / n;
    let p = |r: &FrameReport| r.phases;
    // every timed phase, so `other` is only what no timer saw (it held the bookkeeping too)
    let attributed = |r: &FrameReport| {
        p(r).local + p(r).assembly + p(r).factorization + p(r).solve + p(r).bookkeeping
    };
    Phases {
        local: mean(&|r| p(r).local),
        assembly: mean(&|r| p(r).assembly),
        factorization: mean(&|r| p(r).factorization),
        solve: mean(&|r| p(r).solve),
        bookkeeping: mean(&|r| p(r).bookkeeping),
        other: mean(&|r| r.ms - attributed(r)),
    }
}

fn stats(values: &[f64]) -> Ms {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let median = if v.is_empty() { 0.0 } else { v[v.len() / 2] };
    Ms {
        median,
        max: v.last().copied().unwrap_or(0.0),
    }
}

// Long because: one command's sequence: build the model, run the frames, then write every figure of the JSON.
pub fn bench(args: BenchArgs) -> u8 {
    if args.frames == 0 || args.frames > 100_000 {
        errln!("error: --frames must be from 1 to 100000");
        return 2;
    }
    let kind = match args.solver {
        SolverArg::Cholesky => SolverKind::Cholesky,
        SolverArg::Cg => SolverKind::Cg,
    };
    let mut config = SolverConfig {
        kind,
        ..SolverConfig::default()
    };
    if let Some(k) = args.irls_iterations {
        config.irls_iterations = k.min(1000);
    }
    if let Some(k) = args.l2_anderson {
        config.l2_anderson = k.min(16);
    }
    if let Some(k) = args.l2_iterations {
        config.l2_iterations = k.min(1000);
    }
    config.threads = args.threads.min(64);
    let (model, mut asm, drag) = match args.arap_grid {
        Some(k) => {
            if !(2..=2000).contains(&k) {
                errln!("error: --arap-grid must be from 2 to 2000");
                return 2;
            }
            // classic ARAP: least squares only, one local + global iteration per frame
            // (unless asked for more)
            config.irls_iterations = 0;
            config.l2_iterations = args.l2_iterations.map_or(1, |k| k.min(1000));
            config.tolerance = 0.0;
            let mut asm = Assembly::new(Arc::new(synthetic::arap_grid(k)));
            let left: Vec<usize> = (0..k).map(|j| j * k).collect();
            let right: Vec<usize> = (0..k).map(|j| j * k + k - 1).collect();
            asm.hold_vertices(left, HandleKind::Pin);
            let h = asm.hold_vertices(right, HandleKind::Grab);
            (
                format!("arap-grid {k}x{k}"),
                asm,
                h.map(|h| (h, DVec2::new(0.3, 0.5) * k as f64)),
            )
        }
        None => {
            if !(10..=10_000_000).contains(&args.parts) {
                errln!("error: --parts must be from 10 to 10000000");
                return 2;
            }
            let mut asm = Assembly::new(Arc::new(synthetic::city(args.parts)));
            let (lo, hi) = grid_corners(&asm);
            if let Some(p) = asm.part_nearest(lo) {
                asm.hold_part(p, HandleKind::Pin);
            }
            let h = asm
                .part_nearest(hi)
                .and_then(|p| asm.hold_part(p, HandleKind::Grab));
            let size = (hi - lo).length();
            (
                format!("city of ~{} parts", args.parts),
                asm,
                h.map(|h| (h, DVec2::new(0.3, 0.2) * size)),
            )
        }
    };
    let mut session = Session::new(config);
    let mut rules_ms = Vec::with_capacity(args.frames);
    let mut rules_fired = 0;
    let mut reports: Vec<FrameReport> = Vec::with_capacity(args.frames);
    for k in 1..=args.frames {
        if let Some((h, offset)) = drag {
            asm.move_handle(h, offset * (k as f64 / args.frames as f64), 0.0);
        }
        // A live session's frame: the solver, then the rules. Their cost is part of the
        // per-frame budget, so it is reported too, apart from the solver's.
        match session.frame(&mut asm) {
            Ok(f) => {
                rules_fired += f.events.len();
                let total = session.frame_ms().last().copied().unwrap_or(f.report.ms);
                rules_ms.push((total - f.report.ms).max(0.0));
                reports.push(f.report);
            }
            Err(e) => {
                errln!("error: frame {k}: {e}");
                return 1;
            }
        }
    }
    let solver = session.solver();
    let n = reports.len() as f64;
    let later: Vec<f64> = reports.iter().skip(1).map(|r| r.ms).collect();
    let later = if later.is_empty() {
        vec![reports[0].ms]
    } else {
        later
    };
    let result = BenchResult {
        model,
        parts: asm.data().parts.len(),
        vertices: asm.data().positions.len(),
        matrix_nonzeros: solver.matrix_nonzeros(),
        factor_values: solver.factor_values(),
        solver: match kind {
            SolverKind::Cholesky => "cholesky",
            SolverKind::Cg => "cg",
        },
        frames: reports.len(),
        pass1_iterations: reports
            .iter()
            .map(|r| r.pass1_iterations as f64)
            .sum::<f64>()
            / n,
        l2_iterations: reports.iter().map(|r| r.l2_iterations as f64).sum::<f64>() / n,
        factorizations_per_frame: reports.iter().map(|r| r.factorizations as f64).sum::<f64>() / n,
        cg_iterations_per_frame: reports.iter().map(|r| r.cg_iterations as f64).sum::<f64>() / n,
        first_frame_ms: reports[0].ms,
        iteration_ms: args.arap_grid.map(|_| {
            let per: Vec<f64> = reports
                .iter()
                .skip(1)
                .map(|r| r.ms / (r.l2_iterations + r.pass1_iterations).max(1) as f64)
                .collect();
            stats(&per)
        }),
        frame_ms: stats(&later),
        rules_ms: stats(&rules_ms),
        rules_fired,
        converged_frames: reports.iter().filter(|r| r.converged).count(),
        phases_ms: phases(reports.get(1..).unwrap_or(&reports)),
        energy: reports.last().map_or(0.0, |r| r.energy),
        checksum: asm.data().positions.iter().map(|p| p.x + p.y).sum(),
        objective_mean: reports.iter().map(|r| r.objective).sum::<f64>() / n,
    };
    let text = if args.json {
        match serde_json::to_string_pretty(&result) {
            Ok(s) => s,
            Err(e) => {
                errln!("error: {e}");
                return 2;
            }
        }
    } else {
        format!(
            "{}: {} parts, {} vertices, solver {}, {} frames\niterations per frame: {:.2} pass-1 + {:.2} L2, {:.2} factorisations, {:.1} CG iterations\nfirst frame {:.2} ms; frame_ms median {:.2}, max {:.2}\nrules_ms median {:.3}, max {:.3} ({} fired){}",
            result.model,
            result.parts,
            result.vertices,
            result.solver,
            result.frames,
            result.pass1_iterations,
            result.l2_iterations,
            result.factorizations_per_frame,
            result.cg_iterations_per_frame,
            result.first_frame_ms,
            result.frame_ms.median,
            result.frame_ms.max,
            result.rules_ms.median,
            result.rules_ms.max,
            result.rules_fired,
            result
                .iteration_ms
                .as_ref()
                .map_or(String::new(), |m| format!(
                    "\niteration_ms median {:.2}, max {:.2}",
                    m.median, m.max
                )),
        )
    };
    out::stdout_line(&text).err().map_or(0, |stop| stop.exit(0))
}

/// South-west and north-east corners of the street grid (the parts above the wall).
fn grid_corners(asm: &Assembly) -> (DVec2, DVec2) {
    let above = asm.data().positions.iter().filter(|p| p.y >= 0.0);
    let (lo, hi) = above.fold(
        (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    if lo.x > hi.x {
        (DVec2::ZERO, DVec2::ZERO)
    } else {
        (lo, hi)
    }
}
