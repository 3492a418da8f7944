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

use std::time::{Duration, Instant};

use clay_dsl::compiled::{Part, PartKind, STRETCH_TWO};
use glam::DVec2;

use super::clock::out_of_time;
use super::global_step::Pass;
use super::local::{self, StretchEnds};
use super::pass2::handle_term;
use super::report::{FrameReport, Proposal, SolverError};
use super::rounding::{Relaxed, decide_run, runs};
use super::state::Solver;
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
    /// what it proposes (empty when it changes nothing), two alternatives. Its chains'
    /// lengths are rounded in rounds: each round relaxes with the chains decided so far held
    /// at their counts, then decides the chains whose lengths are nearly whole (within
    /// [`DECIDED`] of a count) and the one nearest a whole count (with the chains in series
    /// with it: `rounding.rs`), so that a change the relaxation spreads over chains in series
    /// or round a loop ends whole in one of them rather than split and lost; and the first
    /// round's lengths each rounded on their own (a loop that only closes evenly).
    pub(super) fn relax(
        &mut self,
        asm: &Assembly,
        warm: &[DVec2],
        deadline: Option<Instant>,
    ) -> Result<Vec<Proposal>, SolverError> {
        let data = asm.data();
        let families: Vec<Option<Family>> = data.parts.iter().map(Family::of).collect();
        let held = held_elements(asm);
        let hysteresis = self.config.hysteresis;
        let mut f = warm.to_vec();
        let mut decided: Vec<Option<usize>> = vec![None; data.chains.len()];
        let series = runs(asm.grammar(), data);
        // the first relaxation's lengths each rounded on their own: the other alternative
        let mut at_once: Option<(Vec<Option<usize>>, Vec<DVec2>)> = None;
        loop {
            let fixed = fixed_scales(asm, &decided, &held);
            self.relax_from(asm, &families, &fixed, &mut f, deadline)?;
            if f.iter().any(|p| !p.is_finite()) {
                return Ok(Vec::new());
            }
            let lengths = relaxed_lengths(asm, &families, &f);
            if at_once.is_none() {
                let mut each = vec![None; data.chains.len()];
                for r in &lengths {
                    each[r.chain] = Some(r.decide(hysteresis));
                }
                at_once = Some((each, f.clone()));
            }
            let open: Vec<&Relaxed> = lengths
                .iter()
                .filter(|r| decided[r.chain].is_none())
                .collect();
            let Some(nearest) = open.iter().map(|r| r.doubt()).min_by(f64::total_cmp) else {
                break;
            };
            for r in &open {
                if decided[r.chain].is_some() || r.doubt() > DECIDED.max(nearest) {
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
            if out_of_time(deadline, Duration::ZERO) {
                break;
            }
        }
        let mut alternatives: Vec<Proposal> = Vec::new();
        for (decided, f) in [Some((decided, f)), at_once].into_iter().flatten() {
            let lengths = relaxed_lengths(asm, &families, &f);
            let counts: Vec<(usize, usize, usize)> = (lengths.iter())
                .filter_map(|r| decided[r.chain].and_then(|want| r.towards(want)))
                .collect();
            let p = Proposal {
                counts,
                states: self.relaxed_states(&data.parts, &f),
                pose: f,
            };
            if !p.is_empty()
                && !alternatives
                    .iter()
                    .any(|q| q.counts == p.counts && q.states == p.states)
            {
                alternatives.push(p);
            }
        }
        Ok(alternatives)
    }

    /// One relaxation from `f` (left there), every stretch part's scales fitted but the
    /// `fixed` ones. Least squares with the local step of [`Solver::relaxed_targets`],
    /// Anderson-accelerated like pass 2 and, like it, taking only iterates that lower the
    /// objective.
    fn relax_from(
        &mut self,
        asm: &Assembly,
        families: &[Option<Family>],
        fixed: &[Option<[f64; 2]>],
        f: &mut Vec<DVec2>,
        deadline: Option<Instant>,
    ) -> Result<(), SolverError> {
        let parts = &asm.data().parts;
        let handles = asm.handles();
        let mut next = vec![DVec2::ZERO; f.len()];
        let mut report = FrameReport::default();
        let weight = self.config.handle_weight;
        self.work.start.valid = None;
        let mut anderson = std::mem::take(&mut self.anderson);
        anderson.start(ANDERSON);
        let mut scales: Vec<[f64; 2]> = fixed.iter().map(|x| x.unwrap_or([1.0, 1.0])).collect();
        let mut objective = self.relaxed_targets(parts, families, fixed, f, &mut scales)
            + handle_term(handles, f, weight);
        let mut kept = self.work.targets.clone();
        let mut last = Duration::ZERO;
        for _ in 0..ITERATIONS {
            if out_of_time(deadline, last) {
                break;
            }
            let start = Instant::now();
            self.work.targets.clone_from(&kept);
            self.solve_global(f, &mut next, Pass::LeastSquares, &mut report)?;
            let mixed = anderson.mix(f, &mut next);
            let mut trial = scales.clone();
            let mut e = self.relaxed_targets(parts, families, fixed, &next, &mut trial)
                + handle_term(handles, &next, weight);
            // NaN does not descend either
            let descends = |e: f64| e < objective;
            if mixed && !descends(e) {
                anderson.plain(&mut next);
                anderson.reset();
                trial.clone_from(&scales);
                e = self.relaxed_targets(parts, families, fixed, &next, &mut trial)
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
            last = start.elapsed();
            if flat {
                break;
            }
        }
        self.anderson = anderson;
        Ok(())
    }

    /// The relaxed local step at `f`: every part's rest edges (a stretch part's its two
    /// elements scaled to span `scales[part]` elements, fitted here, a piece part's its
    /// nearest rest state) and the rotation, fitted to its edges, that brings them nearest
    /// `f`'s, as edge targets into `work.targets`; returns their elastic energy. Each part's
    /// fit lowers its edges' energy, so with the global step the relaxation descends.
    fn relaxed_targets(
        &mut self,
        parts: &[Part],
        families: &[Option<Family>],
        fixed: &[Option<[f64; 2]>],
        f: &[DVec2],
        scales: &mut [[f64; 2]],
    ) -> f64 {
        let nearest = self.relaxed_states(parts, f);
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
                },
                None => Rest {
                    base: (k..end).map(|j| edge(rest_of(state), &edges[j])).collect(),
                    a: Vec::new(),
                    b: Vec::new(),
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

    /// The piece parts with alternative rest states whose nearest state at `f` is not their
    /// active one (the local step's judgement, without hysteresis).
    fn relaxed_states(&self, parts: &[Part], f: &[DVec2]) -> Vec<(usize, usize)> {
        let how = local::Switching {
            hysteresis: 0.0,
            stretch: &[],
            shared: Some(&self.work.vertex_parts),
        };
        (parts.iter().enumerate())
            .filter(|(_, p)| matches!(p.kind, PartKind::Piece { .. }) && p.states.len() > 1)
            .filter_map(|(pi, part)| {
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
    /// by alternating the two fits a few times from `s` (scales at least [`SHORTEST`]); with
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
                s = [sa.max(SHORTEST), sb.max(SHORTEST)];
            }
            r = rotation(s);
        }
        (r, s)
    }
}

/// Past differences the relaxation's Anderson acceleration mixes.
const ANDERSON: usize = 3;

/// The stable ids of the instances the handles hold.
fn held_elements(asm: &Assembly) -> Vec<u64> {
    (asm.handles().iter())
        .filter_map(|h| h.held.as_ref().map(|x| x.id))
        .collect()
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
