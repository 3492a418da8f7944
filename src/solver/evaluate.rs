//! The local step's evaluation at a pose (paper 4.1-4.3): every part's rotation, the edge
//! targets `R_xy (x0 - y0)` and the per-part residuals into the work buffers, with the
//! states fixed or switching (with hysteresis, one claim per chain: [`growth`]). The fast
//! path runs [`chunks::evaluate`] over the rest cache; when the cache does not fit the
//! assembly, the reference functions of [`local`] run part by part.
//!
//! Its own `impl Solver` block because both passes and the trials of other states call it,
//! and it reads and writes only the state's buffers.

use clay_dsl::compiled::{Part, PartKind};
use glam::DVec2;

use super::config::cone_cosine;
use super::report::{Judged, StateSwitch};
use super::state::Solver;
use super::{chunks, growth, local};
use crate::assembly::Assembly;

impl Solver {
    /// Each part's rotation onto `f` with its active state (states fixed), into
    /// `work.rotations`.
    fn rotations_at(&mut self, parts: &[Part], f: &[DVec2]) {
        let w = &mut self.work;
        match &mut w.rest {
            Some(cache) => cache.part_rotations(parts, f, &mut w.rotations),
            None => {
                w.rotations.clear();
                w.rotations
                    .extend(parts.iter().map(|part| local::part_rotation(part, f)));
            }
        }
    }

    /// Whether the rest cache fits the assembly (else the reference functions run).
    pub(super) fn cache_fits(&self, parts: usize) -> bool {
        let edges = self.pattern.edges.len();
        (self.work.rest.as_ref()).is_some_and(|c| c.parts() == parts && c.edges() == edges)
    }

    /// The local step at `f` with the states fixed: rotations, edge targets and per-part
    /// residuals into the work buffers; returns the elastic energy at `f`.
    pub(super) fn evaluate_fixed(&mut self, parts: &[Part], f: &[DVec2]) -> f64 {
        if !self.cache_fits(parts.len()) {
            self.rotations_at(parts, f);
            self.edge_targets(parts);
            return self.residuals_at(f);
        }
        self.evaluate(parts, f, chunks::Choice::Keep)
    }

    /// The local step at `f` with state switching (paper 4.3): as
    /// [`Solver::evaluate_fixed`], and every part whose nearest state wins the hysteresis
    /// switches to it (reported in part order), except that a stretch chain claims at most
    /// one element per frame ([`growth`]).
    pub(super) fn evaluate_switching(
        &mut self,
        parts: &mut [Part],
        f: &[DVec2],
        switches: &mut Vec<StateSwitch>,
    ) {
        let stretch = std::mem::take(&mut self.work.stretch);
        let shared = std::mem::take(&mut self.work.vertex_parts);
        let how = local::Switching {
            hysteresis: self.config.hysteresis,
            stretch: &stretch,
            shared: Some(&shared),
        };
        let from = switches.len();
        if self.cache_fits(parts.len()) {
            self.evaluate(parts, f, chunks::Choice::Switch(how));
            for (i, (part, &state)) in parts.iter_mut().zip(&self.work.chosen).enumerate() {
                if state != part.active {
                    switches.push(StateSwitch {
                        part: i,
                        from: part.active,
                        to: state,
                        judged: Judged::Shape,
                    });
                    part.active = state;
                }
            }
        } else {
            self.local_step_switching(parts, f, how, switches);
            self.edge_targets(parts);
            self.residuals_at(f);
        }
        self.work.stretch = stretch;
        self.work.vertex_parts = shared;
        let w = &mut self.work;
        std::mem::swap(&mut w.pass1_claims, &mut w.claims);
        // a state a try chose by energy holds until the handles move: judged by shape, pass 1
        // could switch it back, and the next try again (a 2-cycle while held still). The
        // handles moved this frame when their targets differ from the last frame's (the list
        // itself is cleared after the frame, `Solver::settling`)
        let kept = &w.kept_by_trial;
        let undone = !kept.is_empty()
            && w.last_targets == w.handle_sum
            && undo_kept(parts, switches, from, kept);
        let w = &mut self.work;
        if growth::one_per_chain(parts, switches, from, &w.residuals, &w.pass1_claims) || undone {
            // the reverted parts' rotations and targets are their kept states'
            self.evaluate_fixed(parts, f);
        }
    }

    /// [`chunks::evaluate`] into the work buffers (the rest cache fits).
    pub(super) fn evaluate(&mut self, parts: &[Part], f: &[DVec2], choice: chunks::Choice) -> f64 {
        let cos_cone = cone_cosine(self.config.rotation_cone_degrees);
        let threads = self.config.thread_count();
        let w = &mut self.work;
        let Some(cache) = &w.rest else {
            return 0.0;
        };
        let count = parts.len();
        w.rotations.resize(count, DVec2::X);
        w.chosen.resize(count, 0);
        w.claims.resize(count, 0);
        w.residuals.resize(count, 0.0);
        // every slot is written: no clearing pass
        w.targets.resize(cache.edges(), DVec2::ZERO);
        let out = chunks::Outputs {
            rotations: &mut w.rotations,
            chosen: &mut w.chosen,
            claims: &mut w.claims,
            residuals: &mut w.residuals,
            targets: &mut w.targets,
        };
        chunks::evaluate(cache, parts, f, choice, cos_cone, threads, out)
    }

    /// Per part, its squared stacked residual at `f` with `work.targets` (into
    /// `work.residuals`); returns the elastic energy (the same sums as [`chunks::evaluate`]
    /// for a model of one chunk).
    fn residuals_at(&mut self, f: &[DVec2]) -> f64 {
        let w = &mut self.work;
        let edges = &self.pattern.edges;
        w.residuals.clear();
        w.residuals.resize(w.rotations.len(), 0.0);
        let mut elastic = 0.0;
        let mut k = 0;
        while k < edges.len() {
            let part = edges[k].part;
            let end = k + edges[k..].iter().take_while(|e| e.part == part).count();
            let d2: f64 = (k..end)
                .map(|j| {
                    let (x, y) = edges[j].ends();
                    let r2 = (w.targets[j] - (f[x] - f[y])).length_squared();
                    elastic += r2;
                    r2
                })
                .sum();
            if let Some(r) = w.residuals.get_mut(part as usize) {
                *r = d2;
            }
            k = end;
        }
        elastic
    }

    /// Local step with state switching; fills `work.rotations` and `work.claims`.
    fn local_step_switching(
        &mut self,
        parts: &mut [Part],
        f: &[DVec2],
        how: local::Switching,
        switches: &mut Vec<StateSwitch>,
    ) {
        let w = &mut self.work;
        w.rotations.clear();
        w.claims.clear();
        for (i, part) in parts.iter_mut().enumerate() {
            let chosen = match &mut w.rest {
                Some(cache) => cache.choose_state(i, part, f, how),
                None => local::choose_state(i, part, f, how),
            };
            if chosen.state != part.active {
                switches.push(StateSwitch {
                    part: i,
                    from: part.active,
                    to: chosen.state,
                    judged: Judged::Shape,
                });
                part.active = chosen.state;
            }
            w.rotations.push(chosen.rotation);
            w.claims.push(chosen.claim);
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
            while k < edges.len() && edges[k].part as usize == pi {
                let e = &edges[k];
                let [a, b] = e.local.map(|i| i as usize);
                let d0 = match (rest.get(a), rest.get(b)) {
                    (Some(&a), Some(&b)) => a - b,
                    _ => DVec2::ZERO,
                };
                let r = if cos_cone < 1.0 {
                    local::normalised_or(w.part_sums[a] + w.part_sums[b], own)
                } else {
                    own
                };
                w.targets.push(r.rotate(d0));
                k += 1;
            }
        }
    }

    /// Paper 4.3 in the pose pass 1 hands the rules: a piece part that switched by shape in
    /// this pass (`switches[first..]`) keeps its new state only if that state is nearer the
    /// last pose `f` than the one it began the pass in by the hysteresis margin; else the
    /// part goes back to that one. A part that ends the pass in the state it began it in,
    /// so, or having switched there and back, switched nothing: its switches leave the list.
    ///
    /// Why: each iteration's local step judges the pose before that iteration's solve, so a
    /// part could switch at an iterate just past the margin and the pass end just short of
    /// it: a bend piece took its 20-degree state with its sites turned 9.95 degrees in the
    /// pose that decided the frame, 7 of 10^4 generated cases of
    /// `sec4_3_states_follow_the_shape` (`tests/paper_claims_assemblies.rs`). And a switch
    /// there and back within the pass, left in the list, made every frame one that switched:
    /// a held model never converged, tried nothing and was never relaxed (generated round
    /// case 8649: a bend piece flipped to its mirror and back in every frame's pass 1, the
    /// model held at strain 2.5 for 240 frames).
    pub(super) fn confirm_switches(
        &mut self,
        parts: &mut [Part],
        f: &[DVec2],
        first: usize,
        switches: &mut Vec<StateSwitch>,
    ) {
        let mut began: Vec<(usize, usize)> = Vec::new();
        for s in switches.iter().skip(first) {
            if !began.iter().any(|b| b.0 == s.part) {
                began.push((s.part, s.from));
            }
        }
        let how = local::Switching {
            hysteresis: 0.0,
            stretch: &[],
            shared: Some(&self.work.vertex_parts),
        };
        let h = self.config.hysteresis;
        let mut undo = Vec::new();
        let mut reverted = false;
        for (pi, from) in began {
            let to = parts[pi].active;
            if to == from {
                undo.push(pi);
                continue;
            }
            let by_shape = switches.iter().skip(first).any(|s| {
                s.part == pi
                    && s.judged == Judged::Shape
                    && matches!(parts[pi].kind, PartKind::Piece { .. })
            });
            if !by_shape {
                continue;
            }
            let judged = local::judge(pi, &parts[pi], f, how);
            let d = |j: usize| judged.distances.get(j).copied().unwrap_or(f64::NAN);
            // NaN keeps the switch: nothing to judge it by
            let (here, there) = (d(from), d(to));
            if !here.is_nan()
                && !there.is_nan()
                && local::switched(from, here, (to, there), h) == from
            {
                parts[pi].active = from;
                undo.push(pi);
                reverted = true;
            }
        }
        if undo.is_empty() {
            return;
        }
        let mut step = switches.split_off(first);
        step.retain(|s| !undo.contains(&s.part));
        switches.append(&mut step);
        if reverted {
            self.evaluate_fixed(parts, f);
        }
    }

    /// The piece instances (by stable id) of `asm` in another state than `before` gave them
    /// that paper 4.3 would switch again in `asm`'s pose: another state nearer it than their
    /// own by the hysteresis margin, as pass 1 judges. This solver's last frame must have run
    /// on `asm` (its shared vertices are `asm`'s).
    ///
    /// Why: a relaxation proposes a piece's state from the relaxed pose, where least squares
    /// spread the turn, and the model settled with it may not bend that way: the next
    /// frame's pass 1 switched it back, and the proposal came again (generated states case
    /// 1111: a bend piece to -10 degrees and back, its sites turned 0.0 degrees, twice).
    pub(crate) fn switched_again(&self, asm: &Assembly, before: &Assembly) -> Vec<u64> {
        let was: std::collections::HashMap<u64, usize> = (before.data().instances.iter())
            .map(|x| (x.id, x.state))
            .collect();
        let data = asm.data();
        let mut again = Vec::new();
        for (pi, part) in data.parts.iter().enumerate() {
            let PartKind::Piece { instance } = part.kind else {
                continue;
            };
            let Some(x) = data.instances.get(instance) else {
                continue;
            };
            let switched = was.get(&x.id).is_some_and(|&s| s != part.active);
            if switched && !self.stands(pi, part, &data.positions) {
                again.push(x.id);
            }
        }
        again
    }

    /// Whether part `pi` keeps its active state in pose `f` as pass 1 judges it (paper 4.3:
    /// no other state nearer by the hysteresis margin). This solver's shared vertices must be
    /// those of the parts'.
    fn stands(&self, pi: usize, part: &Part, f: &[DVec2]) -> bool {
        if part.states.len() < 2 {
            return true;
        }
        let how = local::Switching {
            hysteresis: 0.0,
            stretch: &[],
            shared: Some(&self.work.vertex_parts),
        };
        let judged = local::judge(pi, part, f, how);
        let Some(&here) = judged.distances.get(part.active) else {
            return true;
        };
        let best = (judged.distances.iter().copied().enumerate())
            .filter(|(_, d)| d.is_finite())
            .min_by(|a, b| a.1.total_cmp(&b.1));
        !here.is_finite()
            || best.is_none_or(|b| {
                local::switched(part.active, here, b, self.config.hysteresis) == part.active
            })
    }
}

/// Undoes the switches `switches[from..]` of parts in `kept` (their states back to where the
/// switch found them; the switches leave the list). Returns whether any was undone.
fn undo_kept(
    parts: &mut [Part],
    switches: &mut Vec<StateSwitch>,
    from: usize,
    kept: &[usize],
) -> bool {
    let mut step = switches.split_off(from);
    let before = step.len();
    step.retain(|s| {
        let undo = kept.contains(&s.part);
        if undo {
            parts[s.part].active = s.from;
        }
        !undo
    });
    let undone = step.len() < before;
    switches.append(&mut step);
    undone
}
