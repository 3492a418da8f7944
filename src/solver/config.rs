//! The solver's settings: which linear solver, iteration counts and
//! tolerances, hysteresis and the norm exponent, taken from a grammar's `solver` block.

use clay_dsl::compiled::SolverParams;

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

/// Solver parameters. The first four mirror the grammar's [`SolverParams`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverConfig {
    pub kind: SolverKind,
    /// A part switches to a nearer rest state only when `d_new < (1 - hysteresis) d_active`.
    pub hysteresis: f64,
    /// Exponent p of pass 1's sub-quadratic norm (2 = least squares).
    pub norm: f64,
    /// Pass 1 (paper 5.2: "the constraint handles are considered as outliers"): a stretch
    /// part that holds a held vertex weighs `handle_outlier^(2 - p)` in the sparse norm
    /// (least squares, p = 2, is unchanged). An evenly stretched chain is a stationary point
    /// of the sparse norm, equally far from gathering its stretch into any one part; next to
    /// the handles a gap is cheaper, so that is where it opens.
    pub handle_outlier: f64,
    /// A chain whose last change of element count went one way changes the other way only
    /// once its length is off by this many elements (a stretch after a shrink: longer than
    /// its elements at rest by this much; a shrink after a stretch: shorter). The sparse norm
    /// gathers a chain's whole leftover length into one part, where the hysteresis of paper
    /// 4.3 switches at about half an element, so right after a switch the chain is within a
    /// few hundredths of an element of switching back; a hand that wavers by a third of an
    /// element would add and remove an element every time (`docs/solver.md`).
    pub reversal: f64,
    /// Epsilon in the IRLS weight `1 / (|r| + eps)^(2 - p)`.
    pub irls_epsilon: f64,
    /// Pass 1: most IRLS iterations per frame; each is a local step, one weight per part,
    /// and a global step with a fresh numeric factorisation. Five pass every claim of both
    /// claims suites (300 generated cases of each property; four fail two of them); a large
    /// model seldom converges to the tolerance below in a frame of a brisk drag (the
    /// 10,000-part city took 19 iterations a frame with 20 allowed), and the next frame starts
    /// where this one left the displayed pose (`docs/solver.md`).
    pub irls_iterations: usize,
    /// Most least-squares (pass 2) iterations per frame.
    pub l2_iterations: usize,
    /// Most pass-2 iterations per frame while nothing is held: a model let go relaxes along
    /// its softest modes (a long, thin chain unbending), which least squares crosses slowly;
    /// with 5 a frame, a buckled chain of 113 thin bricks took 600 frames to come to rest, with
    /// 20 under 200 (`docs/solver.md`).
    pub l2_iterations_free: usize,
    /// Pass 2: how many past iterates Anderson acceleration mixes (0: the plain local/global
    /// iteration); an accelerated iterate that does not lower the objective is dropped.
    pub l2_anderson: usize,
    /// Handle weight relative to the mean edge weight of the handle's connected component
    /// (Eq. 3): large, so handles are hard.
    pub handle_weight: f64,
    /// Proximal weight `mu` (relative to the component's mean edge weight) pulling every vertex towards the
    /// current iterate; keeps components without handles well-posed.
    pub proximal_weight: f64,
    /// Parts whose rotations differ by more than this many degrees do not average into each
    /// other's `R_xy` (pieces at a corner sit in different frames even at rest). 180 gives the
    /// paper's plain average, 0 (the default) each part's own rotation: see `docs/solver.md`
    /// for why (a cone makes the energy jump when a part crosses it).
    pub rotation_cone_degrees: f64,
    /// Pass 2 stops early once no vertex moved more than this fraction of its connected
    /// component's size (the diagonal of its bounding box).
    pub tolerance: f64,
    /// Pass 1 stops early once no vertex moved more than this fraction of its connected
    /// component's mean rest edge and no state switched (from its second iteration on). Pass 1
    /// only decides the rest states, so its pose need not be as exact as the displayed one.
    /// Relative to the parts, not to the model's size, and each component to its own: a claim
    /// must not depend on how large the rest of the model is (with 1e-3 of the size, a
    /// 50-brick wall stopped at its evenly stretched pose, 5 cm steps being converged; with
    /// the model's mean edge, a chain of long elements 700 m away kept a wall a brick longer).
    pub pass1_tolerance: f64,
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
    /// A frame counts as converged ([`FrameReport::converged`](super::FrameReport::converged)) when no state switched and the
    /// displayed positions moved less than this fraction of their components' sizes.
    pub settle_tolerance: f64,
    /// Compute the relative residual of every linear solve into the report (one extra matrix
    /// product per solve).
    pub measure_residual: bool,
    /// Threads of the local step (0: every core). The results are the same bit for bit
    /// whatever the count (`solver/chunks.rs`); models under a few thousand parts use one.
    pub threads: usize,
}

impl Default for SolverConfig {
    fn default() -> Self {
        Self::from_params(&SolverParams::default())
    }
}

impl SolverConfig {
    /// The defaults with the grammar's parameters.
    /// A grammar's `solver` block, the session-only settings at the defaults of the one
    /// table (`clay_dsl::settings`).
    pub fn from_params(params: &SolverParams) -> Self {
        let default = |name| clay_dsl::settings::setting(name).map_or(0.0, |s| s.default.number());
        Self {
            kind: SolverKind::Cholesky,
            hysteresis: params.hysteresis,
            norm: params.norm,
            irls_epsilon: params.irls_epsilon,
            handle_outlier: 0.5,
            reversal: 0.95,
            irls_iterations: default("irls_iterations") as usize,
            l2_iterations: default("l2_iterations") as usize,
            l2_iterations_free: 20,
            l2_anderson: default("l2_anderson") as usize,
            handle_weight: default("handle_weight"),
            rotation_cone_degrees: 0.0,
            proximal_weight: 1e-8,
            tolerance: 1e-6,
            pass1_tolerance: 1e-3,
            cg_tolerance: 1e-6,
            cg_max_iterations: 20_000,
            pcg_max_iterations: 0,
            pcg_tolerance: 1e-6,
            settle_tolerance: 1e-6,
            measure_residual: false,
            threads: 0,
        }
    }
}

impl SolverConfig {
    /// The threads the local step runs on ([`SolverConfig::threads`], 0 resolved to the
    /// machine's cores, asked once).
    pub fn thread_count(&self) -> usize {
        static CORES: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
        match self.threads {
            0 => *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
            t => t,
        }
    }
}

/// The cosine of a cone half-angle in degrees (180 and above: every direction).
pub(crate) fn cone_cosine(degrees: f64) -> f64 {
    if degrees >= 180.0 {
        -1.0
    } else {
        degrees.max(0.0).to_radians().cos()
    }
}
