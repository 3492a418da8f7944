//! The mutable elastic solver (paper 4.1-4.3, 5.2): one frame of alternating local steps
//! (rotations and rest-state choice with hysteresis) and global steps (a sparse linear solve),
//! warm-started from the previous positions. Pass 1 reweights edges for the sub-quadratic
//! norm (IRLS) and decides the active rest states; pass 2 is plain least squares with the
//! states fixed, and its positions are what the user sees.
//!
//! This file is the frame's table of contents: the module list, the public API, and
//! `frame_prepared`, the frame's steps in order, each a call with a one-line comment naming
//! the file it lives in. The state the steps share is `state.rs`'s; every job is a sibling
//! with its own `impl Solver` block that imports the state (and what else it needs) from its
//! siblings, never from here, so no child imports its parent.

mod anderson;
mod cg;
mod chains;
mod cholesky;
mod chunks;
mod clock;
mod closure;
mod config;
mod evaluate;
pub(crate) mod follow;
mod global;
mod global_step;
mod growth;
mod handles;
mod layout;
pub(crate) mod local;
mod loops;
mod measure;
mod pass1;
mod pass2;
mod relax;
mod report;
mod rest_cache;
mod rounding;
mod state;
mod trials;
mod turns;
mod units;

pub use clock::Stop;
pub use config::{SolverConfig, SolverKind};
pub use measure::{bbox, bbox_diagonal, edge_strain, elastic_energy, max_edge_strain};
// Names only the tests use, re-exported as `clay::testing::X`.
pub use report::{FrameReport, Judged, PhaseTimes, Proposal, SolverError, StateSwitch};
pub use state::Solver;
#[cfg(any(test, feature = "testing"))]
pub use {follow::Components, measure::edge_strains};

use std::time::{Duration, Instant};

use clay_dsl::compiled::PartKind;
use glam::DVec2;

use crate::assembly::Assembly;
use cholesky::SymbolicFactor;
use clock::ms_since;

/// What runs between a frame's two passes ([`Solver::frame_with`]): the assembly, the report
/// so far and the pass-1 pose.
pub type Between<'a> = dyn FnMut(&mut Assembly, &FrameReport, &[DVec2]) + Send + 'a;

impl Solver {
    /// The pass-1 (sub-quadratic) pose of the last frame, from which the active rest states
    /// were decided; empty before the first frame.
    pub fn pass1_pose(&self) -> &[DVec2] {
        &self.pass1_pose
    }

    /// What the local step sees of `part` at `asm`'s pose when it chooses the part's state
    /// ([`local::Judgement`]), with this solver's last frame's view of the chains (the
    /// directions their parts are measured along, the states the rules can honour) when the
    /// assembly has not changed since. For the inspector.
    pub(crate) fn judge(&self, asm: &Assembly, part: usize) -> Option<local::Judgement> {
        let data = asm.data();
        let p = data.parts.get(part)?;
        let current = self.generation == Some(asm.generation())
            && self.work.stretch.len() == data.parts.len();
        let fresh;
        let shared = if current {
            &self.work.vertex_parts
        } else {
            fresh = local::VertexParts::build(&data.parts, data.positions.len());
            &fresh
        };
        let stretch: &[Option<local::StretchContext>] =
            if current { &self.work.stretch } else { &[] };
        let how = local::Switching {
            hysteresis: self.config.hysteresis,
            stretch,
            shared: Some(shared),
        };
        Some(local::judge(part, p, &data.positions, how))
    }

    /// What the last frame's relaxation proposed (`relax.rs`: alternatives), when made for
    /// `asm`'s structure; taken by the session, which tries them with the rules.
    pub(crate) fn take_proposals(&mut self, asm: &Assembly) -> Vec<Proposal> {
        match self.proposals.take() {
            Some((generation, p)) if generation == asm.generation() => p,
            _ => Vec::new(),
        }
    }

    /// What the relaxation proposes for `asm` as it is (after a frame of this solver on it),
    /// its turns' proposals aside: the lengths a restructured copy then asks for
    /// ([`Proposal::then_lengths`]), with the states of the pieces in `kept` (instances: the
    /// turn's own choice) left as they are: were they switched back, one proposal would
    /// switch a piece out and back in a single step. Empty when the relaxation fails.
    pub(crate) fn relaxed_after(&mut self, asm: &Assembly, kept: &[usize]) -> Vec<Proposal> {
        let warm = asm.data().positions.clone();
        let mut found = self.relax(asm, &warm).unwrap_or_default();
        let parts = &asm.data().parts;
        let keeps = |&(part, _): &(usize, usize)| matches!(parts[part].kind, PartKind::Piece { instance } if kept.contains(&instance));
        found.retain(|p| !p.then_lengths);
        for p in &mut found {
            p.states.retain(|s| !keeps(s));
        }
        found.retain(|p| !p.is_empty());
        found
    }

    /// Number of stored entries of the normal matrix's lower triangle (after the first frame).
    pub fn matrix_nonzeros(&self) -> usize {
        self.pattern.nnz()
    }

    /// Number of values a Cholesky factor of the normal matrix stores (after the first frame;
    /// 0 for the CG solver).
    pub fn factor_values(&self) -> usize {
        self.symbolic.as_ref().map_or(0, |s| s.stored_values())
    }

    /// Runs one frame on `asm`: moves its positions, active states and rotations.
    pub fn frame(&mut self, asm: &mut Assembly) -> Result<FrameReport, SolverError> {
        self.frame_within(asm, Stop::Never, &mut |_, _, _| {})
    }

    /// Runs one frame with `between` called after pass 1 (paper 5.2: "after having
    /// determined the topology, we run a second optimization pass with the ordinary
    /// least-squares energy, the result of which will be displayed"): it gets the assembly, the
    /// frame's report so far (switches, claims) and the pass-1 pose, and may rewrite the
    /// assembly's structure (the stretch and shrink rules); pass 2 then runs on the rewritten
    /// assembly, from its positions, so what is displayed is the least-squares pose of the
    /// new structure. Its passes stop as `stop` says ([`Stop`]).
    pub fn frame_with(
        &mut self,
        asm: &mut Assembly,
        stop: Stop,
        between: &mut Between,
    ) -> Result<FrameReport, SolverError> {
        self.frame_within(asm, stop, between)
    }

    /// Runs one frame that stops early once `budget` is (about to be) spent, for an editor
    /// that must draw at a fixed rate. It always runs the pass-1 iterations that decide states
    /// (two: the first only weighs the parts; fewer if the configuration asks for fewer) and
    /// ends with at least one least-squares solve, so the displayed positions are a
    /// proper least-squares pose of the current states even when cut short. A further
    /// iteration is started only if the previous one of its pass fits in the time left. When
    /// cut short, the report has `complete == false` and `converged == false`; call again next
    /// frame: the positions and active states carry the work over. Only the passes stop
    /// early (the trials of other rest states run whole), and the report's
    /// `pass1_iterations` and `l2_iterations` say where, so [`Stop::After`] with them
    /// replays the frame bit for bit. A budget of `Duration::MAX` behaves like
    /// [`Solver::frame`].
    pub fn frame_budgeted(
        &mut self,
        asm: &mut Assembly,
        budget: Duration,
    ) -> Result<FrameReport, SolverError> {
        self.frame_within(asm, Stop::within(budget), &mut |_, _, _| {})
    }

    fn frame_within(
        &mut self,
        asm: &mut Assembly,
        stop: Stop,
        between: &mut Between,
    ) -> Result<FrameReport, SolverError> {
        let start = Instant::now();
        let on_pool = self.frame_uses_pool(asm);
        let mut run = || {
            self.prepare(asm)?;
            self.frame_prepared(asm, stop, start, between)
        };
        // A frame whose steps go to both cores runs as one task of the pool
        // (`chunks::on_pool`): each step is pushed to the pool from inside it rather than
        // handed over from this thread, which woke and put to sleep a thread about 90 times a
        // frame at 10k parts (docs/performance.md). The steps, and so the bits, are the same
        // wherever the frame runs. The preparation runs in the same task, so the frame's
        // buffers reuse the memory its analysis frees (a thread allocates from its own arena:
        // prepared on this thread, the 100k city peaked 5 MB higher).
        if on_pool { chunks::on_pool(run) } else { run() }
    }

    /// Whether some step of a frame on `asm` runs on both cores (judged by the last
    /// preparation's factor when the pattern is new: only where the frame runs depends on it).
    fn frame_uses_pool(&self, asm: &Assembly) -> bool {
        self.config.thread_count() > 1
            && (asm.data().parts.len() >= chunks::PARALLEL_MIN_PARTS
                || asm.data().positions.len() >= chunks::PARALLEL_MIN_ROWS
                || self.symbolic.as_ref().is_some_and(SymbolicFactor::is_split))
    }

    /// [`Solver::frame_within`] after [`Solver::prepare`] (`start`: when the frame began):
    /// the frame's table of contents, its steps in order (`docs/solver.md`), each in the file
    /// named beside it.
    fn frame_prepared(
        &mut self,
        asm: &mut Assembly,
        stop: Stop,
        start: Instant,
        between: &mut Between,
    ) -> Result<FrameReport, SolverError> {
        let mut report = FrameReport {
            complete: true,
            ..FrameReport::default()
        };
        if asm.data().positions.is_empty() || asm.data().parts.is_empty() {
            report.converged = true;
            report.ms = start.elapsed().as_secs_f64() * 1e3;
            return Ok(report);
        }
        // 1. Rigid following: the displayed pose, components moved by their handles (handles.rs).
        let mut warm = self.warm_start(asm)?;
        // 2. Pass 1's start, the held vertices snapped, and the chains' view (pass1.rs).
        let mut pose = self.pass1_start(asm, &warm);
        report.phases.bookkeeping += ms_since(start);
        // 3. Pass 1: the sparse norm by IRLS; its local steps choose the states (pass1.rs).
        let pass1 = self.pass1(&mut asm.data_mut().parts, &mut pose, stop, &mut report);
        self.pass1_pose = pose;
        // 4. Claims: how many elements each chain gains or loses, by its length (chains.rs).
        self.collect_claims(asm, &mut report);
        // a frame that fails leaves no evaluation to reuse (its states may have switched)
        self.work.start.valid.take_if(|_| pass1.is_err());
        let pass1_converged = pass1?;
        // 5. Trials: a held model that stopped strained tries other rest states (trials.rs).
        self.trials(asm, &mut warm, &mut report)?;
        // 6. The rules (`between`); pass 2 starts from their layout if they rewrote (handles.rs).
        let t = Instant::now();
        let before = asm.generation();
        between(asm, &report, &self.pass1_pose);
        if asm.generation() != before {
            self.restart(asm, &mut warm)?;
        }
        report.phases.bookkeeping += ms_since(t);
        // 7. Pass 2: least squares with the states fixed, from the displayed pose (pass2.rs).
        let (parts, handles, tolerance) = (&asm.data().parts, asm.handles(), self.config.tolerance);
        let pass2 = self.pass2(parts, handles, warm, tolerance, stop, &mut report);
        self.work.start.valid.take_if(|_| pass2.is_err());
        let (f, terms, pass2_converged) = pass2?;
        // 8. Pass 2's pose shown, kept for the next frame, and judged converged (pass2.rs).
        let converged = pass1_converged && pass2_converged;
        self.show(asm, f, terms, converged, &mut report)?;
        report.ms = start.elapsed().as_secs_f64() * 1e3;
        Ok(report)
    }
}
