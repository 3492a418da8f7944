//! The solver's state between frames: [`Solver`] (the settings, the sparsity pattern and
//! its factors, the connected components and their units) and [`Work`], the buffers sized
//! once per assembly generation and reused every frame, with [`Solver::prepare`], which
//! rebuilds them when the assembly's structure changes.
//!
//! Every job of a frame is a sibling module with its own `impl Solver` block (`pass1.rs`,
//! `pass2.rs`, `global_step.rs`, ...) that imports the state from here, and `mod.rs` runs
//! them in order. The state lives in its own file so that those children share it as
//! siblings: none imports its parent. Its fields are `pub(super)`, the solver's own.

use clay_dsl::compiled::{Part, PartKind};
use glam::DVec2;

use super::cholesky::{NumericFactor, SymbolicFactor};
use super::config::{SolverConfig, SolverKind};
use super::global::Pattern;
use super::growth::ChainLength;
use super::report::SolverError;
use super::{anderson, cg, follow, local, measure, rest_cache, units};
use crate::assembly::Assembly;

/// The solver for one live assembly. Keeps the sparsity pattern, the symbolic factorisation
/// and all buffers between frames; rebuilds them when the assembly's generation changes.
#[derive(Debug)]
pub struct Solver {
    pub config: SolverConfig,
    pub(super) generation: Option<u64>,
    pub(super) pattern: Pattern,
    pub(super) symbolic: Option<SymbolicFactor>,
    pub(super) irls_factor: NumericFactor,
    pub(super) l2_factor: NumericFactor,
    pub(super) work: Work,
    /// The last frame's pass-1 pose.
    pub(super) pass1_pose: Vec<DVec2>,
    /// The connected components of the vertex graph (rigid following, free centroids).
    pub(super) components: follow::Components,
    /// Each component's units of length: its mean rest edge in the active states when the
    /// generation was prepared (pass 1's tolerance, the rest test of
    /// [`Solver::try_states`]) and its size this frame (pass 2's).
    pub(super) units: units::Units,
    /// The components with no held vertex this frame, ascending (solves shift their
    /// centroids back).
    pub(super) free_components: Vec<usize>,
    /// Pass 2's mixing history ([`SolverConfig::l2_anderson`]).
    pub(super) anderson: anderson::Anderson,
    /// Per vertex, its row in the factor's fill-reducing order (the inverse of
    /// [`SymbolicFactor::factor_order`]; empty when the factor has no such order): the
    /// least-squares solve reads its solution from there.
    pub(super) factor_slot: Vec<usize>,
    /// The least-squares right-hand side and solution, `(x, y)` per row in factor order.
    pub(super) ordered: Vec<[f64; 2]>,
    /// The last relaxation's proposals and the generation they were made for (`relax.rs`).
    pub(super) proposals: Option<(u64, Vec<super::report::Proposal>)>,
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
            pass1_pose: Vec::new(),
            components: follow::Components::default(),
            free_components: Vec::new(),
            units: units::Units::default(),
            anderson: anderson::Anderson::default(),
            factor_slot: Vec::new(),
            ordered: Vec::new(),
            proposals: None,
        }
    }

    /// Rebuilds the pattern and symbolic factorisation if the assembly changed structurally.
    pub(super) fn prepare(&mut self, asm: &Assembly) -> Result<(), SolverError> {
        let n = asm.data().positions.len();
        let edge_count: usize = asm.data().parts.iter().map(|p| p.edges.len()).sum();
        let stale = self.generation != Some(asm.generation())
            || self.pattern.n != n
            || self.pattern.edges.len() != edge_count
            || self
                .work
                .rest
                .as_ref()
                .is_some_and(|c| c.parts() != asm.data().parts.len());
        if !stale {
            return Ok(());
        }
        // the pattern and the rest cache keep vertex and part indices as u32
        if u32::try_from(n).is_err() {
            return Err(SolverError(format!(
                "the model has {n} vertices, more than the solver can index"
            )));
        }
        let part_count = asm.data().parts.len();
        if u32::try_from(part_count).is_err() {
            return Err(SolverError(format!(
                "the model has {part_count} parts, more than the solver can index"
            )));
        }
        for (i, p) in asm.data().parts.iter().enumerate() {
            let m = p.vertices.len();
            if p.vertices.iter().any(|&v| v >= n) || p.edges.iter().any(|e| e[0] >= m || e[1] >= m)
            {
                return Err(SolverError(format!(
                    "part {i} refers to a vertex that does not exist"
                )));
            }
        }
        self.pattern = Pattern::build(n, &asm.data().parts);
        self.work.vertex_parts = local::VertexParts::build(&asm.data().parts, n);
        self.work.rest = rest_cache::RestCache::build(&asm.data().parts, &self.work.vertex_parts);
        self.components = follow::Components::build(&asm.data().parts, n);
        self.units = units::Units::build(&asm.data().parts, &self.components);
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
        // a model loaded or rebuilt at rest rested there: a small move of the handles
        // from it is elastic
        if !self.strained(measure::elastic_energy(asm, &self.config)) {
            self.work.rested = Some(Rested::of(asm, self.work.rested.as_ref()));
        }
        self.work.tried = false;
        self.work.kept_by_trial.clear();
        Ok(())
    }
}

/// Buffers sized once per generation and reused every frame.
#[derive(Debug, Default)]
pub(super) struct Work {
    pub(super) rotations: Vec<DVec2>,
    pub(super) vertex_parts: local::VertexParts,
    /// The parts' rest data flattened for the local step (rebuilt with the generation);
    /// `None` when it could not be built, and the local step then reads the parts directly.
    pub(super) rest: Option<rest_cache::RestCache>,
    /// Per part-edge: `R_xy (x0 - y0)`.
    pub(super) targets: Vec<DVec2>,
    /// Per part: its IRLS weight (pass 1), for all its edges.
    pub(super) weights: Vec<f64>,
    /// Per vertex: number of handle targets, and their sum.
    pub(super) handle_count: Vec<f64>,
    pub(super) handle_sum: Vec<DVec2>,
    pub(super) diagonal: Vec<f64>,
    pub(super) extra: Vec<DVec2>,
    pub(super) values: Vec<f64>,
    pub(super) l2_values: Vec<f64>,
    pub(super) l2_diagonal: Vec<f64>,
    pub(super) rhs: Vec<f64>,
    /// The least-squares right-hand side, one `(x, y)` per vertex in vertex order.
    pub(super) vertex_rhs: Vec<DVec2>,
    pub(super) solution: Vec<f64>,
    pub(super) scratch: Vec<f64>,
    pub(super) cg: cg::CgWork,
    pub(super) part_sums: Vec<DVec2>,
    /// The displayed pose at the start of the frame (then moved by rigid following).
    pub(super) warm: Vec<DVec2>,
    /// Rotations and edge targets of the kept pass-2 iterate while the next one is judged,
    /// and between steps those of [`Start`].
    pub(super) kept_rotations: Vec<DVec2>,
    pub(super) kept_targets: Vec<DVec2>,
    /// The positions the last frame displayed (pass 1 continues only from them).
    pub(super) shown: Vec<DVec2>,
    pub(super) next: Vec<DVec2>,
    /// The local step already evaluated at the pose pass 2 starts from (see [`Start`]).
    pub(super) start: Start,
    /// Per part: the state the last local step chose, and its squared stacked residual.
    pub(super) chosen: Vec<usize>,
    pub(super) residuals: Vec<f64>,
    /// Per part: the factor of its term in the sparse norm (the handles as outliers:
    /// [`SolverConfig::handle_outlier`]).
    pub(super) outlier: Vec<f64>,
    /// Per part: a stretch part's context for this frame's switching steps.
    pub(super) stretch: Vec<Option<local::StretchContext>>,
    /// Per part: the claim of the last local step, and of pass 1's last switching step.
    pub(super) claims: Vec<i32>,
    pub(super) pass1_claims: Vec<i32>,
    /// Per chain: its lengths where pass 1 starts (`None`: not measured).
    pub(super) chain_lengths: Vec<Option<ChainLength>>,
    /// How far the handles moved the held vertices at the frame's start.
    pub(super) snapped_moved: f64,
    /// The handle targets (`handle_sum`) of the last frame: still when equal.
    pub(super) last_targets: Vec<DVec2>,
    /// How far the last frame moved the displayed pose, in its components' rest edges
    /// ([`units::Units::max_move_in_edges`]).
    pub(super) last_moved: f64,
    /// The elastic energy the last frame ended with, and the one before it.
    pub(super) last_energy: [f64; 2],
    /// Other rest states were tried since the handles, the states or the structure last
    /// changed, and none helped ([`Solver::try_states`]).
    pub(super) tried: bool,
    /// The parts whose states a try switched (by energy) since the handles or the structure
    /// last changed: pass 1 (by shape) does not switch them back meanwhile.
    pub(super) kept_by_trial: Vec<usize>,
    /// Where the model last rested: what a small move is measured from ([`Rested`]).
    pub(super) rested: Option<Rested>,
}

/// A pose the model rested in: its structure (the assembly's generation), its parts'
/// states and its vertices' positions. While the structure and states are these, handles
/// whose targets are less than the hysteresis in elements from these positions are answered
/// elastically: neither a try nor the relaxation runs (`trials.rs`, `Solver::moved_little`).
#[derive(Debug)]
pub(super) struct Rested {
    pub(super) generation: u64,
    pub(super) states: Vec<usize>,
    pub(super) pose: Vec<DVec2>,
    /// Its shortest element's length (metres): what a small move is measured in.
    pub(super) shortest: f64,
}

impl Rested {
    /// `asm` as it is; its shortest element as `before` measured it, for the same structure.
    pub(super) fn of(asm: &Assembly, before: Option<&Rested>) -> Self {
        let shortest = match before {
            Some(r) if r.generation == asm.generation() => r.shortest,
            _ => shortest_element(asm),
        };
        Self {
            generation: asm.generation(),
            states: asm.data().parts.iter().map(|p| p.active).collect(),
            pose: asm.data().positions.clone(),
            shortest,
        }
    }
}

/// The evaluation of the pose pass 2 starts from (the displayed pose after rigid following),
/// when a step already computed it: the first IRLS iteration of this frame (it evaluates that
/// pose, and its rotations are those of the states it chose), or the last accepted pass-2
/// iterate of the previous frame (the pose displayed since). Pass 2 takes it instead of
/// evaluating the same pose again; it is the same numbers bit for bit, since the local step
/// depends only on the pose, the active states and the settings. Its rotations and targets
/// are kept in `Work::kept_rotations` and `Work::kept_targets` (pass 2's scratch, unused
/// until then).
#[derive(Debug, Default)]
pub(super) struct Start {
    pub(super) elastic: f64,
    /// Valid for this assembly generation and settings while exactly this many state
    /// switches have been reported in the frame (a later switch changes the rest edges).
    pub(super) valid: Option<(u64, SolverConfig, usize)>,
}

impl Work {
    /// Keeps the accepted pass-2 iterate's evaluation (in `rotations` and `targets`, with
    /// energy `elastic`) as the next frame's [`Start`]: valid while that pose stays shown and
    /// the parts keep their active states (noted in `chosen`: `Assembly::set_active_state`
    /// changes them without a new generation).
    pub(super) fn keep_start(
        &mut self,
        cfg: SolverConfig,
        generation: u64,
        parts: &[Part],
        elastic: f64,
    ) {
        if cfg.l2_iterations > 0 && self.rotations.len() == parts.len() {
            std::mem::swap(&mut self.kept_rotations, &mut self.rotations);
            std::mem::swap(&mut self.kept_targets, &mut self.targets);
            self.chosen.clear();
            self.chosen.extend(parts.iter().map(|p| p.active));
            self.start.elastic = elastic;
            self.start.valid = Some((generation, cfg, 0));
        } else {
            self.start.valid = None;
        }
    }

    /// Whether the last frame's [`Start`] holds for this one: kept under `key`, for the pose
    /// `warm` (the one it showed) and the parts' active states.
    pub(super) fn start_holds(
        &self,
        key: Option<(u64, SolverConfig, usize)>,
        warm: &[DVec2],
        parts: &[Part],
    ) -> bool {
        let states = || {
            self.chosen.len() == parts.len()
                && parts.iter().zip(&self.chosen).all(|(p, &c)| p.active == c)
        };
        self.start.valid == key && self.shown == warm && states()
    }
}

/// The shortest element's length (metres) of `asm`: a stretch part's element, or a piece
/// with alternative states, from its first site to its second (0 when it has neither). An
/// element that turns (an arc's) measures its chord: read only where it stretches straight,
/// an arc's elements were left out, and a far chain of 16 m elements made a 1 m pull of an
/// arc of 0.87 m elements a small move (`far_pieces_change_nothing_in_an_assembly`).
fn shortest_element(asm: &Assembly) -> f64 {
    let grammar = asm.grammar();
    let data = asm.data();
    // from the piece's first site's centre to its second's, at rest
    let chord = |piece: usize, [a, b]: [usize; 2]| -> Option<f64> {
        let piece = grammar.pieces.get(piece)?;
        let rest = &piece.states.first()?.positions;
        let centre = |site: usize| -> Option<DVec2> {
            let vs = &piece.sites.get(site)?.vertices;
            let sum = vs
                .iter()
                .map(|&v| rest.get(v).copied())
                .sum::<Option<DVec2>>()?;
            Some(sum / vs.len().max(1) as f64)
        };
        Some(centre(a)?.distance(centre(b)?))
    };
    let length = |part: &Part| -> Option<f64> {
        match part.kind {
            PartKind::Stretch { chain, .. } => {
                let rule = grammar.stretch_rules.get(data.chains.get(chain)?.rule)?;
                chord(rule.piece, [rule.from, rule.to])
            }
            PartKind::Piece { instance } if part.states.len() > 1 => {
                chord(data.instances.get(instance)?.piece, [0, 1])
            }
            PartKind::Piece { .. } => None,
        }
    };
    let shortest = (data.parts.iter())
        .filter_map(length)
        .filter(|l| l.is_finite() && *l > 0.0)
        .fold(f64::INFINITY, f64::min);
    if shortest.is_finite() { shortest } else { 0.0 }
}
