//! The relaxation of a held model that stopped strained (`docs/solver.md`, "A held model that
//! stops strained is relaxed"): least squares in which every chain element may take any
//! length along its chain (a stretch part's rest shape is its two elements, each scaled on its
//! own: the continuous family through the counts the stretch rule makes) and every piece part
//! takes its nearest rest state at each step, from the displayed pose with the handles where
//! they hold. Where a rest configuration exists, the relaxed model finds its way towards it
//! whatever the counts it started from; its chains' lengths then give the counts and its
//! pieces the states: [`Proposal`]s that the session tries with the rules and keeps when the
//! model rests better with one (paper 4.2: the structure changes where a rest state fits
//! better, judged by energy).
//!
//! A file of its own because it is one step of a frame that has stopped (`trials.rs` calls
//! it): an `impl Solver` block over the state of `state.rs`, imported from that sibling rather
//! than from `mod.rs`, so no child imports its parent.

use clay_dsl::compiled::{Part, PartKind, STRETCH_TWO};
use glam::DVec2;

use super::closure::closing;
use super::global_step::Pass;
use super::growth::ChainLength;
use super::local::{self, StretchEnds};
use super::pass2::handle_term;
use super::report::{FrameReport, Proposal, SolverError};
use super::rounding::{Relaxed, decide_run, held_elements, runs};
use super::state::Solver;
use super::turns::counts_from_turns;
use crate::assembly::Assembly;
use crate::fit::align;

/// Most least-squares iterations of the relaxation (it stops earlier once its objective no
/// longer falls).
const ITERATIONS: usize = 1000;

/// The relaxation stops once an iteration lowers its objective by less than this fraction.
const FLAT: f64 = 1e-10;

/// An element's shortest relaxed length, in elements: one squeezed below it (folded onto
/// itself) is held there.
const SHORTEST: f64 = 0.1;

/// A stretch part's relaxed rest family: its two elements, each scaled along the chain's
/// axis on its own (element `a` from the near end, element `b` after it), so that a chain
/// relaxes to any length with every element at its own scale, a held element at its own
/// (the two parts over an element agree on it). Every vertex's position is affine in the
/// two scales: `p0 + sa qa + sb qb`.
struct Family {
    p0: Vec<DVec2>,
    qa: Vec<DVec2>,
    qb: Vec<DVec2>,
    ends: StretchEnds,
    two: Vec<DVec2>,
    /// The least and most scale of an element ([`scale_bounds`]).
    bounds: [f64; 2],
}

impl Family {
    fn of(part: &Part) -> Option<Self> {
        if !matches!(part.kind, PartKind::Stretch { .. }) || part.states.len() != 3 {
            return None;
        }
        let m = part.vertices.len();
        if part.states.iter().any(|s| s.positions.len() < m) {
            return None;
        }
        let ends = StretchEnds::find(
            &part.states[0].positions[..m],
            &part.states[2].positions[..m],
        )?;
        let two = &part.states[STRETCH_TWO].positions[..m];
        let near = ends.near.iter().map(|&k| two[k]).sum::<DVec2>() / ends.near.len() as f64;
        let (axis, l) = (ends.axis, ends.element);
        let (mut p0, mut qa, mut qb) = (
            Vec::with_capacity(m),
            Vec::with_capacity(m),
            Vec::with_capacity(m),
        );
        for &p in two {
            let x = (p - near).dot(axis);
            p0.push(p - axis * x);
            if x <= l * (1.0 + 1e-9) {
                qa.push(axis * x);
                qb.push(DVec2::ZERO);
            } else {
                qa.push(axis * l);
                qb.push(axis * (x - l));
            }
        }
        Some(Self {
            p0,
            qa,
            qb,
            ends,
            two: two.to_vec(),
            bounds: [SHORTEST, f64::INFINITY],
        })
    }

    /// Each element's length in `pose` (its vertices' positions), in elements at rest, along
    /// the chain's direction as the `two` shape best fits it.
    fn lengths(&self, part: &Part, pose: &[DVec2]) -> [f64; 2] {
        let at = |k: usize| pose[part.vertices[k]];
        let r = align(&self.two, &part.vertices, pose).rotation;
        let axis = r.rotate(self.ends.axis);
        self.ends
            .element_spans(at)
            .map(|d| d.dot(axis) / self.ends.element)
    }
}

impl Solver {
    /// The relaxation from `warm` (the displayed pose; the handles gathered this frame), and
    /// what it proposes (empty when it changes nothing). Its chains' lengths are rounded in
    /// rounds (`Solver::round_counts`); the straight chains round loops get the counts that
    /// close them (`closure.rs`), the turning ones the counts their turns ask for
    /// (`turns.rs`). The session keeps the one the model rests best with.
    pub(super) fn relax(
        &mut self,
        asm: &Assembly,
        warm: &[DVec2],
    ) -> Result<Vec<Proposal>, SolverError> {
        let data = asm.data();
        let families: Vec<Option<Family>> = (data.parts.iter())
            .map(|part| {
                let mut family = Family::of(part)?;
                family.bounds = scale_bounds(asm, part, &self.work.chain_lengths);
                Some(family)
            })
            .collect();
        let hysteresis = self.config.hysteresis;
        let mut f = warm.to_vec();
        let (forced, tied) = self.relaxed_piece_states(asm, &families, &mut f)?;
        // the straight chains round loops: the counts that close them (`closure.rs`)
        let closes = self.counts_that_close(asm, &families, (&forced, &f), tied);
        let Some((decided, g)) = self.round_counts(asm, &families, &forced, &f)? else {
            return Ok(Vec::new());
        };
        let mut alternatives: Vec<Proposal> = Vec::new();
        let rounded = Proposal {
            counts: (relaxed_lengths(asm, &families, &g).iter())
                .filter_map(|r| decided[r.chain].and_then(|want| r.towards(want)))
                .collect(),
            states: self.relaxed_states(&data.parts, &forced, &g),
            pose: g,
            then_lengths: false,
        };
        if !rounded.is_empty() {
            alternatives.push(rounded);
        }
        let same = |p: &Proposal, q: &Proposal| p.counts == q.counts && p.states == q.states;
        alternatives.extend(closes.filter(|p| !alternatives.iter().any(|q| same(p, q))));
        // a chain of turning elements: the count its ends' turn asks for (`turns.rs`)
        for (counts, taken) in counts_from_turns(asm, &f, hysteresis) {
            // the relaxed states, a piece's taken in another where the turn asks for it
            let taken: Option<Vec<(usize, usize)>> = (taken.iter())
                .map(|&(instance, state)| Some((asm.piece_part(instance)?, state)))
                .collect();
            let Some(taken) = taken else {
                continue;
            };
            let mut states = self.relaxed_states(&data.parts, &forced, &f);
            states.retain(|s| taken.iter().all(|t| t.0 != s.0));
            let active = |&(part, state): &(usize, usize)| data.parts[part].active == state;
            states.extend(taken.into_iter().filter(|t| !active(t)));
            states.sort_unstable();
            alternatives.push(Proposal {
                counts,
                states,
                pose: f.clone(),
                then_lengths: true,
            });
        }
        Ok(alternatives)
    }

    /// Counts for every chain, decided in rounds from the relaxation at `start`: each round
    /// relaxes with the chains decided so far held at their counts, then decides the chains
    /// whose lengths are nearly whole (within [`DECIDED`] of a count) and one more, the one
    /// nearest a whole count (with the chains in series with it: `rounding.rs`), so that a
    /// change the relaxation spreads over chains in series or round a loop ends whole in one
    /// of them rather than split and lost. Returns the counts and the last round's pose;
    /// `None` when the relaxation left the finite numbers.
    fn round_counts(
        &mut self,
        asm: &Assembly,
        families: &[Option<Family>],
        forced: &[(usize, usize)],
        start: &[DVec2],
    ) -> Result<Option<Rounded>, SolverError> {
        let data = asm.data();
        let held = held_elements(asm);
        let hysteresis = self.config.hysteresis;
        let series = runs(asm.grammar(), data, &held);
        let mut f = start.to_vec();
        let mut decided: Vec<Option<usize>> = vec![None; data.chains.len()];
        loop {
            let fixed = fixed_scales(asm, &decided, &held);
            self.relax_from(asm, families, &fixed, forced, &mut f)?;
            if f.iter().any(|p| !p.is_finite()) {
                return Ok(None);
            }
            let lengths = relaxed_lengths(asm, families, &f);
            let open: Vec<&Relaxed> = lengths
                .iter()
                .filter(|r| decided[r.chain].is_none())
                .collect();
            let Some(chosen) = open.iter().map(|r| r.doubt()).min_by(f64::total_cmp) else {
                break;
            };
            for r in &open {
                let doubt = r.doubt();
                if decided[r.chain].is_some() || (doubt > DECIDED && doubt != chosen) {
                    continue;
                }
                // a chain in series with others is decided with them (`rounding.rs`)
                let run: Option<Vec<&Relaxed>> = (series.iter().find(|g| g.contains(&r.chain)))
                    .map(|g| {
                        open.iter()
                            .copied()
                            .filter(|q| g.contains(&q.chain))
                            .collect()
                    });
                match run
                    .as_deref()
                    .and_then(|run| Some((run, decide_run(run, hysteresis)?)))
                {
                    Some((run, counts)) => {
                        for (q, n) in run.iter().zip(counts) {
                            decided[q.chain] = Some(n);
                        }
                    }
                    None => decided[r.chain] = Some(r.decide(hysteresis)),
                }
            }
        }
        Ok(Some((decided, f)))
    }

    /// The piece parts' states the relaxation keeps, judged by its energy, and `f` relaxed
    /// with them (counts free). Least squares spreads a turn over every part it crosses, so
    /// a piece part whose bent state would take the whole turn reads nearest its straight
    /// one in the relaxed pose (a bend piece between two chains, its hubs turned 45 degrees
    /// apart, sees 4 degrees of it). So, in up to [`STATE_ROUNDS`] rounds, the
    /// [`STATE_TRIES`] alternative states nearest their parts' shapes are each relaxed with,
    /// and the lowest is kept when below `(1 - hysteresis)` times the relaxation without it
    /// (paper 4.2: a rest state is taken where it fits better, judged by energy).
    fn relaxed_piece_states(
        &mut self,
        asm: &Assembly,
        families: &[Option<Family>],
        f: &mut Vec<DVec2>,
    ) -> Result<(States, Vec<Assigned>), SolverError> {
        let parts = &asm.data().parts;
        let free = vec![None; parts.len()];
        let mut forced: Vec<(usize, usize)> = Vec::new();
        let mut energy = self.relax_from(asm, families, &free, &forced, f)?;
        let margin = 1.0 - self.config.hysteresis;
        // every assignment relaxed: (relaxed objective, the states, the relaxed pose)
        let mut tried: Vec<(f64, States, Vec<DVec2>)> = Vec::new();
        for _ in 0..STATE_ROUNDS {
            let mut best: Option<(f64, States, Vec<DVec2>)> = None;
            for m in self.state_candidates(parts, &forced, f) {
                let mut trial: Vec<(usize, usize)> = (forced.iter().copied())
                    .filter(|x| m.iter().all(|y| y.0 != x.0))
                    .collect();
                trial.extend(&m);
                let mut g = f.clone();
                let e = self.relax_from(asm, families, &free, &trial, &mut g)?;
                if e < margin * energy && best.as_ref().is_none_or(|b| e < b.0) {
                    best = Some((e, trial.clone(), g.clone()));
                }
                tried.push((e, trial, g));
            }
            let Some((e, trial, g)) = best else {
                break;
            };
            forced = trial;
            energy = e;
            *f = g;
        }
        // the others that relax as well as the kept one: a turn taken by another piece
        let tied = (tried.into_iter())
            .filter(|(e, states, _)| {
                *states != forced && (*e * margin <= energy || !self.strained(*e))
            })
            .map(|(_, states, g)| (states, g))
            .collect();
        Ok((forced, tied))
    }

    /// What the counts that close the loops propose (`closure.rs`): with the piece states the
    /// relaxation kept (`forced`, relaxed to `f`), or with another assignment
    /// that relaxes as well (`tied`) when its whole counts close better by the hysteresis
    /// margin. Counts free, a turn's share moved from one bendable piece to another closes as
    /// well, and only the whole counts tell them apart: a tree whose far hub is led where a
    /// bend on its last link rests, the bend taken by a piece on its first, rested at strain
    /// 0.04 (generated morph case 658).
    fn counts_that_close(
        &self,
        asm: &Assembly,
        families: &[Option<Family>],
        (forced, f): (&States, &[DVec2]),
        tied: Vec<Assigned>,
    ) -> Option<Proposal> {
        let held = held_elements(asm);
        let parts = &asm.data().parts;
        let margin = 1.0 - self.config.hysteresis;
        let mut kept = closing(asm, f, &relaxed_lengths(asm, families, f), &held)?;
        let mut best = (
            kept.misfit,
            Proposal {
                counts: std::mem::take(&mut kept.changes),
                states: self.relaxed_states(parts, forced, f),
                pose: f.to_vec(),
                then_lengths: false,
            },
        );
        for (states, g) in tied {
            let Some(other) = closing(asm, &g, &relaxed_lengths(asm, families, &g), &held) else {
                continue;
            };
            if other.misfit < margin * best.0 {
                let states = self.relaxed_states(parts, &states, &g);
                best = (
                    other.misfit,
                    Proposal {
                        counts: other.changes,
                        states,
                        pose: g,
                        then_lengths: true,
                    },
                );
            }
        }
        let (misfit, proposal) = best;
        (kept.better(misfit, self.config.hysteresis) && !proposal.is_empty()).then_some(proposal)
    }

    fn state_candidates(
        &self,
        parts: &[Part],
        forced: &[(usize, usize)],
        f: &[DVec2],
    ) -> Vec<Vec<(usize, usize)>> {
        let how = local::Switching {
            hysteresis: 0.0,
            stretch: &[],
            shared: Some(&self.work.vertex_parts),
        };
        let now = self.relaxed_states(parts, forced, f);
        let mut out: Vec<(f64, usize, usize)> = Vec::new();
        for (pi, part) in parts.iter().enumerate() {
            if !matches!(part.kind, PartKind::Piece { .. })
                || part.states.len() < 2
                || forced.iter().any(|x| x.0 == pi)
            {
                continue;
            }
            let current = now.iter().find(|x| x.0 == pi).map_or(part.active, |x| x.1);
            let j = local::judge(pi, part, f, how);
            let Some(&here) = j.distances.get(current) else {
                continue;
            };
            for (state, d) in j.distances.iter().enumerate() {
                if state != current && d.is_finite() {
                    out.push((d - here, pi, state));
                }
            }
        }
        out.sort_by(|a, b| a.0.total_cmp(&b.0));
        let state_of = |pi: usize| {
            (forced.iter().chain(&now))
                .find(|x| x.0 == pi)
                .map_or(parts[pi].active, |x| x.1)
        };
        // hand-offs: a bent piece part back in its first state and a straight one taking a
        // bent state (the turn taken by another piece on the path: counts free, both
        // assignments close, and only the whole counts tell them apart)
        let bent: Vec<usize> = (parts.iter().enumerate())
            .filter(|(pi, p)| {
                matches!(p.kind, PartKind::Piece { .. }) && p.states.len() > 1 && state_of(*pi) != 0
            })
            .map(|(pi, _)| pi)
            .take(HAND_OFF_FROM)
            .collect();
        let mut hand_offs: Vec<Vec<(usize, usize)>> = Vec::new();
        for &a in &bent {
            let takers = (out.iter())
                .filter(|&&(_, pi, state)| pi != a && state != 0 && state_of(pi) == 0)
                .take(HAND_OFF_TO);
            hand_offs.extend(takers.map(|&(_, pi, state)| vec![(a, 0), (pi, state)]));
        }
        let mut moves: Vec<Vec<(usize, usize)>> = (out.into_iter().take(STATE_TRIES))
            .map(|(_, pi, state)| vec![(pi, state)])
            .collect();
        moves.extend(hand_offs);
        let back: Vec<(usize, usize)> = (parts.iter().enumerate())
            .filter(|(pi, p)| {
                matches!(p.kind, PartKind::Piece { .. }) && p.states.len() > 1 && state_of(*pi) != 0
            })
            .map(|(pi, _)| (pi, 0))
            .collect();
        if back.len() > 1 {
            moves.push(back);
        }
        moves
    }

    /// One relaxation from `f` (left there), every stretch part's scales fitted but the
    /// `fixed` ones, the `forced` piece parts in the given states. Least squares with the
    /// local step of [`Solver::relaxed_targets`], Anderson-accelerated like pass 2 and, like
    /// it, taking only iterates that lower the objective; returns the objective reached.
    fn relax_from(
        &mut self,
        asm: &Assembly,
        families: &[Option<Family>],
        fixed: &[Option<[f64; 2]>],
        forced: &[(usize, usize)],
        f: &mut Vec<DVec2>,
    ) -> Result<f64, SolverError> {
        let parts = &asm.data().parts;
        let handles = asm.handles();
        let mut next = vec![DVec2::ZERO; f.len()];
        let mut report = FrameReport::default();
        let weight = self.config.handle_weight;
        self.work.start.valid = None;
        let mut anderson = std::mem::take(&mut self.anderson);
        anderson.start(ANDERSON);
        let mut scales: Vec<[f64; 2]> = fixed.iter().map(|x| x.unwrap_or([1.0, 1.0])).collect();
        let mut objective = self.relaxed_targets(parts, families, fixed, forced, f, &mut scales)
            + handle_term(handles, f, weight);
        let mut kept = self.work.targets.clone();
        for _ in 0..ITERATIONS {
            self.work.targets.clone_from(&kept);
            self.solve_global(f, &mut next, Pass::LeastSquares, &mut report)?;
            let mixed = anderson.mix(f, &mut next);
            let mut trial = scales.clone();
            let mut e = self.relaxed_targets(parts, families, fixed, forced, &next, &mut trial)
                + handle_term(handles, &next, weight);
            // NaN does not descend either
            let descends = |e: f64| e < objective;
            if mixed && !descends(e) {
                anderson.plain(&mut next);
                anderson.reset();
                trial.clone_from(&scales);
                e = self.relaxed_targets(parts, families, fixed, forced, &next, &mut trial)
                    + handle_term(handles, &next, weight);
            }
            if !descends(e) {
                break;
            }
            std::mem::swap(f, &mut next);
            scales = trial;
            kept.clone_from(&self.work.targets);
            let flat = objective - e <= FLAT * objective;
            objective = e;
            if flat {
                break;
            }
        }
        self.anderson = anderson;
        Ok(objective)
    }

    /// The relaxed local step at `f`: every part's rest edges (a stretch part's its two
    /// elements scaled to span `scales[part]` elements, fitted here, a piece part's its
    /// nearest rest state, or its `forced` one) and the rotation, fitted to its edges, that brings them nearest
    /// `f`'s, as edge targets into `work.targets`; returns their elastic energy. Each part's
    /// fit lowers its edges' energy, so with the global step the relaxation descends.
    fn relaxed_targets(
        &mut self,
        parts: &[Part],
        families: &[Option<Family>],
        fixed: &[Option<[f64; 2]>],
        forced: &[(usize, usize)],
        f: &[DVec2],
        scales: &mut [[f64; 2]],
    ) -> f64 {
        let nearest = self.relaxed_states(parts, forced, f);
        let edges = &self.pattern.edges;
        let targets = &mut self.work.targets;
        targets.clear();
        let mut elastic = 0.0;
        let mut k = 0;
        while k < edges.len() {
            let pi = edges[k].part as usize;
            let end = k + edges[k..]
                .iter()
                .take_while(|e| e.part as usize == pi)
                .count();
            let part = &parts[pi];
            let state = nearest
                .iter()
                .find(|s| s.0 == pi)
                .map_or(part.active, |s| s.1);
            let rest_of = |j: usize| part.states.get(j).map_or(&[][..], |s| &s.positions[..]);
            let edge = |rest: &[DVec2], e: &super::global::EdgeSlot| {
                let [a, b] = e.local.map(|i| i as usize);
                match (rest.get(a), rest.get(b)) {
                    (Some(&a), Some(&b)) => a - b,
                    _ => DVec2::ZERO,
                }
            };
            let posed: Vec<DVec2> = (k..end)
                .map(|j| {
                    let (x, y) = edges[j].ends();
                    f[x] - f[y]
                })
                .collect();
            let rest = match &families[pi] {
                // rest edges affine in the two elements' scales
                Some(family) => Rest {
                    base: (k..end).map(|j| edge(&family.p0, &edges[j])).collect(),
                    a: (k..end).map(|j| edge(&family.qa, &edges[j])).collect(),
                    b: (k..end).map(|j| edge(&family.qb, &edges[j])).collect(),
                    bounds: family.bounds,
                },
                None => Rest {
                    base: (k..end).map(|j| edge(rest_of(state), &edges[j])).collect(),
                    a: Vec::new(),
                    b: Vec::new(),
                    bounds: [SHORTEST, f64::INFINITY],
                },
            };
            let (r, sc) = rest.fit(&posed, scales[pi], fixed[pi].is_some());
            scales[pi] = sc;
            for (i, q) in posed.iter().enumerate() {
                let t = r.rotate(rest.at(i, sc));
                elastic += (t - *q).length_squared();
                targets.push(t);
            }
            k = end;
        }
        elastic
    }

    /// The piece parts whose state in the relaxation is not their active one: the `forced`
    /// ones (part, state), and those with alternative rest states whose nearest state at `f`
    /// is not (the local step's judgement, without hysteresis).
    fn relaxed_states(
        &self,
        parts: &[Part],
        forced: &[(usize, usize)],
        f: &[DVec2],
    ) -> Vec<(usize, usize)> {
        let how = local::Switching {
            hysteresis: 0.0,
            stretch: &[],
            shared: Some(&self.work.vertex_parts),
        };
        (parts.iter().enumerate())
            .filter(|(_, p)| matches!(p.kind, PartKind::Piece { .. }) && p.states.len() > 1)
            .filter_map(|(pi, part)| {
                if let Some(&(_, state)) = forced.iter().find(|x| x.0 == pi) {
                    return (state != part.active).then_some((pi, state));
                }
                let j = local::judge(pi, part, f, how);
                let best = (0..j.distances.len())
                    .min_by(|&a, &b| j.distances[a].total_cmp(&j.distances[b]))?;
                (best != part.active && j.distances[best] < j.distances[part.active])
                    .then_some((pi, best))
            })
            .collect()
    }
}

/// A part's rest edges in the relaxation: `base + sa a + sb b` (a stretch part, its two
/// elements' scales `sa`, `sb`), or `base` (`a`, `b` empty).
struct Rest {
    base: Vec<DVec2>,
    a: Vec<DVec2>,
    b: Vec<DVec2>,
    /// The least and most scale of an element.
    bounds: [f64; 2],
}

impl Rest {
    fn at(&self, i: usize, s: [f64; 2]) -> DVec2 {
        if self.a.is_empty() {
            self.base[i]
        } else {
            self.base[i] + self.a[i] * s[0] + self.b[i] * s[1]
        }
    }

    /// The rotation and scales that bring the rest edges nearest `posed` (least squares),
    /// by alternating the two fits a few times from `s` (scales within `bounds`); with
    /// `fixed`, the rotation for the scales `s`.
    fn fit(&self, posed: &[DVec2], mut s: [f64; 2], fixed: bool) -> (DVec2, [f64; 2]) {
        let rotation = |s: [f64; 2]| {
            let (mut dot, mut cross) = (0.0, 0.0);
            for (i, q) in posed.iter().enumerate() {
                let p = self.at(i, s);
                dot += p.dot(*q);
                cross += p.perp_dot(*q);
            }
            let len = (dot * dot + cross * cross).sqrt();
            if len > 1e-300 && len.is_finite() {
                DVec2::new(dot / len, cross / len)
            } else {
                DVec2::X
            }
        };
        let mut r = rotation(s);
        if self.a.is_empty() || fixed {
            return (r, s);
        }
        for _ in 0..4 {
            // the 2 x 2 normal equations of the scales with the rotation fixed
            let (mut aa, mut ab, mut bb, mut ra, mut rb) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for (i, q) in posed.iter().enumerate() {
                let (da, db) = (r.rotate(self.a[i]), r.rotate(self.b[i]));
                let left = *q - r.rotate(self.base[i]);
                aa += da.length_squared();
                ab += da.dot(db);
                bb += db.length_squared();
                ra += da.dot(left);
                rb += db.dot(left);
            }
            let det = aa * bb - ab * ab;
            if det > 1e-300 * (aa * bb).max(1e-300) && det.is_finite() {
                let sa = (ra * bb - rb * ab) / det;
                let sb = (aa * rb - ab * ra) / det;
                let [lo, hi] = self.bounds;
                s = [sa.clamp(lo, hi), sb.clamp(lo, hi)];
            }
            r = rotation(s);
        }
        (r, s)
    }
}

/// Piece parts and the states the relaxation holds them in, `(part, state)`.
type States = Vec<(usize, usize)>;

/// Piece states the relaxation was run with, and its relaxed pose.
type Assigned = (States, Vec<DVec2>);

/// What [`Solver::round_counts`] decides: every chain's count (`None`: left as it is), and
/// the last round's relaxed pose.
type Rounded = (Vec<Option<usize>>, Vec<DVec2>);

/// Rounds of [`Solver::relaxed_piece_states`]: each keeps at most one piece part's state.
const STATE_ROUNDS: usize = 3;

/// Bent piece parts that hand their turn to another in a round of
/// [`Solver::relaxed_piece_states`], and the straight parts' states each is handed to.
const HAND_OFF_FROM: usize = 2;
const HAND_OFF_TO: usize = 6;

/// Alternative piece states [`Solver::relaxed_piece_states`] relaxes with in a round.
const STATE_TRIES: usize = 4;

/// Past differences the relaxation's Anderson acceleration mixes.
const ANDERSON: usize = 3;

/// The least and most scale of an element of a stretch `part`'s chain in the relaxation:
/// at least [`SHORTEST`] and `min / count`, at most `max / count`, so that the relaxed
/// chain stays within its rule's bounds. Without them a loop of free hubs relaxed into a rest
/// configuration that needs a chain shorter than its `min` (a hexagon pulled out and back:
/// sides of 3.49, 0.51 and 3.49 elements where the rule allows 2, 2 and 2 only). Not the
/// least for a chain whose ends are closer than its `min` elements in a row (its chord in
/// `lengths`, this frame's [`ChainLength`]s, measured where pass 1
/// started: the displayed pose, since the relaxation runs only while the handles stay put):
/// no rest configuration keeps it above its `min`, and a chain held from shrinking buckles in
/// the relaxation too, its wavy elements read long (71 thin bricks, `min 71`, pushed to 0.2
/// of their length were proposed 152).
fn scale_bounds(asm: &Assembly, part: &Part, lengths: &[Option<ChainLength>]) -> [f64; 2] {
    let PartKind::Stretch { chain, .. } = part.kind else {
        return [SHORTEST, f64::INFINITY];
    };
    let data = asm.data();
    let Some(rule) = (data.chains.get(chain)).and_then(|c| asm.grammar().stretch_rules.get(c.rule))
    else {
        return [SHORTEST, f64::INFINITY];
    };
    let count = data.chains[chain].instances.len().max(1) as f64;
    let fits_min =
        (lengths.get(chain).and_then(Option::as_ref)).is_none_or(|l| l.chord >= rule.min as f64);
    let lo = if fits_min {
        (rule.min as f64 / count).clamp(SHORTEST, 1.0)
    } else {
        SHORTEST
    };
    let hi = rule
        .max
        .map_or(f64::INFINITY, |m| (m as f64 / count).max(1.0));
    [lo, hi]
}

/// Per part, the scales of its two elements when its chain is decided (`decided[chain]`:
/// its count): every element the same length, so that the chain's elements span that many,
/// but a held element at its own.
fn fixed_scales(asm: &Assembly, decided: &[Option<usize>], held: &[u64]) -> Vec<Option<[f64; 2]>> {
    let data = asm.data();
    let scale_of: Vec<Option<f64>> = (data.chains.iter().zip(decided))
        .map(|(c, d)| {
            let want = (*d)? as f64;
            let kept = c
                .instances
                .iter()
                .filter(|&&i| held.contains(&data.instances[i].id))
                .count();
            let free = c.instances.len() - kept;
            (free > 0).then(|| ((want - kept as f64) / free as f64).max(SHORTEST))
        })
        .collect();
    (data.parts.iter())
        .map(|part| {
            let PartKind::Stretch { chain, first } = part.kind else {
                return None;
            };
            let s = scale_of.get(chain).copied().flatten()?;
            let c = &data.chains[chain];
            let of = |k: usize| {
                let held = c
                    .instances
                    .get(k)
                    .is_some_and(|&i| held.contains(&data.instances[i].id));
                if held { 1.0 } else { s }
            };
            Some([of(first), of(first + 1)])
        })
        .collect()
}

/// Every chain's relaxed length at `f`.
fn relaxed_lengths(asm: &Assembly, families: &[Option<Family>], f: &[DVec2]) -> Vec<Relaxed> {
    let data = asm.data();
    let grammar = asm.grammar();
    let mut out: Vec<Relaxed> = (data.chains.iter().enumerate())
        .map(|(chain, c)| {
            let rule = grammar.stretch_rules.get(c.rule);
            Relaxed {
                chain,
                count: c.instances.len(),
                length: 0.0,
                element: 0.0,
                parts: Vec::new(),
                min: rule.map_or(usize::MAX, |r| r.min),
                max: rule.and_then(|r| r.max),
            }
        })
        .collect();
    for (part, family) in data.parts.iter().zip(families) {
        let (PartKind::Stretch { chain, first }, Some(family)) = (part.kind, family) else {
            continue;
        };
        let Some(r) = out.get_mut(chain) else {
            continue;
        };
        let [a, b] = family.lengths(part, f);
        r.element = family.ends.element;
        r.length += a;
        if first + 2 == r.count {
            r.length += b;
        }
        r.parts.push((first, a + b));
    }
    out.retain(|r| !r.parts.is_empty() && r.length.is_finite() && r.min != usize::MAX);
    out
}

/// A chain whose relaxed length is within this of a whole count is decided in the round
/// that measured it ([`Solver::relax`]).
const DECIDED: f64 = 0.1;
