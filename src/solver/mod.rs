//! The mutable elastic solver (paper 4.1-4.3, 5.2): one frame of alternating local steps
//! (rotations and rest-state choice with hysteresis) and global steps (a sparse linear solve),
//! warm-started from the previous positions. Pass 1 reweights edges for the sub-quadratic
//! norm (IRLS) and decides the active rest states; pass 2 is plain least squares with the
//! states fixed, and its positions are what the user sees.

pub mod admm;
pub mod cg;
pub mod cholesky;
pub mod global;
pub mod local;

use std::time::{Duration, Instant};

use clay_dsl::compiled::{Part, PartKind, SolverParams};
use glam::DVec2;

use crate::assembly::{Assembly, Handle};
use cholesky::{NumericFactor, SymbolicFactor};
use global::Pattern;

/// Which linear solver the global step uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SolverKind {
    /// Sparse supernodal Cholesky, symbolic analysis reused per assembly generation.
    #[default]
    Cholesky,
    /// Unpreconditioned conjugate gradients warm-started from the previous positions (the
    /// paper's own solver; the baseline).
    Cg,
}

/// How pass 1 minimises the sub-quadratic energy (both decide the active rest states).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Pass1 {
    /// Iteratively reweighted least squares (the paper's 5.2), restarted from the displayed
    /// pose every frame: a numeric factorisation per iteration.
    Irls,
    /// Variable splitting ([`admm`]): least-squares solves with the pass-2 factor, per-edge
    /// gaps and duals carried from frame to frame. No factorisation while the assembly and
    /// the held vertices stay the same.
    #[default]
    Admm,
}

impl Pass1 {
    pub fn name(self) -> &'static str {
        match self {
            Pass1::Irls => "irls",
            Pass1::Admm => "admm",
        }
    }

    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "irls" => Some(Pass1::Irls),
            "admm" => Some(Pass1::Admm),
            _ => None,
        }
    }
}

/// Solver parameters. The first four mirror the grammar's [`SolverParams`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverConfig {
    pub kind: SolverKind,
    /// The pass-1 method.
    pub pass1: Pass1,
    /// [`Pass1::Admm`]: residuals shorter than this fraction of the mean rest edge length
    /// close (the edge stays rigid); longer ones open as gaps.
    pub admm_threshold: f64,
    /// [`Pass1::Admm`]: edges at a held vertex close below this fraction of the threshold,
    /// i.e. weigh `factor^(2 - p)` in the sparse norm. Among equally strained edges the gaps
    /// then open at the handles first (paper 5.2: the handles are the outliers); without it a
    /// chain pulled evenly stays evenly stretched, a stationary point the splitting cannot
    /// leave by itself. Slightly below 1 breaks such ties without overriding real differences
    /// (0.5 makes the streets next to a handle turn first and tears a bent street).
    pub admm_handle_factor: f64,
    /// [`Pass1::Admm`]: most splitting iterations per frame (each a local step, a solve with
    /// the kept factor, a shrink and a dual update). The variables carry over between frames,
    /// so fewer are needed than IRLS iterations.
    pub admm_iterations: usize,
    /// A part switches to a nearer rest state only when `d_new < (1 - hysteresis) d_active`.
    pub hysteresis: f64,
    /// Exponent p of the IRLS pass (2 = least squares).
    pub norm: f64,
    /// Epsilon in the IRLS weight `1 / (|r| + eps)^(2 - p)`.
    pub irls_epsilon: f64,
    /// [`Pass1::Irls`]: most IRLS iterations per frame; each is a local and a global step
    /// with a fresh numeric factorisation.
    pub irls_iterations: usize,
    /// Most least-squares (pass 2) iterations per frame.
    pub l2_iterations: usize,
    /// Handle weight relative to the mean edge weight (Eq. 3): large, so handles are hard.
    pub handle_weight: f64,
    /// Proximal weight `mu` (relative to the mean edge weight) pulling every vertex towards the
    /// current iterate; keeps components without handles well-posed.
    pub proximal_weight: f64,
    /// Parts whose rotations differ by more than this many degrees do not average into each
    /// other's `R_xy` (pieces at a corner sit in different frames even at rest). 180 gives the
    /// paper's plain average, 0 each part's own rotation.
    pub rotation_cone_degrees: f64,
    /// A pass stops early once no vertex moved more than this fraction of the model's size
    /// (and, in pass 1, no state switched).
    pub tolerance: f64,
    /// Relative residual each CG solve reaches (`SolverKind::Cg`), measured against the norm of
    /// the right-hand side's edge terms (the handle rows would otherwise dominate it).
    pub cg_tolerance: f64,
    /// Cap on CG iterations per solve.
    pub cg_max_iterations: usize,
    /// Cholesky path, pass 1: most iterations of CG preconditioned by the last IRLS factor
    /// before the reweighted system is factorised afresh (0: factorise every IRLS iteration).
    /// The factor is kept across iterations and frames; only the weights change in between.
    pub pcg_max_iterations: usize,
    /// Relative residual (against the right-hand side's edge terms, as `cg_tolerance`) the
    /// preconditioned pass-1 solves reach. Pass 2 is always solved directly.
    pub pcg_tolerance: f64,
    /// A frame counts as converged ([`FrameReport::converged`]) when no state switched and the
    /// displayed positions moved less than this fraction of the model's size.
    pub settle_tolerance: f64,
    /// Compute the relative residual of every linear solve into the report (one extra matrix
    /// product per solve).
    pub measure_residual: bool,
}

impl Default for SolverConfig {
    fn default() -> Self {
        Self::from_params(&SolverParams::default())
    }
}

impl SolverConfig {
    /// The defaults with the grammar's parameters.
    pub fn from_params(params: &SolverParams) -> Self {
        Self {
            kind: SolverKind::Cholesky,
            pass1: Pass1::Admm,
            admm_threshold: 0.05,
            admm_handle_factor: 0.9,
            admm_iterations: 2,
            hysteresis: params.hysteresis,
            norm: params.norm,
            irls_epsilon: params.irls_epsilon,
            irls_iterations: 4,
            l2_iterations: 2,
            handle_weight: 1e6,
            rotation_cone_degrees: 20.0,
            proximal_weight: 1e-8,
            tolerance: 1e-6,
            cg_tolerance: 1e-6,
            cg_max_iterations: 20_000,
            pcg_max_iterations: 0,
            pcg_tolerance: 1e-6,
            settle_tolerance: 1e-6,
            measure_residual: false,
        }
    }
}

/// A part's active rest state changed during a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StateSwitch {
    pub part: usize,
    pub from: usize,
    pub to: usize,
}

/// What one frame did.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct FrameReport {
    /// Pass-1 iterations run (splitting or IRLS, per [`SolverConfig::pass1`]).
    pub pass1_iterations: usize,
    /// Least-squares (pass 2) iterations run.
    pub l2_iterations: usize,
    /// Pass-2 elastic energy (Eq. 4 with the final states and rotations), handles excluded.
    pub energy: f64,
    /// Pass-2 objective: `energy` plus the handle terms.
    pub objective: f64,
    /// The pass-2 objective of the warm start (the previous frame's positions, with this frame's
    /// handle targets and final states); `objective <= warm_objective` always.
    pub warm_objective: f64,
    /// Rest-state switches, in the order they happened.
    pub switches: Vec<StateSwitch>,
    /// Wall time of the frame in milliseconds.
    pub ms: f64,
    /// The frame left the model at rest: the frame was complete, no rest state switched, and
    /// the displayed positions moved less than [`SolverConfig::settle_tolerance`] times the
    /// model's size (or both passes stopped on their step tolerance). Running another frame
    /// with the same handles would change nothing visible, so a caller can stop solving.
    pub converged: bool,
    /// The frame ran the iterations its passes asked for; `false` when
    /// [`Solver::frame_budgeted`] cut it short to meet its time budget (the displayed
    /// positions are still a least-squares pose; the next call continues from them).
    pub complete: bool,
    /// Largest distance a displayed vertex moved this frame.
    pub moved: f64,
    /// Numeric Cholesky factorisations done this frame.
    pub factorizations: usize,
    /// CG iterations summed over all solves this frame (unpreconditioned, `SolverKind::Cg`).
    pub cg_iterations: usize,
    /// Iterations of CG preconditioned by a kept Cholesky factor (pass 1 of the Cholesky path).
    pub pcg_iterations: usize,
    /// Where the frame's time went.
    pub phases: PhaseTimes,
    /// Largest relative residual `|b - A x| / |b|` of the frame's linear solves, when
    /// [`SolverConfig::measure_residual`] is set.
    pub linear_residual: Option<f64>,
}

/// Wall time of a frame by phase, in milliseconds.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct PhaseTimes {
    /// Local steps: rest-state choice, rotations, edge targets, objective evaluations.
    pub local: f64,
    /// IRLS weights, right-hand side and matrix values.
    pub assembly: f64,
    /// Numeric Cholesky factorisations.
    pub factorization: f64,
    /// Triangular solves and (preconditioned) CG.
    pub solve: f64,
}

/// Why a frame could not be solved (left the positions unchanged).
#[derive(Clone, Debug, PartialEq)]
pub struct SolverError(pub String);

impl std::fmt::Display for SolverError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for SolverError {}

/// Buffers sized once per generation and reused every frame.
#[derive(Debug, Default)]
struct Work {
    rotations: Vec<DVec2>,
    vertex_parts: local::VertexParts,
    /// The parts' rest data flattened for the local step (rebuilt with the generation);
    /// `None` when it could not be built, and the local step then reads the parts directly.
    rest: Option<local::RestCache>,
    /// Per part-edge: `R_xy (x0 - y0)`.
    targets: Vec<DVec2>,
    weights: Vec<f64>,
    ones: Vec<f64>,
    /// Per vertex: number of handle targets, and their sum.
    handle_count: Vec<f64>,
    handle_sum: Vec<DVec2>,
    diagonal: Vec<f64>,
    extra: Vec<DVec2>,
    values: Vec<f64>,
    l2_values: Vec<f64>,
    l2_diagonal: Vec<f64>,
    rhs: Vec<f64>,
    /// The least-squares right-hand side, one `(x, y)` per vertex in vertex order.
    vertex_rhs: Vec<DVec2>,
    solution: Vec<f64>,
    scratch: Vec<f64>,
    cg: cg::CgWork,
    part_sums: Vec<DVec2>,
    warm: Vec<DVec2>,
    /// Rotations and edge targets of the warm start with the final states (filled by the
    /// first local step of pass 1 when no later one switches, else by pass 2), so pass 2 does
    /// not recompute them.
    warm_rotations: Vec<DVec2>,
    warm_targets: Vec<DVec2>,
    /// Rotations and edge targets of the kept pass-2 iterate while the next one is judged.
    kept_rotations: Vec<DVec2>,
    kept_targets: Vec<DVec2>,
    warm_held: Vec<DVec2>,
    /// The positions the last frame displayed (the splitting pass continues only from them).
    shown: Vec<DVec2>,
    /// The generation and active states for which `rotations` and `targets` are those of
    /// `shown` (set by a frame that finished, taken by the next one): the first local step
    /// then only judges the parts that have a state to switch to.
    carried: Option<u64>,
    carried_states: Vec<usize>,
    /// Scratch: the parts whose edge targets a state switch changed.
    touched: Vec<usize>,
    f: Vec<DVec2>,
    next: Vec<DVec2>,
}

/// The solver for one live assembly. Keeps the sparsity pattern, the symbolic factorisation
/// and all buffers between frames; rebuilds them when the assembly's generation changes.
#[derive(Debug)]
pub struct Solver {
    pub config: SolverConfig,
    generation: Option<u64>,
    pattern: Pattern,
    symbolic: Option<SymbolicFactor>,
    irls_factor: NumericFactor,
    l2_factor: NumericFactor,
    work: Work,
    /// Pass-1 splitting variables ([`Pass1::Admm`]), carried between frames.
    splitting: admm::Splitting,
    /// Scratch: the shifted edge targets `t + z - u` of a splitting solve.
    shifted: Vec<DVec2>,
    /// Per vertex, its row in the factor's fill-reducing order (the inverse of
    /// [`SymbolicFactor::factor_order`]; empty when the factor has no such order): the
    /// least-squares solve reads its solution from there.
    factor_slot: Vec<usize>,
    /// The least-squares right-hand side and solution, `(x, y)` per row in factor order.
    ordered: Vec<[f64; 2]>,
}

impl Solver {
    pub fn new(config: SolverConfig) -> Self {
        Self {
            config,
            generation: None,
            pattern: Pattern::default(),
            symbolic: None,
            irls_factor: NumericFactor::default(),
            l2_factor: NumericFactor::default(),
            work: Work::default(),
            splitting: admm::Splitting::default(),
            shifted: Vec::new(),
            factor_slot: Vec::new(),
            ordered: Vec::new(),
        }
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

    /// Rebuilds the pattern and symbolic factorisation if the assembly changed structurally.
    fn prepare(&mut self, asm: &Assembly) -> Result<(), SolverError> {
        let n = asm.data.positions.len();
        let edge_count: usize = asm.data.parts.iter().map(|p| p.edges.len()).sum();
        let stale = self.generation != Some(asm.generation())
            || self.pattern.n != n
            || self.pattern.edges.len() != edge_count
            || self
                .work
                .rest
                .as_ref()
                .is_some_and(|c| c.parts() != asm.data.parts.len());
        if !stale {
            return Ok(());
        }
        // the pattern and the rest cache keep vertex indices as u32
        if u32::try_from(n).is_err() {
            return Err(SolverError(format!(
                "the model has {n} vertices, more than the solver can index"
            )));
        }
        for (i, p) in asm.data.parts.iter().enumerate() {
            let m = p.vertices.len();
            if p.vertices.iter().any(|&v| v >= n) || p.edges.iter().any(|e| e[0] >= m || e[1] >= m)
            {
                return Err(SolverError(format!(
                    "part {i} refers to a vertex that does not exist"
                )));
            }
        }
        self.pattern = Pattern::build(n, &asm.data.parts);
        self.work.vertex_parts = local::VertexParts::build(&asm.data.parts, n);
        self.work.rest = local::RestCache::build(&asm.data.parts, &self.work.vertex_parts);
        self.symbolic = match self.config.kind {
            SolverKind::Cholesky if n > 0 => Some(
                SymbolicFactor::analyse(n, &self.pattern.col_ptr, &self.pattern.row_idx)
                    .map_err(|e| SolverError(e.0))?,
            ),
            _ => None,
        };
        self.factor_slot.clear();
        if let Some(order) = self.symbolic.as_ref().and_then(|s| s.factor_order()) {
            self.factor_slot.resize(n, 0);
            for (i, &v) in order.iter().enumerate() {
                self.factor_slot[v] = i;
            }
        }
        self.irls_factor.invalidate();
        self.l2_factor.invalidate();
        self.work.l2_diagonal.clear();
        self.generation = Some(asm.generation());
        Ok(())
    }

    /// Runs one frame on `asm`: moves its positions, active states and rotations.
    pub fn frame(&mut self, asm: &mut Assembly) -> Result<FrameReport, SolverError> {
        self.frame_within(asm, None)
    }

    /// Runs one frame that stops early once `budget` is (about to be) spent, for an editor
    /// that must draw at a fixed rate. It always runs the pass-1 iterations that decide states
    /// (two splitting iterations, or one IRLS iteration; fewer if the configuration asks for
    /// fewer) and ends with at least one least-squares solve, so the displayed positions are a
    /// proper least-squares pose of the current states even when cut short. A further
    /// iteration is started only if the previous one of its pass fits in the time left. When
    /// cut short, the report has `complete == false` and `converged == false`; call again next
    /// frame: the positions, active states and splitting variables carry the work over. A
    /// budget of `Duration::MAX` behaves like [`Solver::frame`].
    pub fn frame_budgeted(
        &mut self,
        asm: &mut Assembly,
        budget: Duration,
    ) -> Result<FrameReport, SolverError> {
        let deadline = Instant::now().checked_add(budget);
        self.frame_within(asm, deadline)
    }

    fn frame_within(
        &mut self,
        asm: &mut Assembly,
        deadline: Option<Instant>,
    ) -> Result<FrameReport, SolverError> {
        let start = Instant::now();
        // Would another iteration that lasts as long as the last one overrun the deadline?
        let out_of_time = |last: Duration| deadline.is_some_and(|d| Instant::now() + last > d);
        self.prepare(asm)?;
        let mut report = FrameReport::default();
        let n = asm.data.positions.len();
        report.complete = true;
        if n == 0 || asm.data.parts.is_empty() {
            report.converged = true;
            report.ms = start.elapsed().as_secs_f64() * 1e3;
            return Ok(report);
        }
        let cfg = self.config;
        self.gather_handles(asm.handles(), n);
        // Position buffers live in `work` between frames (taken here, put back at the end; an
        // error path just drops them and the next frame reallocates).
        let mut warm = std::mem::take(&mut self.work.warm);
        warm.clear();
        warm.extend_from_slice(&asm.data.positions);
        if warm.iter().any(|p| !p.is_finite()) {
            return Err(SolverError(
                "the warm start has non-finite positions".into(),
            ));
        }
        let scale = bbox_diagonal(&warm).max(1e-9);
        let step_tolerance = cfg.tolerance * scale;
        // Handle vertices start at their targets: the gap then opens where the handle meets the
        // rest of the model, and the sub-quadratic norm keeps it there (paper 5.2: handles are
        // the "outliers" and gaps first appear near them).
        let mut warm_held = std::mem::take(&mut self.work.warm_held);
        warm_held.clone_from(&warm);
        for (v, p) in warm_held.iter_mut().enumerate() {
            let count = self.work.handle_count[v];
            if count > 0.0 {
                *p = self.work.handle_sum[v] / count;
            }
        }
        let mut f = std::mem::take(&mut self.work.f);
        let mut next = std::mem::take(&mut self.work.next);
        next.clear();
        next.resize(n, DVec2::ZERO);
        let mut pass1_converged = false;
        // Set once `work.warm_*` hold the displayed pose's rotations and edge targets, with
        // the states as they were after that many of this frame's switches.
        let mut warm_cached: Option<usize> = None;

        // Pass 1 by splitting: least-squares solves with the pass-2 factor.
        let pass1_iterations = match cfg.pass1 {
            Pass1::Irls => cfg.irls_iterations,
            Pass1::Admm => cfg.admm_iterations,
        };
        let irls_iterations = match cfg.pass1 {
            Pass1::Irls => cfg.irls_iterations,
            Pass1::Admm => 0,
        };
        let carried = self.work.carried.take() == Some(asm.generation())
            && self.work.carried_states.len() == asm.data.parts.len()
            && self
                .work
                .carried_states
                .iter()
                .zip(&asm.data.parts)
                .all(|(&s, p)| s == p.active)
            && self.work.rotations.len() == asm.data.parts.len()
            && self.work.targets.len() == self.pattern.edges.len();
        if cfg.pass1 == Pass1::Admm && cfg.admm_iterations > 0 {
            let carry = self.work.shown == warm;
            pass1_converged = self.split_pass(
                asm,
                SplitStart {
                    warm: &warm,
                    carry,
                    carried: carry && carried,
                    step_tolerance,
                    deadline,
                },
                &mut f,
                &mut next,
                &mut report,
                &mut warm_cached,
            )?;
        } else {
            f.clone_from(&warm_held);
            // the splitting variables did not follow this frame
            self.splitting.generation = None;
        }

        // Pass 1: IRLS with the sub-quadratic norm; local steps decide the active states.
        let mut last_iteration = Duration::ZERO;
        for it in 0..irls_iterations {
            if it > 0 && out_of_time(last_iteration) {
                report.complete = false;
                break;
            }
            let iteration_start = Instant::now();
            report.pass1_iterations += 1;
            let t = Instant::now();
            let switched_before = report.switches.len();
            let pose = if it == 0 { &warm } else { &f };
            self.judge_states(
                &mut asm.data.parts,
                pose,
                it == 0,
                &mut report,
                &mut warm_cached,
            );
            report.phases.local += ms_since(t);
            let t = Instant::now();
            let (p, eps) = (cfg.norm, cfg.irls_epsilon.max(1e-12));
            let w = &mut self.work;
            w.weights.clear();
            for (e, &t) in self.pattern.edges.iter().zip(&w.targets) {
                let r = (t - (f[e.x] - f[e.y])).length();
                let weight = irls_weight(r + eps, p);
                w.weights.push(if weight.is_finite() {
                    weight
                } else {
                    eps.powf(p - 2.0)
                });
            }
            let mean = mean_or_one(&w.weights);
            report.phases.assembly += ms_since(t);
            self.solve_global(&f, &mut next, mean, Pass::Irls, &mut report)?;
            let delta = max_move(&f, &next);
            std::mem::swap(&mut f, &mut next);
            last_iteration = iteration_start.elapsed();
            if delta <= step_tolerance && report.switches.len() == switched_before {
                pass1_converged = true;
                break;
            }
        }
        if pass1_iterations == 0 {
            pass1_converged = true;
        }

        // Pass 2: least squares, states fixed. Start from whichever of the pass-1 result and
        // the warm start is better, and never accept an iterate that raises the objective, so
        // the frame cannot end worse than it started.
        let handles = asm.handles();
        let t = Instant::now();
        // Candidates: the pass-1 result, the warm start with the handles carried to their
        // targets (continues last frame's least-squares pose), and the plain warm start. The
        // handles-moved start is judged only when the pass-1 result does not beat the warm
        // start (while dragging it nearly always does: one local step saved).
        let parts = &asm.data.parts;
        match warm_cached {
            Some(k) if k == report.switches.len() => {}
            // Later local steps switched a few parts: only theirs and their neighbours'
            // rotations and targets at the warm start changed.
            Some(k) if self.retarget_warm(parts, &warm, &report.switches[k..]) => {}
            _ => {
                self.objective(parts, handles, &warm);
                self.work.warm_rotations.clone_from(&self.work.rotations);
                self.work.warm_targets.clone_from(&self.work.targets);
            }
        }
        let warm_terms = self.terms_at(&self.work.warm_targets, handles, &warm);
        // objective() leaves f's rotations and edge targets in the work buffers
        let mut terms = self.objective(parts, handles, &f);
        report.warm_objective = warm_terms.total();
        let mut chosen = 0;
        let held_judged = report.pass1_iterations > 0 && terms.total() >= warm_terms.total();
        if held_judged {
            // keep f's rotations and edge targets aside while the held start is judged
            std::mem::swap(&mut self.work.rotations, &mut self.work.kept_rotations);
            std::mem::swap(&mut self.work.targets, &mut self.work.kept_targets);
            let held_terms = self.objective(parts, handles, &warm_held);
            if held_terms.total() < terms.total() {
                (chosen, terms) = (1, held_terms);
            }
        }
        if warm_terms.total() < terms.total() {
            (chosen, terms) = (2, warm_terms);
        }
        if chosen != 0 {
            f.copy_from_slice(if chosen == 1 { &warm_held } else { &warm });
        }
        // The first solve uses the rotations of its start, or for the handles-moved warm
        // start those of the last displayed pose (see pass 1).
        if chosen != 0 || report.pass1_iterations == 0 {
            self.work.rotations.clone_from(&self.work.warm_rotations);
            self.work.targets.clone_from(&self.work.warm_targets);
        } else if held_judged {
            // judging the handles-moved start overwrote f's rotations: take back the kept ones
            std::mem::swap(&mut self.work.rotations, &mut self.work.kept_rotations);
            std::mem::swap(&mut self.work.targets, &mut self.work.kept_targets);
        }
        // Whether the work buffers hold the rotations and edge targets of `f` itself (not
        // so for the handles-moved start, which borrows the displayed pose's).
        let mut exact = chosen == 2 || (chosen == 0 && report.pass1_iterations > 0);
        report.phases.local += ms_since(t);
        let mut pass2_converged = cfg.l2_iterations == 0;
        let mut last_iteration = Duration::ZERO;
        for it in 0..cfg.l2_iterations {
            if it > 0 && out_of_time(last_iteration) {
                report.complete = false;
                break;
            }
            let iteration_start = Instant::now();
            report.l2_iterations += 1;
            // objective() left the rotations and edge targets of `f` in the work buffers.
            self.solve_global(&f, &mut next, 1.0, Pass::LeastSquares, &mut report)?;
            let t = Instant::now();
            // keep f's rotations aside instead of recomputing them if `next` is rejected
            std::mem::swap(&mut self.work.rotations, &mut self.work.kept_rotations);
            std::mem::swap(&mut self.work.targets, &mut self.work.kept_targets);
            let new_terms = self.objective(&asm.data.parts, handles, &next);
            let improved = new_terms
                .total()
                .partial_cmp(&terms.total())
                .is_some_and(|o| o.is_le());
            if !improved {
                // restore rotations of the kept iterate
                std::mem::swap(&mut self.work.rotations, &mut self.work.kept_rotations);
                std::mem::swap(&mut self.work.targets, &mut self.work.kept_targets);
                report.phases.local += ms_since(t);
                pass2_converged = true;
                break;
            }
            report.phases.local += ms_since(t);
            let delta = max_move(&f, &next);
            std::mem::swap(&mut f, &mut next);
            terms = new_terms;
            exact = true;
            last_iteration = iteration_start.elapsed();
            if delta <= step_tolerance {
                pass2_converged = true;
                break;
            }
        }

        if f.iter().any(|p| !p.is_finite()) {
            return Err(SolverError(
                "the solve produced non-finite positions".into(),
            ));
        }
        asm.data.positions.copy_from_slice(&f);
        let rot = asm.rotations_mut();
        if rot.len() == self.work.rotations.len() {
            rot.copy_from_slice(&self.work.rotations);
        }
        sync_instance_states(asm);
        report.energy = terms.elastic;
        report.objective = terms.total();
        report.moved = max_move(&warm, &f);
        let settled = report.switches.is_empty() && report.moved <= cfg.settle_tolerance * scale;
        report.converged = report.complete && (settled || (pass1_converged && pass2_converged));
        self.work.shown.clone_from(&f);
        self.work.carried = exact.then_some(asm.generation());
        self.work.carried_states.clear();
        self.work
            .carried_states
            .extend(asm.data.parts.iter().map(|p| p.active));
        report.ms = start.elapsed().as_secs_f64() * 1e3;
        (
            self.work.warm,
            self.work.warm_held,
            self.work.f,
            self.work.next,
        ) = (warm, warm_held, f, next);
        Ok(report)
    }

    /// Pass 1 by splitting ([`admm`]): up to `admm_iterations` iterations of local step,
    /// least-squares solve with the edge targets shifted by `z - u` (pass 2's factor), shrink
    /// and dual update. Continues the last frame's splitting variables and pass-1 pose when
    /// the assembly is the same generation and shows what the solver last displayed; else
    /// starts from the displayed pose with no gaps. Leaves the pass-1 pose in `f`; returns
    /// whether it converged.
    fn split_pass(
        &mut self,
        asm: &mut Assembly,
        start: SplitStart<'_>,
        f: &mut Vec<DVec2>,
        next: &mut Vec<DVec2>,
        report: &mut FrameReport,
        warm_cached: &mut Option<usize>,
    ) -> Result<bool, SolverError> {
        let cfg = self.config;
        let warm = start.warm;
        let n = warm.len();
        let m = self.pattern.edges.len();
        let mut split = std::mem::take(&mut self.splitting);
        if !(start.carry && split.is_valid(asm.generation(), m, n)) {
            split.reset(asm.generation(), m, warm);
        }
        // The pass-1 pose continues; the handles' vertices jump to their targets.
        f.clone_from(&split.pose);
        for (v, p) in f.iter_mut().enumerate() {
            let count = self.work.handle_count[v];
            if count > 0.0 {
                *p = self.work.handle_sum[v] / count;
            }
        }
        let p = cfg.norm;
        let mut rho = 1.0;
        let mut converged = false;
        let mut last_iteration = Duration::ZERO;
        let mut result = Ok(());
        for it in 0..cfg.admm_iterations {
            // Two iterations are the least that decides states: the first judges the
            // displayed pose, the second the pass-1 pose, where the gaps are.
            if it >= MIN_SPLIT_ITERATIONS
                && start
                    .deadline
                    .is_some_and(|d| Instant::now() + last_iteration > d)
            {
                report.complete = false;
                break;
            }
            let iteration_start = Instant::now();
            report.pass1_iterations += 1;
            let t = Instant::now();
            let switched_before = report.switches.len();
            if it == 0 && start.carried {
                self.judge_carried(&mut asm.data.parts, warm, report, warm_cached);
            } else {
                let pose: &[DVec2] = if it == 0 { warm } else { f };
                self.judge_states(&mut asm.data.parts, pose, it == 0, report, warm_cached);
            }
            // A part that switched state has new rest edges: its gaps and duals start over.
            let edges = &self.pattern.edges;
            for s in &report.switches[switched_before..] {
                // edges are listed part by part
                let first = edges.partition_point(|e| e.part < s.part);
                let count = edges[first..]
                    .iter()
                    .take_while(|e| e.part == s.part)
                    .count();
                split.z[first..first + count].fill(DVec2::ZERO);
                split.u[first..first + count].fill(DVec2::ZERO);
            }
            if it == 0 {
                let lengths: f64 = self.work.targets.iter().map(|t| t.length()).sum();
                let mean = if m > 0 { lengths / m as f64 } else { 1.0 };
                let threshold = cfg.admm_threshold * if mean > 0.0 { mean } else { 1.0 };
                rho = admm::penalty(threshold, p);
            }
            self.shifted.clear();
            self.shifted.extend(
                self.work
                    .targets
                    .iter()
                    .zip(split.z.iter().zip(&split.u))
                    .map(|(&t, (&z, &u))| t + z - u),
            );
            report.phases.local += ms_since(t);
            std::mem::swap(&mut self.work.targets, &mut self.shifted);
            let solved = self.solve_global(f, next, 1.0, Pass::LeastSquares, report);
            std::mem::swap(&mut self.work.targets, &mut self.shifted);
            if let Err(e) = solved {
                result = Err(e);
                break;
            }
            let t = Instant::now();
            let shrink = admm::Shrink::new(rho, p);
            // weight c = factor^(2 - p) in the norm: the penalty seen by the shrink is rho / c
            let factor = cfg.admm_handle_factor.clamp(1e-3, 1.0);
            let at_handle = admm::Shrink::new(rho / factor.powf(2.0 - p), p);
            let held = &self.work.handle_count;
            for (k, &[x, y]) in self.pattern.ends.iter().enumerate() {
                let (x, y) = (x as usize, y as usize);
                let v = (next[x] - next[y]) - self.work.targets[k] + split.u[k];
                let z = if held[x] > 0.0 || held[y] > 0.0 {
                    at_handle.apply(v)
                } else {
                    shrink.apply(v)
                };
                split.z[k] = z;
                split.u[k] = v - z;
            }
            report.phases.local += ms_since(t);
            let delta = max_move(f, next);
            std::mem::swap(f, next);
            last_iteration = iteration_start.elapsed();
            if delta <= start.step_tolerance && report.switches.len() == switched_before {
                converged = true;
                break;
            }
        }
        split.pose.clone_from(f);
        self.splitting = split;
        result.map(|()| converged)
    }

    /// A pass-1 local step: rotations and state choice at `pose`, then the edge targets.
    /// The first of a frame (`first`) judges the displayed pose, before the handles moved
    /// (judged with only the handles moved, the parts next to a handle look rotated and the
    /// first solve would bend a model that should just follow rigidly); its rotations and
    /// targets are also pass 2's warm start, kept in `warm_*` until a later step switches a
    /// state.
    fn judge_states(
        &mut self,
        parts: &mut [Part],
        pose: &[DVec2],
        first: bool,
        report: &mut FrameReport,
        warm_cached: &mut Option<usize>,
    ) {
        self.local_step_switching(parts, pose, self.config.hysteresis, &mut report.switches);
        self.edge_targets(parts);
        if first {
            self.work.warm_rotations.clone_from(&self.work.rotations);
            self.work.warm_targets.clone_from(&self.work.targets);
            *warm_cached = Some(report.switches.len());
        }
    }

    /// The first local step of a frame that starts where the last one ended, whose
    /// rotations and edge targets are still in the work buffers: only parts with more than
    /// one rest state are judged (a part keeping its state gets the same rotation, bit for
    /// bit, since both come from the same sums), and the edge targets are recomputed only
    /// when one switched. Otherwise as [`Solver::judge_states`] with `first`.
    fn judge_carried(
        &mut self,
        parts: &mut [Part],
        pose: &[DVec2],
        report: &mut FrameReport,
        warm_cached: &mut Option<usize>,
    ) {
        let switched_before = report.switches.len();
        let hysteresis = self.config.hysteresis;
        let w = &mut self.work;
        for (i, part) in parts.iter_mut().enumerate() {
            if part.states.len() < 2 {
                continue;
            }
            let (state, r) = match &mut w.rest {
                Some(cache) => cache.choose_state(i, part, pose, hysteresis),
                None => local::choose_state(part, pose, hysteresis),
            };
            if state != part.active {
                report.switches.push(StateSwitch {
                    part: i,
                    from: part.active,
                    to: state,
                });
                part.active = state;
            }
            w.rotations[i] = r;
        }
        if report.switches.len() > switched_before
            && !self.retarget_switched(parts, &report.switches[switched_before..])
        {
            self.edge_targets(parts);
        }
        debug_assert!(self.carried_is_exact(parts, pose));
        self.work.warm_rotations.clone_from(&self.work.rotations);
        self.work.warm_targets.clone_from(&self.work.targets);
        *warm_cached = Some(report.switches.len());
    }

    /// Brings `work.rotations` and `work.targets`, which hold some pose's values with the
    /// states before `switches`, up to date after them, given that the switched parts'
    /// rotations already are: a switch changes the part's rest edges and rotation, hence its
    /// own targets and those of every part sharing a vertex with it (their `R_xy`); no
    /// other target. `false` (nothing done) without a rest cache that fits the parts.
    fn retarget_switched(&mut self, parts: &[Part], switches: &[StateSwitch]) -> bool {
        let cos_cone = cone_cosine(self.config.rotation_cone_degrees);
        let w = &mut self.work;
        match &mut w.rest {
            Some(cache) if cache.parts() == parts.len() && cache.edges() == w.targets.len() => {
                w.touched.clear();
                for s in switches {
                    w.touched.push(s.part);
                    for &v in &parts[s.part].vertices {
                        w.touched.extend_from_slice(w.vertex_parts.of(v));
                    }
                }
                w.touched.sort_unstable();
                w.touched.dedup();
                cache.edge_targets_of(parts, &w.touched, &w.rotations, cos_cone, &mut w.targets);
                true
            }
            _ => false,
        }
    }

    /// Brings the warm start's rotations and edge targets (`work.warm_*`, computed at `warm`
    /// before `switches`) up to date with the parts' states, recomputing only what the
    /// switches changed: the same values, bit for bit, as a full local step at `warm`.
    /// `work.rotations` and `work.targets` are left as they were. `false` when it could not
    /// (the caller then redoes the local step at `warm`).
    fn retarget_warm(&mut self, parts: &[Part], warm: &[DVec2], switches: &[StateSwitch]) -> bool {
        let w = &mut self.work;
        if w.warm_rotations.len() != parts.len() || switches.iter().any(|s| s.part >= parts.len()) {
            return false;
        }
        let Some(cache) = &mut w.rest else {
            return false;
        };
        std::mem::swap(&mut w.rotations, &mut w.warm_rotations);
        std::mem::swap(&mut w.targets, &mut w.warm_targets);
        for s in switches {
            w.rotations[s.part] = cache.part_rotation(s.part, &parts[s.part], warm);
        }
        let done = self.retarget_switched(parts, switches);
        debug_assert!(!done || self.carried_is_exact(parts, warm));
        let w = &mut self.work;
        std::mem::swap(&mut w.rotations, &mut w.warm_rotations);
        std::mem::swap(&mut w.targets, &mut w.warm_targets);
        done
    }

    /// Debug check of [`Solver::judge_carried`]: the carried rotations and edge targets
    /// equal, bit for bit, those recomputed at `pose` (checked on models small enough to
    /// afford it).
    fn carried_is_exact(&mut self, parts: &[Part], pose: &[DVec2]) -> bool {
        if parts.len() > 5000 {
            return true;
        }
        let (rotations, targets) = (self.work.rotations.clone(), self.work.targets.clone());
        let bits = |v: &[DVec2]| -> Vec<[u64; 2]> {
            v.iter().map(|p| [p.x.to_bits(), p.y.to_bits()]).collect()
        };
        self.work.rotations.clear();
        for (i, part) in parts.iter().enumerate() {
            let r = match &mut self.work.rest {
                Some(cache) => cache.part_rotation(i, part, pose),
                None => local::part_rotation(part, pose),
            };
            self.work.rotations.push(r);
        }
        self.edge_targets(parts);
        let exact = bits(&rotations) == bits(&self.work.rotations)
            && bits(&targets) == bits(&self.work.targets);
        (self.work.rotations, self.work.targets) = (rotations, targets);
        exact
    }

    fn gather_handles(&mut self, handles: &[Handle], n: usize) {
        let w = &mut self.work;
        w.handle_count.clear();
        w.handle_count.resize(n, 0.0);
        w.handle_sum.clear();
        w.handle_sum.resize(n, DVec2::ZERO);
        for h in handles {
            for (k, &v) in h.vertices.iter().enumerate() {
                if v < n {
                    let t = h.target(k);
                    if t.is_finite() {
                        w.handle_count[v] += 1.0;
                        w.handle_sum[v] += t;
                    }
                }
            }
        }
    }

    /// Local step with state switching; fills `work.rotations`.
    fn local_step_switching(
        &mut self,
        parts: &mut [Part],
        f: &[DVec2],
        hysteresis: f64,
        switches: &mut Vec<StateSwitch>,
    ) {
        let w = &mut self.work;
        w.rotations.clear();
        for (i, part) in parts.iter_mut().enumerate() {
            let (state, r) = match &mut w.rest {
                Some(cache) => cache.choose_state(i, part, f, hysteresis),
                None => local::choose_state(part, f, hysteresis),
            };
            if state != part.active {
                switches.push(StateSwitch {
                    part: i,
                    from: part.active,
                    to: state,
                });
                part.active = state;
            }
            w.rotations.push(r);
        }
    }

    /// `R_xy (x0 - y0)` for every part-edge from `work.rotations` and the active states.
    /// Same result as [`local::edge_rotation`] per edge, but each part sums its vertices'
    /// neighbour rotations once instead of once per edge end.
    fn edge_targets(&mut self, parts: &[Part]) {
        let w = &mut self.work;
        let cos_cone = cone_cosine(self.config.rotation_cone_degrees);
        let edges = &self.pattern.edges;
        if let Some(cache) = &mut w.rest
            && cache.parts() == parts.len()
            && cache.edges() == edges.len()
        {
            cache.edge_targets(parts, &w.rotations, cos_cone, &mut w.targets);
            return;
        }
        w.targets.clear();
        let mut k = 0;
        for (pi, part) in parts.iter().enumerate() {
            let own = w.rotations[pi];
            w.part_sums.clear();
            if cos_cone < 1.0 {
                for &v in &part.vertices {
                    w.part_sums.push(local::vertex_rotation_sum(
                        &w.vertex_parts,
                        &w.rotations,
                        v,
                        own,
                        cos_cone,
                    ));
                }
            }
            let rest = part
                .states
                .get(part.active)
                .map(|s| s.positions.as_slice())
                .unwrap_or(&[]);
            while k < edges.len() && edges[k].part == pi {
                let e = &edges[k];
                let d0 = match (rest.get(e.local[0]), rest.get(e.local[1])) {
                    (Some(&a), Some(&b)) => a - b,
                    _ => DVec2::ZERO,
                };
                let r = if cos_cone < 1.0 {
                    local::normalised_or(w.part_sums[e.local[0]] + w.part_sums[e.local[1]], own)
                } else {
                    own
                };
                w.targets.push(r.rotate(d0));
                k += 1;
            }
        }
    }

    /// Pass-2 objective at `f` with the states fixed; leaves `f`'s rotations and edge targets
    /// in the work buffers.
    fn objective(&mut self, parts: &[Part], handles: &[Handle], f: &[DVec2]) -> Terms {
        let w = &mut self.work;
        match &mut w.rest {
            Some(cache) => cache.part_rotations(parts, f, &mut w.rotations),
            None => {
                w.rotations.clear();
                w.rotations
                    .extend(parts.iter().map(|part| local::part_rotation(part, f)));
            }
        }
        self.edge_targets(parts);
        self.terms_at(&self.work.targets, handles, f)
    }

    /// The pass-2 objective's terms at `f` for the given edge targets.
    fn terms_at(&self, targets: &[DVec2], handles: &[Handle], f: &[DVec2]) -> Terms {
        let hw = self.config.handle_weight;
        // the compact edge ends of the rest cache instead of the wide edge slots
        match self.work.rest.as_ref().and_then(|c| c.elastic(targets, f)) {
            Some(elastic) => Terms {
                elastic,
                ..terms(&[], &[], handles, f, hw)
            },
            None => terms(&self.pattern.edges, targets, handles, f, hw),
        }
    }

    /// Global step: solves for `next` with the current edge targets and the weights of `pass`.
    fn solve_global(
        &mut self,
        f: &[DVec2],
        next: &mut [DVec2],
        mean_weight: f64,
        pass: Pass,
        report: &mut FrameReport,
    ) -> Result<(), SolverError> {
        let cfg = self.config;
        let n = f.len();
        if pass == Pass::LeastSquares
            && cfg.kind == SolverKind::Cholesky
            && self.factor_slot.len() == n
        {
            return self.solve_least_squares_ordered(f, next, report);
        }
        let t = Instant::now();
        let w = &mut self.work;
        let lambda = cfg.handle_weight * mean_weight;
        let mu = cfg.proximal_weight * mean_weight;
        w.diagonal.clear();
        w.extra.clear();
        for ((&count, &sum), &p) in w.handle_count.iter().zip(&w.handle_sum).zip(f) {
            w.diagonal.push(lambda * count + mu);
            w.extra.push(lambda * sum + mu * p);
        }
        let weights: &[f64] = match pass {
            Pass::Irls => {
                global::fill_rhs(
                    &self.pattern.edges,
                    &w.weights,
                    &w.targets,
                    &w.extra,
                    &mut w.rhs,
                );
                &w.weights
            }
            Pass::LeastSquares => {
                global::fill_rhs_unit(&self.pattern.ends, &w.targets, &w.extra, &mut w.rhs);
                &[]
            }
        };
        match pass {
            Pass::Irls => self
                .pattern
                .fill_values(weights, &w.diagonal, &mut w.values),
            Pass::LeastSquares => refresh_least_squares(&self.pattern, w, &mut self.l2_factor),
        }
        let values = if pass == Pass::LeastSquares {
            &w.l2_values
        } else {
            &w.values
        };
        w.solution.clear();
        w.solution.extend(f.iter().map(|p| p.x));
        w.solution.extend(f.iter().map(|p| p.y));
        report.phases.assembly += ms_since(t);
        match (cfg.kind, self.symbolic.as_mut()) {
            (SolverKind::Cholesky, Some(symbolic)) => {
                let factor = if pass == Pass::LeastSquares {
                    &mut self.l2_factor
                } else {
                    &mut self.irls_factor
                };
                // Pass 1: the kept factor of an earlier IRLS matrix (same pattern, other
                // weights) preconditions CG on this one; only when that takes too long is the
                // matrix factorised afresh.
                let mut solved = false;
                if pass == Pass::Irls && factor.is_valid() && cfg.pcg_max_iterations > 0 {
                    let t = Instant::now();
                    let outcome = {
                        let factor = &*factor;
                        let mut precondition =
                            |z: &mut [f64]| symbolic.solve_in_place(factor, z, 2);
                        cg::solve(
                            &self.pattern,
                            values,
                            &w.rhs,
                            &mut w.solution,
                            cg::CgStop {
                                tolerance: cfg.pcg_tolerance,
                                max_iterations: cfg.pcg_max_iterations,
                                reference: Some(elastic_norm(&w.rhs, &w.extra)),
                            },
                            Some(&mut precondition),
                            &mut w.cg,
                        )
                    };
                    report.pcg_iterations += outcome.iterations;
                    report.phases.solve += ms_since(t);
                    solved = outcome.converged;
                }
                if !solved {
                    if pass == Pass::Irls || !factor.is_valid() {
                        let t = Instant::now();
                        symbolic
                            .factorize(factor, &self.pattern.col_ptr, &self.pattern.row_idx, values)
                            .map_err(|e| SolverError(e.0))?;
                        report.factorizations += 1;
                        report.phases.factorization += ms_since(t);
                    }
                    let t = Instant::now();
                    w.solution.copy_from_slice(&w.rhs);
                    symbolic.solve_in_place(factor, &mut w.solution, 2);
                    report.phases.solve += ms_since(t);
                }
            }
            _ => {
                let t = Instant::now();
                let outcome = cg::solve(
                    &self.pattern,
                    values,
                    &w.rhs,
                    &mut w.solution,
                    cg::CgStop {
                        tolerance: cfg.cg_tolerance,
                        max_iterations: cfg.cg_max_iterations,
                        reference: Some(elastic_norm(&w.rhs, &w.extra)),
                    },
                    None,
                    &mut w.cg,
                );
                report.cg_iterations += outcome.iterations;
                report.phases.solve += ms_since(t);
            }
        }
        if cfg.measure_residual {
            let r = global::relative_residual(
                &self.pattern,
                values,
                &w.solution,
                &w.rhs,
                &mut w.scratch,
            );
            report.linear_residual = Some(report.linear_residual.map_or(r, |m| m.max(r)));
        }
        for (v, p) in next.iter_mut().enumerate() {
            *p = DVec2::new(w.solution[v], w.solution[n + v]);
        }
        Ok(())
    }
}

impl Solver {
    /// The least-squares global step (unit weights) by Cholesky, with the right-hand side
    /// gathered into and solved in the factor's order
    /// ([`SymbolicFactor::solve_in_factor_order`]): the same numbers as the general path,
    /// without its column copies.
    fn solve_least_squares_ordered(
        &mut self,
        f: &[DVec2],
        next: &mut [DVec2],
        report: &mut FrameReport,
    ) -> Result<(), SolverError> {
        let cfg = self.config;
        let t = Instant::now();
        let w = &mut self.work;
        let slot = &self.factor_slot;
        let (lambda, mu) = (cfg.handle_weight, cfg.proximal_weight);
        self.ordered.resize(f.len(), [0.0; 2]);
        // Summed in vertex order (where an edge's ends are near each other; the factor's
        // order scatters them), then gathered into the factor's order. Sized first and then
        // written: a push per vertex would check the capacity every time.
        let n = f.len();
        let b = &mut w.vertex_rhs;
        w.diagonal.resize(n, 0.0);
        b.resize(n, DVec2::ZERO);
        let handles = w.handle_count.iter().zip(&w.handle_sum).zip(f);
        for ((d, bi), ((&count, &sum), &p)) in w.diagonal.iter_mut().zip(b.iter_mut()).zip(handles)
        {
            *d = lambda * count + mu;
            *bi = lambda * sum + mu * p;
        }
        for (&[x, y], &t) in self.pattern.ends.iter().zip(&w.targets) {
            let (x, y) = (x as usize, y as usize);
            if x != y {
                b[x] += t;
                b[y] -= t;
            }
        }
        let x = &mut self.ordered;
        let order = self.symbolic.as_ref().and_then(|s| s.factor_order());
        for (xi, &v) in x.iter_mut().zip(order.unwrap_or_default()) {
            *xi = b[v].to_array();
        }
        refresh_least_squares(&self.pattern, w, &mut self.l2_factor);
        report.phases.assembly += ms_since(t);
        let Some(symbolic) = self.symbolic.as_mut() else {
            return Err(SolverError("no symbolic factorisation".into()));
        };
        if !self.l2_factor.is_valid() {
            let t = Instant::now();
            symbolic
                .factorize(
                    &mut self.l2_factor,
                    &self.pattern.col_ptr,
                    &self.pattern.row_idx,
                    &w.l2_values,
                )
                .map_err(|e| SolverError(e.0))?;
            report.factorizations += 1;
            report.phases.factorization += ms_since(t);
        }
        let t = Instant::now();
        if !symbolic.solve_in_factor_order(&self.l2_factor, x) {
            return Err(SolverError("the factor has no supernodal order".into()));
        }
        report.phases.solve += ms_since(t);
        for (p, &i) in next.iter_mut().zip(slot) {
            *p = DVec2::from(x[i]);
        }
        if cfg.measure_residual {
            // the general path's columns, only to measure (tests)
            let columns = |v: &[DVec2], out: &mut Vec<f64>| {
                out.clear();
                out.extend(v.iter().map(|p| p.x));
                out.extend(v.iter().map(|p| p.y));
            };
            columns(&w.vertex_rhs, &mut w.rhs);
            columns(next, &mut w.solution);
            let r = global::relative_residual(
                &self.pattern,
                &w.l2_values,
                &w.solution,
                &w.rhs,
                &mut w.scratch,
            );
            report.linear_residual = Some(report.linear_residual.map_or(r, |m| m.max(r)));
        }
        Ok(())
    }
}

/// Brings the least-squares matrix up to date with `w.diagonal`: its values depend only on
/// the handles' vertices, so they, and the factor, are kept while the diagonal stays the same;
/// otherwise refilled, and the factor marked for refactorisation.
fn refresh_least_squares(pattern: &Pattern, w: &mut Work, factor: &mut NumericFactor) {
    if w.l2_diagonal == w.diagonal && !w.l2_values.is_empty() {
        return;
    }
    if w.ones.len() != pattern.edges.len() {
        w.ones.clear();
        w.ones.resize(pattern.edges.len(), 1.0);
    }
    pattern.fill_values(&w.ones, &w.diagonal, &mut w.l2_values);
    w.l2_diagonal.clone_from(&w.diagonal);
    factor.invalidate();
}

/// Splitting iterations a budgeted frame always runs (when configured to run that many).
const MIN_SPLIT_ITERATIONS: usize = 2;

/// Where a splitting pass 1 starts from.
struct SplitStart<'a> {
    /// The displayed pose.
    warm: &'a [DVec2],
    /// Whether the displayed pose is the one this solver last produced (so the splitting
    /// variables may continue).
    carry: bool,
    /// Whether, besides, the work buffers still hold that pose's rotations and edge targets
    /// for the current states.
    carried: bool,
    step_tolerance: f64,
    deadline: Option<Instant>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Pass {
    Irls,
    LeastSquares,
}

#[derive(Clone, Copy, Debug)]
struct Terms {
    elastic: f64,
    handle: f64,
}

impl Terms {
    fn total(self) -> f64 {
        self.elastic + self.handle
    }
}

/// Pass-2 objective terms at `f` for the given edge targets.
fn terms(
    edges: &[global::EdgeSlot],
    targets: &[DVec2],
    handles: &[Handle],
    f: &[DVec2],
    handle_weight: f64,
) -> Terms {
    let mut elastic = 0.0;
    for (e, &t) in edges.iter().zip(targets) {
        elastic += (t - (f[e.x] - f[e.y])).length_squared();
    }
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
    Terms {
        elastic,
        handle: handle_weight * handle,
    }
}

/// Per column, the norm of the right-hand side's edge terms (without the handle and proximal
/// terms in `extra`). CG measures its residual against this: the handle rows, a million times
/// stiffer, would otherwise let a solve stop with the elastic rows far from balanced.
fn elastic_norm(rhs: &[f64], extra: &[DVec2]) -> [f64; 2] {
    let n = extra.len();
    let (mut sx, mut sy) = (0.0, 0.0);
    for (i, e) in extra.iter().enumerate() {
        sx += (rhs[i] - e.x).powi(2);
        sy += (rhs[n + i] - e.y).powi(2);
    }
    [sx.sqrt(), sy.sqrt()]
}

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

fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

fn mean_or_one(values: &[f64]) -> f64 {
    if values.is_empty() {
        return 1.0;
    }
    let m = values.iter().sum::<f64>() / values.len() as f64;
    if m.is_finite() && m > 0.0 { m } else { 1.0 }
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

/// Length of the diagonal of the positions' bounding box (0 for no or non-finite positions).
pub fn bbox_diagonal(positions: &[DVec2]) -> f64 {
    match bbox(positions) {
        Some((lo, hi)) => (hi - lo).length(),
        None => 0.0,
    }
}

/// Bounding box `(min, max)` of the positions, `None` when there are none.
pub fn bbox(positions: &[DVec2]) -> Option<(DVec2, DVec2)> {
    let first = *positions.first()?;
    Some(
        positions
            .iter()
            .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))),
    )
}

/// Piece parts carry their active state to their instance (that is the replacement rule).
fn sync_instance_states(asm: &mut Assembly) {
    let data = &mut asm.data;
    for part in &data.parts {
        if let PartKind::Piece { instance } = part.kind
            && let Some(inst) = data.instances.get_mut(instance)
        {
            inst.state = part.active;
        }
    }
}

/// Elastic energy (Eq. 4, unit weights) of the assembly's current positions and active states,
/// with each part's rotation fitted to the current pose.
pub fn elastic_energy(asm: &Assembly, config: &SolverConfig) -> f64 {
    let parts = &asm.data.parts;
    let f = &asm.data.positions;
    let rotations: Vec<DVec2> = parts.iter().map(|p| local::part_rotation(p, f)).collect();
    let vertex_parts = local::VertexParts::build(parts, f.len());
    let cos_cone = cone_cosine(config.rotation_cone_degrees);
    let mut energy = 0.0;
    for (pi, part) in parts.iter().enumerate() {
        let Some(rest) = part.states.get(part.active) else {
            continue;
        };
        for e in &part.edges {
            let (x, y) = (part.vertices[e[0]], part.vertices[e[1]]);
            let d0 = rest.positions[e[0]] - rest.positions[e[1]];
            let r = local::edge_rotation(&vertex_parts, &rotations, x, y, pi, cos_cone);
            energy += (r.rotate(d0) - (f[x] - f[y])).length_squared();
        }
    }
    energy
}

fn cone_cosine(degrees: f64) -> f64 {
    if degrees >= 180.0 {
        -1.0
    } else {
        degrees.max(0.0).to_radians().cos()
    }
}

/// Largest `|length / rest length - 1|` over the edges of every part's active state (edges
/// of zero rest length are skipped).
pub fn max_edge_strain(asm: &Assembly) -> f64 {
    edge_strains(asm).into_iter().fold(0.0, f64::max)
}

/// `length / rest length - 1` (signed) of every edge of every part's active state, part by
/// part; edges of zero rest length are skipped.
pub fn edge_strains(asm: &Assembly) -> Vec<f64> {
    let f = &asm.data.positions;
    let mut out = Vec::new();
    for part in &asm.data.parts {
        let Some(rest) = part.states.get(part.active) else {
            continue;
        };
        for e in &part.edges {
            let rest_len = (rest.positions[e[0]] - rest.positions[e[1]]).length();
            if rest_len > 1e-12 {
                let len = (f[part.vertices[e[0]]] - f[part.vertices[e[1]]]).length();
                out.push(len / rest_len - 1.0);
            }
        }
    }
    out
}
