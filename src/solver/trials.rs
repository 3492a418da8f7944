//! Trials of other rest states (`docs/solver.md`, "Folds"): a held model that stopped
//! strained, or one that creeps, tries other assignments of rest states once (the
//! nearest single switches, a bend handed to a neighbour, bends reverted, the rest layout),
//! each settled by a few iterations, and keeps one that is clearly better.
//!
//! A file of its own because it is one step of the frame (`mod.rs` calls `trials`), run
//! seldom and long: an `impl Solver` block over the state of `state.rs`, imported from that
//! sibling rather than from `mod.rs`, so no child imports its parent.

use clay_dsl::compiled::{Part, PartKind};
use glam::DVec2;

use super::clock::Stop;
use super::global_step::Pass;
use super::report::{FrameReport, Judged, SolverError, StateSwitch};
use super::state::Solver;
use super::{chunks, layout, local};
use crate::assembly::{Assembly, Handle};

impl Solver {
    /// The frame's trials: when it is [`Solver::settling`], other rest states
    /// are tried ([`Solver::try_states`]), and an assignment kept from the rest layout moves
    /// `warm` (where pass 2 starts) there. Notes the handles' targets for the next frame's
    /// stillness test.
    pub(super) fn trials(
        &mut self,
        asm: &mut Assembly,
        warm: &mut [DVec2],
        report: &mut FrameReport,
    ) -> Result<(), SolverError> {
        let little = self.moved_little(asm);
        let settling = self.settling(report);
        self.work.last_targets.clone_from(&self.work.handle_sum);
        self.proposals = None;
        if settling && little {
            // the elastic answer to a small move from rest: nothing to try
            self.work.tried = true;
        } else if settling {
            let handles = asm.handles().to_vec();
            let parts = &mut asm.data_mut().parts;
            if let Some(laid) = self.try_states(parts, &handles, warm, report)? {
                warm.copy_from_slice(&laid);
            }
            // nothing the states could do: what the relaxed model proposes (`relax.rs`); not
            // with least squares, whose structure follows the drag alone (paper Fig. 8)
            if self.work.tried && self.config.norm < 2.0 {
                let generation = asm.generation();
                self.proposals = Some((generation, self.relax(asm, warm)?));
            }
        }
        Ok(())
    }

    /// Whether the model is held, rested with the structure and states it has, and its
    /// handles' targets have stayed nearer where their vertices rested than the hysteresis
    /// times its shortest element ever since (paper 4.3, in elements, as a chain's count from
    /// its length): its strain is the elastic answer to a small move, and neither a try nor
    /// the relaxation runs (a tree moved 3 cm from rest was restructured into another rest
    /// configuration, its energy 8.6e-6 against 2.7e-6; one moved 8 mm had a bend state
    /// switched by a try, its energy 2.6e-7 before). A model whose handles went further, or
    /// whose structure or states changed, has left that rest until it rests again: pushed
    /// past its `min` and brought back, it may be folded far from it. Needed by
    /// `sec4_3_small_moves_switch_nothing`.
    fn moved_little(&mut self, asm: &Assembly) -> bool {
        let w = &self.work;
        let Some(r) = &w.rested else {
            return false;
        };
        let parts = &asm.data().parts;
        let same = r.generation == asm.generation()
            && r.states.len() == parts.len()
            && parts.iter().zip(&r.states).all(|(p, &s)| p.active == s)
            && r.pose.len() == w.handle_sum.len();
        // how far the handles' targets are from where their vertices rested
        let moved = (w.handle_count.iter().zip(&w.handle_sum).zip(&r.pose))
            .filter(|((c, _), _)| **c > 0.0)
            .map(|((c, sum), at)| (*sum / *c).distance(*at))
            .fold(0.0, f64::max);
        let held = w.handle_count.iter().any(|&c| c > 0.0);
        let near = same && moved < self.config.hysteresis * r.shortest;
        if !near {
            self.work.rested = None;
        }
        near && held
    }

    /// Whether this frame tries other rest states ([`Solver::try_states`]): the handles
    /// stayed where they were and pass 1 switched nothing, the last frame left the displayed
    /// pose all but still (or its energy creeping down: [`CREEP`]) and yet not at rest, and
    /// no try since the handles, the states or the structure last changed.
    pub(super) fn settling(&mut self, report: &FrameReport) -> bool {
        let w = &mut self.work;
        let held_still = w.last_targets == w.handle_sum;
        if !held_still {
            w.kept_by_trial.clear();
        }
        let still = held_still && report.switches.is_empty();
        if !still {
            w.tried = false;
        }
        let stopped = w.last_moved <= 1e-3;
        // the energy all but flat: a long, thin chain unbending, which least squares would
        // take hundreds of frames over (or a fold it never leaves), free or held (a held
        // tree whose arcs must turn further creeps towards its strained pose for hundreds of
        // frames). The tries run whole whatever the frame's budget, so a gesture saved as a
        // script replays into the same sculpt (`Stop`, `editor/tests/gesture_script.rs`)
        let [last, before] = w.last_energy;
        let creeping = last > CREEP * before;
        let untried = !w.tried;
        still && (stopped || creeping) && untried && self.strained(self.work.start.elastic)
    }

    /// Whether an elastic energy is not at rest: above a millionth of the shortest rest edge
    /// squared (what [`Solver::try_states`] tries to lower; the session's choice among
    /// proposals that rest).
    pub(crate) fn strained(&self, elastic: f64) -> bool {
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
    pub(super) fn try_states(
        &mut self,
        parts: &mut [Part],
        handles: &[Handle],
        warm: &[DVec2],
        report: &mut FrameReport,
    ) -> Result<Option<Vec<DVec2>>, SolverError> {
        const ITERATIONS: usize = 3;
        let hysteresis = self.config.hysteresis;
        let moves = self.trial_moves(parts, warm);
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
        let mut unfolded = None;
        if let Some(laid) = self.rest_layout_at(parts, warm) {
            let e = self.settle(parts, handles, &laid, ITERATIONS, &actives, &[])?;
            if e < (1.0 - hysteresis) * baseline && best.as_ref().is_none_or(|b| e < b.0) {
                best = Some((e, parts.iter().map(|p| p.active).collect()));
                unfolded = Some(laid);
            }
        }
        let energy = best.as_ref().map(|b| [baseline, b.0]);
        let chosen = best.map_or(actives.clone(), |b| b.1);
        // a kept assignment that switches nothing (the rest layout of the same states) is the
        // one try too: were it due again, a model whose pass 2 returns from that layout to
        // where it stopped would try it every frame, never converge and never relax (a square
        // of four hubs pulled out by a corner stayed at strain 0.36 with no rule fired)
        self.work.tried = chosen == actives;
        for (pi, (p, (&from, &to))) in parts
            .iter_mut()
            .zip(actives.iter().zip(&chosen))
            .enumerate()
        {
            p.active = to;
            if from != to {
                report.switches.push(StateSwitch {
                    part: pi,
                    from,
                    to,
                    judged: energy.map_or(Judged::Shape, Judged::Energy),
                });
                self.work.kept_by_trial.push(pi);
            }
        }
        self.work.start.valid = None;
        Ok(unfolded)
    }

    /// `asm`'s parts laid at rest in their active states from its displayed pose and moved
    /// onto its handles, as [`Solver::try_states`] lays them to leave a fold: where a
    /// restructured model settles from when the rules' layout left it folded (an arc's
    /// inserted element turned against its neighbours). The solver's last frame must have run
    /// on `asm` as it is; `None` otherwise or when the layout leaves the finite numbers.
    pub(crate) fn rest_layout_of(&self, asm: &Assembly) -> Option<Vec<DVec2>> {
        self.rest_layout_at(&asm.data().parts, &asm.data().positions)
    }

    /// `parts` laid at rest in their active states from `pose` and moved onto the handles
    /// (`layout::rest_layout`, with the last frame's components and handle targets); `None`
    /// when those are of another model or the layout leaves the finite numbers.
    fn rest_layout_at(&self, parts: &[Part], pose: &[DVec2]) -> Option<Vec<DVec2>> {
        let w = &self.work;
        if w.handle_count.len() != pose.len() || w.handle_sum.len() != pose.len() {
            return None;
        }
        let laid = layout::rest_layout(
            parts,
            &w.vertex_parts,
            &self.components,
            pose,
            &w.handle_count,
            &w.handle_sum,
        );
        laid.iter().all(|p| p.is_finite()).then_some(laid)
    }

    /// The moves [`Solver::try_states`] tries, each a list of `(part, state)`: the few
    /// single switches whose state is nearest (by its shape distance at `warm` against the
    /// active one's), every bent piece part's state handed to each straight neighbour, and
    /// with few bent parts, all but one of them reverted (for each) and all of them.
    fn trial_moves(&self, parts: &[Part], warm: &[DVec2]) -> Vec<Vec<(usize, usize)>> {
        const CANDIDATES: usize = 4;
        // more parts out of their first state than this: no reverting moves (each is a settle)
        const REVERT_LIMIT: usize = 8;
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
        moves
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
        let settled = self.pass2(parts, handles, f, cfg.tolerance, Stop::Never, &mut report);
        self.config = cfg;
        let (_, terms, _) = settled?;
        Ok(terms.total())
    }
}

/// Most pass-2 iterations that settle one trial assignment of rest states
/// ([`Solver::try_states`]): a bend moved to the neighbouring segment moves every segment
/// between it and the handle, which least squares settles slowly.
const SETTLE_ITERATIONS: usize = 60;

/// A model whose energy fell by less than this factor's complement over a frame (5%)
/// creeps, held or free: it tries other states and the rest layout without waiting to stop.
const CREEP: f64 = 0.95;
