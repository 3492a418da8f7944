//! Pass 2 (paper 5.2): plain least squares with the states fixed, from the displayed pose,
//! its local/global iteration Anderson-accelerated and taking only iterates that lower the
//! objective; its pose is what the user sees. The evaluation of the pose it starts from may
//! be done before pass 1 ([`Start`](super::state::Start)), whose stretch parts are measured
//! along its rotations.
//!
//! A file of its own because it is one step of the frame (`mod.rs` calls `pass2`, then
//! `show`, which puts its pose on the assembly and judges convergence): an `impl Solver`
//! block over the state of `state.rs`, imported from that sibling rather than from `mod.rs`,
//! so no child imports its parent.

use std::time::{Duration, Instant};

use clay_dsl::compiled::{Part, PartKind};
use glam::DVec2;

use super::clock::{Stop, ms_since};
use super::config::SolverConfig;
use super::global_step::Pass;
use super::report::{FrameReport, SolverError};
use super::state::{Rested, Solver};
use crate::assembly::{Assembly, Handle};

impl Solver {
    /// Evaluates the local step at the displayed pose `warm` with the states kept and keeps
    /// it as [`Start`] under `key` (its rotations in `work.kept_rotations`).
    pub(super) fn start_at(
        &mut self,
        parts: &[Part],
        handles: &[Handle],
        warm: &[DVec2],
        key: Option<(u64, SolverConfig, usize)>,
    ) {
        let elastic = self.terms_at(parts, handles, warm).elastic;
        let w = &mut self.work;
        std::mem::swap(&mut w.kept_rotations, &mut w.rotations);
        std::mem::swap(&mut w.kept_targets, &mut w.targets);
        w.start.elastic = elastic;
        w.start.valid = key;
    }

    /// Pass 2 (paper 5.2): plain least squares with the states fixed, from the displayed pose
    /// `warm` (iterated in place), until no vertex moves more than `tolerance`, or the
    /// configured count, or (after one iteration) `stop`. With no pass-2 iterations
    /// configured, shows the pass-1 pose. Returns the pose, its objective's terms (its
    /// rotations and edge targets left in the work buffers) and whether it converged.
    pub(super) fn pass2(
        &mut self,
        parts: &[Part],
        handles: &[Handle],
        warm: Vec<DVec2>,
        tolerance: f64,
        stop: Stop,
        report: &mut FrameReport,
    ) -> Result<(Vec<DVec2>, Terms, bool), SolverError> {
        let cfg = self.config;
        let mut f = warm;
        // without pass-2 iterations the pass-1 pose is shown, unless the rules rewrote the
        // structure after it (it has other vertices then): their layout is
        if cfg.l2_iterations == 0 && self.pass1_pose.len() == f.len() {
            f.clear();
            f.extend_from_slice(&self.pass1_pose);
        }
        let mut next = std::mem::take(&mut self.work.next);
        next.clear();
        next.resize(f.len(), DVec2::ZERO);
        let t = Instant::now();
        let w = &mut self.work;
        let key = (
            self.generation.unwrap_or(u64::MAX),
            cfg,
            report.switches.len(),
        );
        let mut terms = if cfg.l2_iterations > 0 && w.start.valid == Some(key) {
            // the local step at `warm` was done already (`Start`)
            std::mem::swap(&mut w.kept_rotations, &mut w.rotations);
            std::mem::swap(&mut w.kept_targets, &mut w.targets);
            w.start.valid = None;
            Terms {
                elastic: w.start.elastic,
                handle: handle_term(handles, &f, cfg.handle_weight),
            }
        } else {
            self.terms_at(parts, handles, &f)
        };
        report.warm_objective = terms.total();
        report.phases.local += ms_since(t);
        let mut converged = cfg.l2_iterations == 0;
        let mut last_iteration = Duration::ZERO;
        let mut anderson = std::mem::take(&mut self.anderson);
        anderson.start(cfg.l2_anderson);
        // a model nothing holds relaxes along its softest modes (a long chain unbending), which
        // least squares takes many iterations over: more of them then
        let iterations = if handles.is_empty() && cfg.l2_iterations > 0 {
            cfg.l2_iterations.max(cfg.l2_iterations_free)
        } else {
            cfg.l2_iterations
        };
        for it in 0..iterations {
            if it > 0 && stop.before(true, it, last_iteration) {
                report.complete = false;
                break;
            }
            let iteration_start = Instant::now();
            report.l2_iterations += 1;
            self.solve_global(&f, &mut next, Pass::LeastSquares, report)?;
            let t = Instant::now();
            // f's rotations and targets aside while the next iterate is judged
            let w = &mut self.work;
            std::mem::swap(&mut w.rotations, &mut w.kept_rotations);
            std::mem::swap(&mut w.targets, &mut w.kept_targets);
            let mixed = anderson.mix(&f, &mut next);
            let mut next_terms = self.terms_at(parts, handles, &next);
            // NaN does not descend either
            let descends = next_terms.total() < terms.total();
            if mixed && !descends {
                // the accelerated iterate does not descend: the plain one, a fresh history
                anderson.plain(&mut next);
                anderson.reset();
                next_terms = self.terms_at(parts, handles, &next);
            }
            report.phases.local += ms_since(t);
            // Only an iterate that lowers the objective is taken: a frame never ends worse
            // than it started, and a model at rest stays exactly where it is (a solve of a
            // pose at rest only adds rounding, and a free component's rounding drifts).
            if next_terms.total() >= terms.total() || !next_terms.total().is_finite() {
                let w = &mut self.work;
                std::mem::swap(&mut w.rotations, &mut w.kept_rotations);
                std::mem::swap(&mut w.targets, &mut w.kept_targets);
                converged = true;
                break;
            }
            let delta = self.units.max_move_in_sizes(&self.components, &f, &next);
            std::mem::swap(&mut f, &mut next);
            terms = next_terms;
            last_iteration = iteration_start.elapsed();
            if delta <= tolerance {
                converged = true;
                break;
            }
        }
        self.anderson = anderson;
        self.work.next = next;
        Ok((f, terms, converged))
    }

    /// Pass 2's objective at `f` (states fixed), its local step left in the work buffers.
    pub(super) fn terms_at(&mut self, parts: &[Part], handles: &[Handle], f: &[DVec2]) -> Terms {
        Terms {
            elastic: self.evaluate_fixed(parts, f),
            handle: handle_term(handles, f, self.config.handle_weight),
        }
    }

    /// Shows pass 2's pose `f` (its objective's terms `terms`): the assembly's positions,
    /// rotations and instance states; keeps what the next frame reads (how far the pose moved,
    /// its energy, its evaluation as [`Start`](super::state::Start)) and reports its energy
    /// and objective and whether the frame converged (`converged`: both passes did).
    pub(super) fn show(
        &mut self,
        asm: &mut Assembly,
        f: Vec<DVec2>,
        terms: Terms,
        converged: bool,
        report: &mut FrameReport,
    ) -> Result<(), SolverError> {
        let cfg = self.config;
        let generation = self.generation.unwrap_or(u64::MAX);
        let t = Instant::now();
        if f.iter().any(|p| !p.is_finite()) {
            self.work.start.valid = None;
            return Err(SolverError(
                "the solve produced non-finite positions".into(),
            ));
        }
        report.moved = max_move(&asm.data().positions, &f);
        let shown = &asm.data().positions;
        self.work.last_moved = self.units.max_move_in_edges(&self.components, shown, &f);
        let settled =
            self.units.max_move_in_sizes(&self.components, shown, &f) <= cfg.settle_tolerance;
        self.work.last_energy = [terms.elastic, self.work.last_energy[0]];
        asm.positions_mut().copy_from_slice(&f);
        let rot = asm.rotations_mut();
        if rot.len() == self.work.rotations.len() {
            rot.copy_from_slice(&self.work.rotations);
        }
        sync_instance_states(asm);
        self.work
            .keep_start(cfg, generation, &asm.data().parts, terms.elastic);
        report.energy = terms.elastic;
        report.objective = terms.total();
        // still and strained, other states not yet tried: the next frame tries them
        // (`settling`), so this one is not the last (a host that stops at convergence, as the
        // editor does, would never run it)
        let strained = self.strained(terms.elastic);
        let trial_due = !self.work.tried && strained;
        // at rest where the handles hold it (pass 2 stopped short of them is not)
        if !strained && !self.strained(terms.handle) {
            self.work.rested = Some(Rested::of(asm, self.work.rested.as_ref()));
        }
        report.converged =
            report.complete && report.switches.is_empty() && !trial_due && (settled || converged);
        // the shown pose is kept; the one shown before is the next frame's warm-start buffer
        self.work.warm = std::mem::replace(&mut self.work.shown, f);
        report.phases.bookkeeping += ms_since(t);
        Ok(())
    }
}

#[derive(Clone, Copy, Debug)]
pub(super) struct Terms {
    pub(super) elastic: f64,
    pub(super) handle: f64,
}

impl Terms {
    pub(super) fn total(self) -> f64 {
        self.elastic + self.handle
    }
}

/// The handle term of the pass-2 objective at `f`.
pub(super) fn handle_term(handles: &[Handle], f: &[DVec2], handle_weight: f64) -> f64 {
    let mut handle = 0.0;
    for h in handles {
        for (k, &v) in h.vertices.iter().enumerate() {
            if let Some(&p) = f.get(v) {
                let t = h.target(k);
                if t.is_finite() {
                    handle += (p - t).length_squared();
                }
            }
        }
    }
    handle_weight * handle
}

fn max_move(a: &[DVec2], b: &[DVec2]) -> f64 {
    // one square root for the largest, not one per vertex (the same value: sqrt is monotonic
    // and correctly rounded)
    a.iter()
        .zip(b)
        .map(|(p, q)| p.distance_squared(*q))
        .fold(0.0, f64::max)
        .sqrt()
}

/// Piece parts carry their active state to their instance (that is the replacement rule).
fn sync_instance_states(asm: &mut Assembly) {
    let data = asm.data_mut();
    for part in &data.parts {
        if let PartKind::Piece { instance } = part.kind
            && let Some(inst) = data.instances.get_mut(instance)
        {
            inst.state = part.active;
        }
    }
}
