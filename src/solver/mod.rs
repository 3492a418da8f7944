//! The mutable elastic solver (paper 4.1-4.3, 5.2): one frame of alternating local steps
//! (rotations and rest-state choice with hysteresis) and global steps (a sparse linear solve),
//! warm-started from the previous positions. Pass 1 reweights edges for the sub-quadratic
//! norm (IRLS) and decides the active rest states; pass 2 is plain least squares with the
//! states fixed, and its positions are what the user sees.

mod anderson;
mod cg;
mod cholesky;
mod chunks;
mod clock;
mod config;
mod evaluate;
pub mod follow;
mod global;
mod global_step;
mod growth;
mod layout;
pub(crate) mod local;
mod measure;
mod pass1;
mod pass2;
mod report;
mod rest_cache;
mod state;
mod units;

pub use config::{SolverConfig, SolverKind};
pub use measure::{
    bbox, bbox_diagonal, edge_strain, edge_strains, elastic_energy, max_edge_strain,
};
pub use report::{FrameReport, PhaseTimes, SolverError, StateSwitch};
pub use state::Solver;

use std::time::{Duration, Instant};

use clay_dsl::compiled::{Part, PartKind};
use glam::DVec2;

use crate::assembly::{Assembly, Handle, HandleKind};
use cholesky::SymbolicFactor;
use clock::{ms_since, out_of_time};
use global_step::Pass;
use growth::ChainLength;

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
        self.frame_within(asm, None, &mut |_, _, _| {})
    }

    /// Runs one frame with `between` called after pass 1 (paper 5.2: "after having
    /// determined the topology, we run a second optimization pass with the ordinary
    /// least-squares energy, the result of which will be displayed"): it gets the assembly, the
    /// frame's report so far (switches, claims) and the pass-1 pose, and may rewrite the
    /// assembly's structure (the stretch and shrink rules); pass 2 then runs on the rewritten
    /// assembly, from its positions, so what is displayed is the least-squares pose of the
    /// new structure. `deadline` as for [`Solver::frame_budgeted`] (`None`: no deadline).
    pub fn frame_with(
        &mut self,
        asm: &mut Assembly,
        deadline: Option<Instant>,
        between: &mut Between,
    ) -> Result<FrameReport, SolverError> {
        self.frame_within(asm, deadline, between)
    }

    /// Runs one frame that stops early once `budget` is (about to be) spent, for an editor
    /// that must draw at a fixed rate. It always runs the pass-1 iterations that decide states
    /// (two: the first only weighs the parts; fewer if the configuration asks for fewer) and
    /// ends with at least one least-squares solve, so the displayed positions are a
    /// proper least-squares pose of the current states even when cut short. A further
    /// iteration is started only if the previous one of its pass fits in the time left. When
    /// cut short, the report has `complete == false` and `converged == false`; call again next
    /// frame: the positions and active states carry the work over. A
    /// budget of `Duration::MAX` behaves like [`Solver::frame`].
    pub fn frame_budgeted(
        &mut self,
        asm: &mut Assembly,
        budget: Duration,
    ) -> Result<FrameReport, SolverError> {
        let deadline = Instant::now().checked_add(budget);
        self.frame_within(asm, deadline, &mut |_, _, _| {})
    }

    fn frame_within(
        &mut self,
        asm: &mut Assembly,
        deadline: Option<Instant>,
        between: &mut Between,
    ) -> Result<FrameReport, SolverError> {
        let start = Instant::now();
        let on_pool = self.frame_uses_pool(asm);
        let mut run = || {
            self.prepare(asm)?;
            self.frame_prepared(asm, deadline, start, between)
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

    /// [`Solver::frame_within`] after [`Solver::prepare`] (`start`: when the frame began).
    // Long because: the frame's steps in order, with the hand-over between its passes.
    fn frame_prepared(
        &mut self,
        asm: &mut Assembly,
        deadline: Option<Instant>,
        start: Instant,
        between: &mut Between,
    ) -> Result<FrameReport, SolverError> {
        let mut report = FrameReport {
            complete: true,
            ..FrameReport::default()
        };
        let n = asm.data().positions.len();
        if n == 0 || asm.data().parts.is_empty() {
            report.converged = true;
            report.ms = start.elapsed().as_secs_f64() * 1e3;
            return Ok(report);
        }
        let cfg = self.config;
        self.gather_handles(asm.handles(), n);
        self.components
            .free(&self.work.handle_count, &mut self.free_components);
        // Position buffers live in `work` between frames (taken here, put back at the end; an
        // error path just drops them and the next frame reallocates).
        let mut warm = std::mem::take(&mut self.work.warm);
        warm.clear();
        warm.extend_from_slice(&asm.data().positions);
        if warm.iter().any(|p| !p.is_finite()) {
            return Err(SolverError(
                "the warm start has non-finite positions".into(),
            ));
        }
        self.units.measure(&self.components, &warm);
        self.follow_handles(&mut warm, cfg.tolerance);
        let generation = self.generation.unwrap_or(u64::MAX);
        let start_key = Some((generation, cfg, 0));
        if !self.work.start_holds(start_key, &warm, &asm.data().parts) {
            self.work.start.valid = None;
        }
        // Pass 1 starts from the displayed least-squares pose with the held vertices where the
        // handles now put them, by either method: the gesture's new step is where the
        // deformation starts, so the sparse norm gathers it next to the handle that moved,
        // and elsewhere into the parts the least-squares pose already strains most
        // (`docs/solver.md`).
        let mut pose = std::mem::take(&mut self.pass1_pose);
        pose.clone_from(&warm);
        self.snap_held(&mut pose);
        if self.pass1_runs() {
            // the evaluation at the displayed pose: pass 2 starts there (`Start`), and its
            // rotations are the directions the stretch parts' lengths are measured along
            if self.work.start.valid.is_none() {
                self.start_at(&asm.data().parts, asm.handles(), &warm, start_key);
            }
            self.stretch_contexts(asm, &pose);
            self.outlier_factors(&asm.data().parts, asm.handles());
        }
        report.phases.bookkeeping += ms_since(start);
        let pass1 = self.pass1(&mut asm.data_mut().parts, &mut pose, deadline, &mut report);
        self.pass1_pose = pose;
        self.collect_claims(asm, &mut report);
        // a frame that fails leaves no evaluation to reuse (its states may have switched)
        self.work.start.valid.take_if(|_| pass1.is_err());
        let pass1_converged = pass1?;
        let settling = self.settling(&report, asm.handles().is_empty());
        self.work.last_targets.clone_from(&self.work.handle_sum);
        if settling && !out_of_time(deadline, Duration::ZERO) {
            let handles = asm.handles().to_vec();
            let parts = &mut asm.data_mut().parts;
            if let Some(laid) = self.try_states(parts, &handles, &warm, &mut report)? {
                warm.copy_from_slice(&laid);
            }
        }
        let t = Instant::now();
        let before = asm.generation();
        between(asm, &report, &self.pass1_pose);
        if asm.generation() != before {
            // the structure changed: pass 2 runs on the new one, from the rules' layout
            self.prepare(asm)?;
            let n = asm.data().positions.len();
            self.gather_handles(asm.handles(), n);
            self.components
                .free(&self.work.handle_count, &mut self.free_components);
            warm.clear();
            warm.extend_from_slice(&asm.data().positions);
            if warm.iter().any(|p| !p.is_finite()) {
                return Err(SolverError("a rule laid out non-finite positions".into()));
            }
            self.units.measure(&self.components, &warm);
            self.work.start.valid = None;
        }
        report.phases.bookkeeping += ms_since(t);
        let generation = self.generation.unwrap_or(u64::MAX);
        let pass2 = self.pass2(
            &asm.data().parts,
            asm.handles(),
            warm,
            cfg.tolerance,
            deadline,
            &mut report,
        );
        self.work.start.valid.take_if(|_| pass2.is_err());
        let (f, terms, pass2_converged) = pass2?;
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
        let trial_due = !self.work.tried && self.strained(terms.elastic);
        report.converged = report.complete
            && report.switches.is_empty()
            && !trial_due
            && (settled || (pass1_converged && pass2_converged));
        // the shown pose is kept; the one shown before is the next frame's warm-start buffer
        self.work.warm = std::mem::replace(&mut self.work.shown, f);
        report.phases.bookkeeping += ms_since(t);
        report.ms = start.elapsed().as_secs_f64() * 1e3;
        Ok(report)
    }

    /// Whether this frame tries other rest states ([`Solver::try_states`]): the handles
    /// stayed where they were and pass 1 switched nothing, the last frame left the displayed
    /// pose all but still and yet not at rest, and no try since the handles, the states or
    /// the structure last changed.
    fn settling(&mut self, report: &FrameReport, free: bool) -> bool {
        let w = &mut self.work;
        let still = w.last_targets == w.handle_sum && report.switches.is_empty();
        if !still {
            w.tried = false;
        }
        let stopped = w.last_moved <= 1e-3;
        // nothing held and the energy all but flat: a long, thin chain unbending, which
        // least squares would take hundreds of frames over (or a fold it never leaves)
        let [last, before] = w.last_energy;
        let creeping = free && last > CREEP * before;
        let untried = !w.tried;
        still && (stopped || creeping) && untried && self.strained(self.work.start.elastic)
    }

    /// Whether an elastic energy is not at rest: above a millionth of the mean rest edge
    /// squared (what [`Solver::try_states`] tries to lower).
    fn strained(&self, elastic: f64) -> bool {
        let edge = self.units.smallest_edge();
        elastic > 1e-6 * edge * edge
    }

    /// A held model that does not come to rest tries other rest states (a move): the few
    /// piece parts whose best alternative state is nearest (by its shape distance against
    /// the active one's) switch, and a part out of its first state hands that state to a
    /// neighbour of its piece (the sparse pass gathered a bend into the part next to the one
    /// the gesture bends). For each move, least squares and the other parts' state choices
    /// settle for a few iterations with the moved parts held in their states; the assignment
    /// with the lowest energy is kept when it is below `(1 - hysteresis)` times the energy
    /// without a move.
    fn try_states(
        &mut self,
        parts: &mut [Part],
        handles: &[Handle],
        warm: &[DVec2],
        report: &mut FrameReport,
    ) -> Result<Option<Vec<DVec2>>, SolverError> {
        const CANDIDATES: usize = 4;
        const ITERATIONS: usize = 3;
        // more parts out of their first state than this: no reverting moves (each is a settle)
        const REVERT_LIMIT: usize = 8;
        let hysteresis = self.config.hysteresis;
        let multi = |p: &Part| matches!(p.kind, PartKind::Piece { .. }) && p.states.len() >= 2;
        let mut singles: Vec<(f64, usize, usize)> = Vec::new();
        for (pi, part) in parts.iter().enumerate().filter(|(_, p)| multi(p)) {
            let d: Vec<f64> = (part.states.iter())
                .map(|st| crate::fit::align(&st.positions, &part.vertices, warm).distance)
                .collect();
            let here = d[part.active.min(d.len() - 1)];
            if here > 0.0 {
                for (j, &dj) in d.iter().enumerate().filter(|(j, _)| *j != part.active) {
                    singles.push((dj / here, pi, j));
                }
            }
        }
        singles.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut moves: Vec<Vec<(usize, usize)>> = singles
            .iter()
            .take(CANDIDATES)
            .map(|&(_, pi, j)| vec![(pi, j)])
            .collect();
        let vp = &self.work.vertex_parts;
        for (pi, part) in parts
            .iter()
            .enumerate()
            .filter(|(_, p)| multi(p) && p.active != 0)
        {
            let mut neighbours: Vec<usize> = (part.vertices.iter())
                .flat_map(|&v| vp.of(v).iter().copied())
                .filter(|&q| q != pi && multi(&parts[q]) && parts[q].active == 0)
                .filter(|&q| parts[q].states.len() == part.states.len())
                .collect();
            neighbours.sort_unstable();
            neighbours.dedup();
            for q in neighbours {
                moves.push(vec![(pi, 0), (q, part.active)]);
            }
        }
        // the bends gathered in the wrong parts (a pause on the way, say): all but one of
        // the parts out of their first state back in it, and all of them
        let bent: Vec<usize> = (0..parts.len())
            .filter(|&pi| multi(&parts[pi]) && parts[pi].active != 0)
            .collect();
        if (2..=REVERT_LIMIT).contains(&bent.len()) {
            for &keep in &bent {
                let revert = bent.iter().filter(|&&q| q != keep).map(|&q| (q, 0));
                moves.push(
                    std::iter::once((keep, parts[keep].active))
                        .chain(revert)
                        .collect(),
                );
            }
        }
        if (1..=REVERT_LIMIT).contains(&bent.len()) {
            moves.push(bent.iter().map(|&q| (q, 0)).collect());
        }
        let actives: Vec<usize> = parts.iter().map(|p| p.active).collect();
        let baseline = self.settle(parts, handles, warm, ITERATIONS, &actives, &[])?;
        let mut best: Option<(f64, Vec<usize>)> = None;
        for m in &moves {
            for (p, &a) in parts.iter_mut().zip(&actives) {
                p.active = a;
            }
            for &(pi, j) in m {
                parts[pi].active = j;
            }
            let forced: Vec<usize> = m.iter().map(|x| x.0).collect();
            let e = self.settle(parts, handles, warm, ITERATIONS, &actives, &forced)?;
            if e < (1.0 - hysteresis) * baseline && best.as_ref().is_none_or(|b| e < b.0) {
                best = Some((e, parts.iter().map(|p| p.active).collect()));
            }
        }
        // the same states from the rest layout: a fold the iteration cannot leave
        for (p, &a) in parts.iter_mut().zip(&actives) {
            p.active = a;
        }
        let w = &self.work;
        let laid = layout::rest_layout(
            parts,
            &w.vertex_parts,
            &self.components,
            warm,
            &w.handle_count,
            &w.handle_sum,
        );
        let mut unfolded = None;
        if laid.iter().all(|p| p.is_finite()) {
            let e = self.settle(parts, handles, &laid, ITERATIONS, &actives, &[])?;
            if e < (1.0 - hysteresis) * baseline && best.as_ref().is_none_or(|b| e < b.0) {
                best = Some((e, parts.iter().map(|p| p.active).collect()));
                unfolded = Some(laid);
            }
        }
        self.work.tried = best.is_none();
        let chosen = best.map_or(actives.clone(), |b| b.1);
        for (pi, (p, (&from, &to))) in parts
            .iter_mut()
            .zip(actives.iter().zip(&chosen))
            .enumerate()
        {
            p.active = to;
            if from != to {
                report.switches.push(StateSwitch { part: pi, from, to });
            }
        }
        self.work.start.valid = None;
        Ok(unfolded)
    }

    /// Settles a trial assignment from `warm`: `iterations` least-squares iterations in which
    /// the piece parts but `forced` choose their states (hysteresis; the stretch parts keep
    /// those in `keep`), then pass 2 with the states fixed, to convergence (at most
    /// [`SETTLE_ITERATIONS`], accelerated like every pass 2). Returns its objective.
    fn settle(
        &mut self,
        parts: &mut [Part],
        handles: &[Handle],
        warm: &[DVec2],
        iterations: usize,
        keep: &[usize],
        forced: &[usize],
    ) -> Result<f64, SolverError> {
        let mut f = warm.to_vec();
        let mut next = vec![DVec2::ZERO; f.len()];
        let shared = std::mem::take(&mut self.work.vertex_parts);
        let mut report = FrameReport::default();
        for _ in 0..iterations {
            let how = local::Switching {
                hysteresis: self.config.hysteresis,
                stretch: &[],
                shared: Some(&shared),
            };
            if self.cache_fits(parts.len()) {
                self.evaluate(parts, &f, chunks::Choice::Switch(how));
                for (i, p) in parts.iter_mut().enumerate() {
                    if forced.contains(&i) {
                        continue;
                    }
                    if matches!(p.kind, PartKind::Piece { .. }) {
                        p.active = self.work.chosen[i];
                    } else {
                        p.active = keep[i];
                    }
                }
            }
            self.evaluate_fixed(parts, &f);
            self.solve_global(&f, &mut next, Pass::LeastSquares, &mut report)?;
            std::mem::swap(&mut f, &mut next);
        }
        self.work.vertex_parts = shared;
        let cfg = self.config;
        self.config.l2_iterations = SETTLE_ITERATIONS;
        self.work.start.valid = None;
        // the sizes measured when the frame began (the same model, a pose near it)
        let settled = self.pass2(parts, handles, f, cfg.tolerance, None, &mut report);
        self.config = cfg;
        let (_, terms, _) = settled?;
        Ok(terms.total())
    }

    /// The claims of the stretch parts pass 1 left in `three` or `one`
    /// ([`FrameReport::claims`]). With a sub-L1 norm they are sized by their chains' lengths
    /// where pass 1 started (`work.chain_lengths`): the part's own claim says where the chain
    /// grows or shrinks, the chain's length (its elements' lengths summed along its
    /// direction) how many elements it gains or loses. The sparse pass gathers a fast
    /// gesture's change of length into one part only as far as its iterations got, and a part
    /// claiming too few would leave the rest to the displayed pose: a chain squeezed in one
    /// frame to a third of its length then buckles before the rules catch up. With p >= 1
    /// nothing gathers: a part claims one element (the paper's rule).
    fn collect_claims(&self, asm: &Assembly, report: &mut FrameReport) {
        use clay_dsl::compiled::{STRETCH_ONE, STRETCH_THREE};
        let parts = &asm.data().parts;
        let claims = &self.work.pass1_claims;
        let standing: Vec<(usize, usize, i32)> = (parts.iter().enumerate())
            .filter_map(|(pi, part)| {
                let PartKind::Stretch { chain, .. } = part.kind else {
                    return None;
                };
                let claim = claims.get(pi).copied();
                match part.active {
                    STRETCH_THREE => Some((pi, chain, claim.unwrap_or(3).max(3))),
                    STRETCH_ONE => Some((pi, chain, claim.unwrap_or(1).min(1))),
                    _ => None,
                }
            })
            .collect();
        if standing.is_empty() {
            return;
        }
        let lengths = &self.work.chain_lengths;
        // only a sub-L1 norm gathers: with p >= 1 every part holds a share of the chain's
        // change of length, and a part claims one element at a time (paper 5.2)
        let gathers = self.config.norm < 1.0;
        for (pi, chain, claim) in standing {
            let count = asm
                .data()
                .chains
                .get(chain)
                .map_or(0, |c| c.instances.len()) as f64;
            let length = lengths.get(chain).copied().flatten().filter(|_| gathers);
            let limit = f64::from(local::MAX_CLAIM);
            let claim = match length {
                // a chain grows by what its ends are apart beyond its elements, too: a slack
                // (buckled) chain pulled straightens before it stretches
                Some(l) if claim >= 3 && l.path.round() - count >= 1.0 => {
                    let grow = (l.path.round() - count).min((l.chord.round() - count).max(1.0));
                    2 + grow.min(limit) as i32
                }
                Some(l) if claim <= 1 && l.path.round() - count <= -1.0 => {
                    2 + (l.path.round() - count).max(-limit) as i32
                }
                _ if claim >= 3 => 3,
                _ => 1,
            };
            report.claims.push((pi, claim));
        }
    }

    /// Per chain, at `pose` ([`ChainLength`]): every element's span from its `from` site to
    /// its `to` site along its part's direction (`work.kept_rotations`), summed, and the
    /// straight distance between the chain's ends. `None` for a chain some part of which
    /// cannot be measured.
    fn chain_lengths(&self, asm: &Assembly, pose: &[DVec2]) -> Vec<Option<ChainLength>> {
        let data = asm.data();
        let mut lengths = vec![Some(ChainLength::default()); data.chains.len()];
        let w = &self.work;
        for (pi, part) in data.parts.iter().enumerate() {
            let PartKind::Stretch { chain, first } = part.kind else {
                continue;
            };
            let Some(slot) = lengths.get_mut(chain) else {
                continue;
            };
            let count = data.chains[chain].instances.len();
            let measured = match (&w.rest, w.kept_rotations.get(pi)) {
                (Some(cache), Some(&r)) => cache.measure_stretch(pi, part, pose, r),
                _ => None,
            };
            let (Some(length), Some(m)) = (slot.as_mut(), measured) else {
                *slot = None;
                continue;
            };
            // each element counted once: as its part's first, and the last as the second
            length.path += m.lengths[0];
            if first == 0 {
                length.near = m.near;
            }
            if first + 2 == count {
                length.path += m.lengths[1];
                length.chord = (m.far - length.near).length() / m.element;
                length.far = m.far;
                length.element = m.element;
            }
        }
        lengths
    }

    /// Every stretch part's context for this frame ([`local::StretchContext`]): its rotation
    /// at the displayed pose `warm` (`work.kept_rotations`, from [`Solver::start_at`] or the
    /// last frame), and the states the stretch rule can honour: `three` below the rule's
    /// `max`, `one` above its `min` unless both elements are held (a shrink would remove one).
    /// A chain claims elements only in the direction its length has moved: `three` only
    /// while it is longer than its elements at rest, `one` only while it is shorter, judged
    /// by its length in `start` (pass 1's first pose: the displayed one with the handles' new
    /// step; [`Solver::chain_lengths`], kept in `work.chain_lengths` to size the claims). The
    /// sparse pass gathers the change into a few parts, and a chain squeezed below its `min`
    /// folds, where a part beside a fold may span more than two elements though the chain as a
    /// whole is short.
    fn stretch_contexts(&mut self, asm: &Assembly, start: &[DVec2]) {
        use clay_dsl::compiled::{STRETCH_ONE, STRETCH_THREE, STRETCH_TWO};
        let data = asm.data();
        let grammar = asm.grammar();
        self.work.stretch.clear();
        if !data
            .parts
            .iter()
            .any(|p| matches!(p.kind, PartKind::Stretch { .. }))
        {
            return;
        }
        let lengths = self.chain_lengths(asm, start);
        let rest_chords = self.rest_chords(asm, start, &lengths);
        let reversal = self.config.reversal;
        let w = &mut self.work;
        let held_ids: Vec<u64> = asm
            .handles()
            .iter()
            .filter_map(|h| h.held.as_ref().map(|x| x.id))
            .collect();
        let held = |instance: usize| {
            data.instances
                .get(instance)
                .is_some_and(|i| held_ids.contains(&i.id))
        };
        // per chain: `None` when its ends are further apart than at rest by half an element
        // (taut), else whether what holds it stretches it half an element beyond its count
        let slack: Vec<Option<bool>> = (0..data.chains.len())
            .map(|chain| {
                let l = lengths.get(chain).copied().flatten()?;
                let rest = rest_chords.get(chain).copied().flatten()?;
                (l.chord < rest + 0.5).then(|| {
                    let c = &data.chains[chain];
                    let centres = c.instances.iter().filter(|&&i| held(i)).map(|&i| {
                        let vs = &data.instances[i].vertices;
                        vs.iter().map(|&v| start[v]).sum::<DVec2>() / vs.len().max(1) as f64
                    });
                    l.taut(centres) >= c.instances.len() as f64 + 0.5
                })
            })
            .collect();
        for (pi, part) in data.parts.iter().enumerate() {
            let PartKind::Stretch { chain, first } = part.kind else {
                w.stretch.push(None);
                continue;
            };
            let (Some(c), Some(&reference)) = (data.chains.get(chain), w.kept_rotations.get(pi))
            else {
                w.stretch.push(None);
                continue;
            };
            let Some(rule) = grammar.stretch_rules.get(c.rule) else {
                w.stretch.push(None);
                continue;
            };
            let count = c.instances.len();
            let both_held = [first, first + 1]
                .iter()
                .all(|&k| c.instances.get(k).is_some_and(|&i| held(i)));
            let length = (lengths.get(chain).copied().flatten()).map_or(count as f64, |l| l.path);
            // a change that reverses the chain's last one waits for `reversal` elements
            let shrink_below = count as f64 - if c.trend > 0 { reversal } else { 0.0 };
            // Against the chain's chord at rest (in elements): ends no further apart than at
            // rest (a chain pulled straight after a buckle, a squeeze let go of, a wave a
            // rewrite left) leave no room for an element, however far its path wanders, unless
            // something holds it out of line ([`ChainLength::taut`]); and then it grows only
            // once its elements span a whole element more than it has.
            let slack = slack.get(chain).copied().flatten();
            let (slack, held_out) = (slack.is_some(), slack == Some(true));
            let wait = match (c.trend < 0, slack) {
                (true, _) => reversal,
                (false, true) => 1.0,
                (false, false) => 0.0,
            };
            let grow_above = count as f64 + wait;
            let mut allowed = 1 << STRETCH_TWO;
            if count > rule.min.max(1) && !both_held && length <= shrink_below {
                allowed |= 1 << STRETCH_ONE;
            }
            if rule.max.is_none_or(|max| count < max)
                && length >= grow_above
                && (!slack || held_out)
            {
                allowed |= 1 << STRETCH_THREE;
            }
            w.stretch
                .push(Some(local::StretchContext { reference, allowed }));
        }
        w.chain_lengths = lengths;
    }

    /// Per chain, its chord in the rest layout ([`layout::rest_layout`], in elements) where a
    /// stretch could be in question (its elements span at least its count) while its ends are
    /// not half an element further apart than a straight chain's (no chord at rest is longer):
    /// `None` for the others, which are taut.
    fn rest_chords(
        &self,
        asm: &Assembly,
        pose: &[DVec2],
        lengths: &[Option<ChainLength>],
    ) -> Vec<Option<f64>> {
        let chains = &asm.data().chains;
        let asked = |c: usize| {
            let count = chains[c].instances.len() as f64;
            lengths[c].is_some_and(|l| l.path >= count && l.chord < count + 0.5)
        };
        if !(0..chains.len().min(lengths.len())).any(asked) {
            return vec![None; chains.len()];
        }
        let w = &self.work;
        let laid = layout::rest_layout(
            &asm.data().parts,
            &w.vertex_parts,
            &self.components,
            pose,
            &[],
            &[],
        );
        let at_rest = self.chain_lengths(asm, &laid);
        (0..chains.len())
            .map(|c| {
                let asked = c < lengths.len() && asked(c);
                asked.then(|| at_rest.get(c).copied().flatten().map(|l| l.chord))?
            })
            .collect()
    }

    /// Per part, the factor of its term in the sparse norm: for a stretch part holding a
    /// vertex of a grab, [`SolverConfig::handle_outlier`] to the power `2 - p`; of a pin only,
    /// the square root of that (the handle the user moves is the likelier place for the gap:
    /// with a pin at one end and a grab at the other, an evenly stretched chain would
    /// otherwise split its stretch between the two ends, where neither half switches); 1 for
    /// every other part.
    fn outlier_factors(&mut self, parts: &[Part], handles: &[Handle]) {
        let cfg = self.config;
        let grab = cfg.handle_outlier.clamp(1e-3, 1.0).powf(2.0 - cfg.norm);
        let pin = grab.sqrt();
        let w = &mut self.work;
        // per vertex, the smallest factor of the handles holding it (the `rhs` buffer is
        // free until the first solve)
        let at = &mut w.rhs;
        at.clear();
        at.resize(w.handle_count.len(), 1.0);
        for h in handles {
            let factor = match h.kind {
                HandleKind::Grab => grab,
                HandleKind::Pin => pin,
            };
            for &v in &h.vertices {
                if let Some(a) = at.get_mut(v) {
                    *a = a.min(factor);
                }
            }
        }
        w.outlier.clear();
        w.outlier.extend(parts.iter().map(|part| {
            if matches!(part.kind, PartKind::Stretch { .. }) {
                part.vertices.iter().map(|&v| at[v]).fold(1.0, f64::min)
            } else {
                1.0
            }
        }));
    }

    /// Puts every held vertex of `pose` where its handles now want it (their mean target);
    /// notes the largest move in `work.snapped_moved`.
    fn snap_held(&mut self, pose: &mut [DVec2]) {
        let w = &mut self.work;
        let mut moved: f64 = 0.0;
        for ((p, &count), &sum) in pose.iter_mut().zip(&w.handle_count).zip(&w.handle_sum) {
            if count > 0.0 {
                let t = sum / count;
                moved = moved.max((t - *p).length());
                *p = t;
            }
        }
        w.snapped_moved = moved;
    }

    /// Moves every component whose held vertices all moved by one rigid motion by that
    /// motion ([`follow`]): the displayed pose `warm`.
    fn follow_handles(&mut self, warm: &mut [DVec2], tolerance: f64) {
        let w = &self.work;
        let held: Vec<bool> = w.handle_count.iter().map(|&c| c > 0.0).collect();
        if !held.iter().any(|&h| h) {
            return;
        }
        let target: Vec<DVec2> = w
            .handle_count
            .iter()
            .zip(&w.handle_sum)
            .map(|(&c, &s)| if c > 0.0 { s / c } else { DVec2::ZERO })
            .collect();
        let units = &self.units;
        let motions = follow::motions(&self.components, warm, &held, &target, |c| {
            tolerance * units.size(c)
        });
        if motions.iter().all(Option::is_none) {
            return;
        }
        follow::move_points(&self.components, &motions, warm);
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
}

/// Most pass-2 iterations that settle one trial assignment of rest states
/// ([`Solver::try_states`]): a bend moved to the neighbouring segment moves every segment
/// between it and the handle, which least squares settles slowly.
const SETTLE_ITERATIONS: usize = 60;

/// A model with nothing held whose energy fell by less than this factor's complement over a
/// frame (5%) creeps: it tries other states and the rest layout without waiting to stop.
const CREEP: f64 = 0.95;

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
