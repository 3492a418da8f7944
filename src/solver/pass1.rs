//! Pass 1 (paper 5.2): the sub-quadratic norm `|r|^p` by iteratively reweighted least
//! squares, one weight per part, from the displayed pose with the held vertices where the
//! handles now put them. Its local steps choose every part's rest state (from its second
//! iteration on); its pose decides the states and the chains' claims, and is not shown.
//!
//! A file of its own because it is one step of the frame (`mod.rs` calls `pass1_start` and
//! `pass1`): an `impl Solver` block over the state of `state.rs`, imported from that sibling
//! rather than from `mod.rs`, so no child imports its parent.

use std::time::{Duration, Instant};

use clay_dsl::compiled::Part;
use glam::DVec2;

use super::clock::{Stop, ms_since};
use super::global_step::Pass;
use super::report::{FrameReport, SolverError};
use super::state::Solver;
use crate::assembly::Assembly;

impl Solver {
    /// Where pass 1 starts: the displayed pose `warm` with the held vertices where the handles
    /// now put them ([`Solver::snap_held`]; in the last pass-1 pose's buffer), and when pass 1
    /// runs, what its local steps read: the evaluation at `warm` (kept for pass 2 as
    /// [`Start`](super::state::Start)), the stretch parts' contexts and the outlier factors.
    pub(super) fn pass1_start(&mut self, asm: &Assembly, warm: &[DVec2]) -> Vec<DVec2> {
        // Pass 1 starts from the displayed least-squares pose with the held vertices where the
        // handles now put them, by either method: the gesture's new step is where the
        // deformation starts, so the sparse norm gathers it next to the handle that moved,
        // and elsewhere into the parts the least-squares pose already strains most
        // (`docs/solver.md`).
        let mut pose = std::mem::take(&mut self.pass1_pose);
        warm.clone_into(&mut pose);
        self.snap_held(&mut pose);
        if self.pass1_runs() {
            let start_key = Some((self.generation.unwrap_or(u64::MAX), self.config, 0));
            // the evaluation at the displayed pose: pass 2 starts there (`Start`), and its
            // rotations are the directions the stretch parts' lengths are measured along
            if self.work.start.valid.is_none() {
                self.start_at(&asm.data().parts, asm.handles(), warm, start_key);
            }
            self.stretch_contexts(asm, &pose);
            self.outlier_factors(&asm.data().parts, asm.handles());
        }
        pose
    }

    /// Whether pass 1 runs at all.
    pub(super) fn pass1_runs(&self) -> bool {
        self.config.irls_iterations > 0
    }

    /// Pass 1 (paper 5.2): the sub-quadratic norm by IRLS, from the pass-1 pose `pose` (the
    /// displayed pose, the handles moved); its local steps decide the active rest states.
    /// Iterates until no vertex moves more than [`SolverConfig::pass1_tolerance`] times the
    /// mean rest edge and no state switches, or the configured count, or (after
    /// [`MIN_PASS1_ITERATIONS`]) `stop`. Leaves its pose in `pose`; returns whether it
    /// converged.
    pub(super) fn pass1(
        &mut self,
        parts: &mut [Part],
        pose: &mut Vec<DVec2>,
        stop: Stop,
        report: &mut FrameReport,
    ) -> Result<bool, SolverError> {
        let cfg = self.config;
        let iterations = cfg.irls_iterations;
        let tolerance = cfg.pass1_tolerance;
        let mut f = std::mem::take(pose);
        let mut next = std::mem::take(&mut self.work.next);
        next.clear();
        next.resize(f.len(), DVec2::ZERO);
        let mut converged = iterations == 0;
        let mut last_iteration = Duration::ZERO;
        let mut result = Ok(());
        let first_switch = report.switches.len();
        for it in 0..iterations {
            if it >= MIN_PASS1_ITERATIONS && stop.before(false, it, last_iteration) {
                report.complete = false;
                break;
            }
            let iteration_start = Instant::now();
            report.pass1_iterations += 1;
            let t = Instant::now();
            let switched_before = report.switches.len();
            // The first iteration judges the pose pass 1 starts from, the least-squares one
            // (with the handles moved): it only weighs the parts. States switch from the
            // second on, judged by the sub-quadratic norm's pose (paper 5.2): on an evenly
            // stretched chain every part would claim an element at once.
            if it > 0 || iterations == 1 {
                self.evaluate_switching(parts, &f, &mut report.switches);
            } else {
                self.evaluate_fixed(parts, &f);
            }
            report.phases.local += ms_since(t);
            let solved = self.irls_iteration(&f, &mut next, report);
            if let Err(e) = solved {
                result = Err(e);
                break;
            }
            let delta = self.units.max_move_in_edges(&self.components, &f, &next);
            std::mem::swap(&mut f, &mut next);
            last_iteration = iteration_start.elapsed();
            if (it > 0 || iterations == 1)
                && delta <= tolerance
                && report.switches.len() == switched_before
            {
                converged = true;
                break;
            }
        }
        if result.is_ok() {
            self.confirm_switches(parts, &f, first_switch, &mut report.switches);
        }
        *pose = f;
        self.work.next = next;
        result.map(|()| converged)
    }

    /// One IRLS iteration (paper 5.2): weights `1 / (|r| + eps)^(2 - p)` from the residuals
    /// at `f` (the last local step's, per part), then the weighted global step.
    fn irls_iteration(
        &mut self,
        f: &[DVec2],
        next: &mut [DVec2],
        report: &mut FrameReport,
    ) -> Result<(), SolverError> {
        let cfg = self.config;
        let t = Instant::now();
        let (p, eps) = (cfg.norm, cfg.irls_epsilon.max(1e-12));
        let w = &mut self.work;
        let part_edges = &self.pattern.part_edges;
        w.weights.clear();
        w.weights.resize(w.residuals.len(), 0.0);
        // one weight per part with edges, from its stacked residual (paper Eq. 6: the shape
        // distance is a part's); a part without edges keeps 0
        for (((weight, &d2), _), &c) in w
            .weights
            .iter_mut()
            .zip(&w.residuals)
            .zip(part_edges)
            .zip(&w.outlier)
            .filter(|((_, count), _)| **count > 0)
        {
            let v = irls_weight(d2.sqrt() + eps, p);
            *weight = c * if v.is_finite() { v } else { eps.powf(p - 2.0) };
        }
        self.units.weigh(part_edges, &w.weights);
        report.phases.assembly += ms_since(t);
        self.solve_global(f, next, Pass::Irls, report)
    }
}

/// Pass-1 iterations a budgeted frame always runs (when configured to run that many): the
/// first judges the pose the last frame left, the second the pose with the handles moved.
const MIN_PASS1_ITERATIONS: usize = 2;

/// `a^(p - 2)`, with the common exponents spelled out (powf dominated the IRLS pass).
fn irls_weight(a: f64, p: f64) -> f64 {
    if p == 2.0 {
        1.0
    } else if p == 0.5 {
        1.0 / (a * a.sqrt())
    } else if p == 1.0 {
        1.0 / a
    } else {
        a.powf(p - 2.0)
    }
}
