//! What one solver frame reports: iterations, energies, state switches, convergence and the
//! time spent per phase; what its relaxation proposes; and the solver's error.

use glam::DVec2;

/// A part's active rest state changed during a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StateSwitch {
    pub part: usize,
    pub from: usize,
    pub to: usize,
    /// What decided it.
    pub judged: Judged,
}

/// What decided a [`StateSwitch`]: what the rule log says of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Judged {
    /// The local step's choice, by shape.
    Shape,
    /// A try of other states, by energy (`docs/solver.md`, "A held model that stops strained
    /// tries other states"): the model's energy without the switch and with it, settled
    /// alike.
    Energy([f64; 2]),
    /// A relaxation's proposal, by energies its caller states (the session's
    /// `try_proposals`, which adds them to the events it keeps).
    Proposal,
}

/// What one frame did.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct FrameReport {
    /// Pass-1 (IRLS) iterations run.
    pub pass1_iterations: usize,
    /// Least-squares (pass 2) iterations run.
    pub l2_iterations: usize,
    /// Pass-2 elastic energy (Eq. 4 with the final states and rotations), handles excluded.
    pub energy: f64,
    /// Pass-2 objective: `energy` plus the handle terms.
    pub objective: f64,
    /// The pass-2 objective of the warm start (the previous frame's positions moved by rigid
    /// following, with this frame's handle targets and final states); with pass-2
    /// iterations, `objective <= warm_objective` (local and global steps never raise it).
    pub warm_objective: f64,
    /// Rest-state switches, in the order they happened.
    pub switches: Vec<StateSwitch>,
    /// `(part, elements)` for every stretch part pass 1 left in `three` or `one`: how many
    /// elements its two span in the pass-1 pose (at least 3 in `three`: the stretch rule
    /// inserts the difference; 1 or fewer in `one`: the shrink rule removes the difference).
    pub claims: Vec<(usize, i32)>,
    /// Wall time of the frame in milliseconds.
    pub ms: f64,
    /// The frame left the model at rest: the frame was complete, no rest state switched, and
    /// the displayed positions moved less than [`SolverConfig::settle_tolerance`](super::SolverConfig::settle_tolerance) times
    /// their components' sizes (or both passes stopped on their step tolerance). Running another frame
    /// with the same handles would change nothing visible, so a caller can stop solving.
    pub converged: bool,
    /// The frame ran the iterations its passes asked for; `false` when
    /// [`Solver::frame_budgeted`](super::Solver::frame_budgeted) cut it short to meet its time budget (the displayed
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
    /// [`SolverConfig::measure_residual`](super::SolverConfig::measure_residual) is set.
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
    /// The rest of the frame: handle targets, the warm start and rigid following, free
    /// components' centroids, the displayed pose's copies.
    pub bookkeeping: f64,
}

/// What the relaxation proposes: per chain whose relaxed length calls for another count, the
/// count and the part where the chain changes; per piece part whose relaxed bend is nearer
/// another rest state, that state; and the relaxed pose, where the rules lay the change out.
#[derive(Clone, Debug, PartialEq)]
pub struct Proposal {
    pub pose: Vec<DVec2>,
    /// `(chain, first, count)`: the chain gets `count` elements, changed at its stretch part
    /// over elements `first` and `first + 1`.
    pub counts: Vec<(usize, usize, usize)>,
    /// `(part, state)`.
    pub states: Vec<(usize, usize)>,
    /// Whether it is judged with the lengths it then asks for ([`Solver::relaxed_after`]):
    /// a count a chain's turn asks for (`turns.rs`) moves the pieces at its ends, and the
    /// straight chains between them rest only at other counts too.
    ///
    /// [`Solver::relaxed_after`]: super::Solver::relaxed_after
    pub then_lengths: bool,
}

impl Proposal {
    /// Whether it changes nothing.
    pub fn is_empty(&self) -> bool {
        self.counts.is_empty() && self.states.is_empty()
    }
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
