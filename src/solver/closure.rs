//! Counts that close (`relax.rs`, `docs/solver.md`): the straight chains round a loop, or
//! along a path between two held pieces through free ones, rest only at counts whose lengths
//! close it. In the relaxed pose every piece between the chains is rigid and every straight
//! chain runs along its direction, so a change of counts moves the pieces beyond a chain along
//! that direction, and each loop of the piece graph (the held pieces one ground) stays closed
//! only when its chains' changes add up to nothing: a linear condition on the counts. The
//! relaxation stops at one point of the family of lengths that close (the one nearest the
//! pose: a pentagon of free hubs at sides 5, 1.76 and 5 where 3, 3 and 3 close), which
//! rounding each length cannot leave; the counts here are the whole numbers that close best,
//! found by enumerating the lattice of counts in the ellipsoid of the closing misfit.

use faer::{Mat, Side};
use glam::DVec2;

use super::loops::PieceGraph;
use super::rounding::Relaxed;
use super::turns::chain_is_straight;
use crate::assembly::Assembly;

/// The weight (per element squared, against the misfit in element lengths squared) that
/// keeps the counts near the relaxed lengths: an exact fit ten elements from them weighs as
/// much as a misfit of a tenth of an element.
const NEAR: f64 = 1e-4;

/// The most lattice points [`closest`] visits before it gives up.
const VISITS: usize = 200_000;

/// The whole counts that close the loops of the piece graph best, against the counts
/// the chains have ([`closing`]).
pub(super) struct Closing {
    /// `(chain, first, count)` changes, as the relaxation proposes them (empty: the counts
    /// the chains have close best).
    pub(super) changes: Vec<(usize, usize, usize)>,
    /// The loops' misfit (metres squared) with those counts, and with the chains' own.
    pub(super) misfit: f64,
    pub(super) now: f64,
    /// The shortest element's length (metres) of the chains counted.
    pub(super) shortest: f64,
}

impl Closing {
    /// Whether counts whose loops' misfit is `misfit` close better than the chains' own by
    /// the hysteresis margin in elements (paper 4.3, as a chain's count from its length): a
    /// shortest element's `hysteresis` nearer, so that a handle moved by less than that from
    /// a rest configuration changes no count.
    pub(super) fn better(&self, misfit: f64, hysteresis: f64) -> bool {
        misfit.sqrt() + hysteresis * self.shortest <= self.now.sqrt()
    }
}

/// The counts for the straight chains in loops of the piece graph (held pieces one ground)
/// that close them best. `lengths` are the relaxed chains' at `pose`. `None` without a loop
/// through a straight chain.
pub(super) fn closing(
    asm: &Assembly,
    pose: &[DVec2],
    lengths: &[Relaxed],
    held: &[u64],
) -> Option<Closing> {
    let (data, grammar) = (asm.data(), asm.grammar());
    let graph = PieceGraph::of(grammar, data, pose, held)?;
    let cycles = graph.cycles();
    // the variables: the relaxed straight chains some loop runs through
    let straight = |chain: usize| {
        (data.chains.get(chain))
            .and_then(|c| grammar.stretch_rules.get(c.rule))
            .is_some_and(chain_is_straight)
    };
    let vars: Vec<&Relaxed> = (lengths.iter())
        .filter(|r| graph.direction[r.chain].is_some() && straight(r.chain))
        .filter(|r| cycles.iter().any(|c| c.iter().any(|&(k, _)| k == r.chain)))
        .collect();
    if vars.is_empty() {
        return None;
    }
    let index = |chain: usize| vars.iter().position(|r| r.chain == chain);
    // the misfit's quadratic form over the counts, in metres squared
    let m = vars.len();
    let mut q = Mat::<f64>::zeros(m, m);
    for cycle in &cycles {
        for axis in 0..2 {
            let row: Vec<(usize, f64)> = (cycle.iter())
                .filter_map(|&(chain, sign)| {
                    let k = index(chain)?;
                    let d = graph.direction[chain]?;
                    let along = if axis == 0 { d.x } else { d.y };
                    Some((k, sign * along * vars[k].element))
                })
                .collect();
            for &(i, a) in &row {
                for &(j, b) in &row {
                    q[(i, j)] += a * b;
                }
            }
        }
    }
    let x: Vec<f64> = vars.iter().map(|r| r.length).collect();
    let misfit = |n: &[f64]| -> f64 {
        let mut s = 0.0;
        for i in 0..m {
            for j in 0..m {
                s += (n[i] - x[i]) * q[(i, j)] * (n[j] - x[j]);
            }
        }
        s.max(0.0)
    };
    let current: Vec<f64> = vars.iter().map(|r| r.count as f64).collect();
    let now = misfit(&current);
    let scale = vars.iter().map(|r| r.element).fold(0.0f64, f64::max);
    let mut qn = q.clone();
    for i in 0..m {
        qn[(i, i)] += NEAR * scale * scale;
    }
    let bounds: Vec<(i64, i64)> = (vars.iter())
        .map(|r| (r.min.max(1) as i64, r.max.map_or(i64::MAX, |v| v as i64)))
        .collect();
    let best = closest(&qn, &x, &bounds)?;
    let then: Vec<f64> = best.iter().map(|&n| n as f64).collect();
    Some(Closing {
        changes: (vars.iter().zip(&best))
            .filter_map(|(r, &n)| r.towards(n as usize))
            .collect(),
        misfit: misfit(&then),
        now,
        shortest: vars.iter().map(|r| r.element).fold(f64::INFINITY, f64::min),
    })
}

/// The whole numbers within `bounds` that minimise `(n - x)^T q (n - x)` for a positive
/// definite `q`: Schnorr and Euchner's enumeration over the Cholesky factor, from the last
/// coordinate to the first, pruned by the best found so far. `None` when `q` is not
/// positive definite or the search visits more than [`VISITS`] points.
fn closest(q: &Mat<f64>, x: &[f64], bounds: &[(i64, i64)]) -> Option<Vec<i64>> {
    let m = x.len();
    let l = q.llt(Side::Lower).ok()?.L().to_owned();
    // q = L L^T; (n - x)^T L L^T (n - x) = sum_j (sum_{i >= j} L[i][j] (n_i - x_i))^2
    let start: Vec<i64> = (x.iter().zip(bounds))
        .map(|(&v, &(lo, hi))| (v.round() as i64).clamp(lo, hi))
        .collect();
    let cost = |n: &[i64]| -> f64 {
        (0..m)
            .map(|j| {
                let s: f64 = (j..m).map(|i| l[(i, j)] * (n[i] as f64 - x[i])).sum();
                s * s
            })
            .sum()
    };
    let mut best = (cost(&start), start.clone());
    let mut n = start;
    let mut visits = 0usize;
    descend(&l, x, bounds, m, 0.0, &mut n, &mut best, &mut visits);
    (visits <= VISITS).then_some(best.1)
}

/// Coordinates `k..m` of `n` are fixed; tries coordinate `k - 1` outwards from its centre.
#[allow(clippy::too_many_arguments)]
fn descend(
    l: &Mat<f64>,
    x: &[f64],
    bounds: &[(i64, i64)],
    k: usize,
    partial: f64,
    n: &mut Vec<i64>,
    best: &mut (f64, Vec<i64>),
    visits: &mut usize,
) {
    if k == 0 {
        if partial < best.0 {
            *best = (partial, n.clone());
        }
        return;
    }
    let j = k - 1;
    let m = x.len();
    let rest: f64 = (k..m).map(|i| l[(i, j)] * (n[i] as f64 - x[i])).sum();
    let d = l[(j, j)];
    let centre = x[j] - rest / d;
    let (lo, hi) = bounds[j];
    let first = centre.round() as i64;
    for step in 0i64.. {
        let mut any = false;
        for v in [first + step, first - step] {
            if step == 0 && v != first {
                continue;
            }
            let s = d * (v as f64 - centre);
            if partial + s * s >= best.0 {
                continue;
            }
            any = true;
            if v < lo || v > hi {
                continue;
            }
            *visits += 1;
            if *visits > VISITS {
                return;
            }
            n[j] = v;
            descend(l, x, bounds, j, partial + s * s, n, best, visits);
        }
        if !any {
            break;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The quadratic form of a loop's misfit over chains of unit elements along `dirs`,
    /// plus the [`NEAR`] weight.
    fn form(dirs: &[DVec2]) -> Mat<f64> {
        let m = dirs.len();
        Mat::from_fn(m, m, |i, j| {
            dirs[i].dot(dirs[j]) + if i == j { NEAR } else { 0.0 }
        })
    }

    #[test]
    fn a_loop_of_three_free_sides_closes_at_the_whole_counts_of_its_family() {
        // a pentagon's last three sides (72-degree turns) between two held corners: 3 + t,
        // 3 - 2 cos 72 t, 3 + t close for every t; t = 2 is where a relaxation stopped
        let d = |k: f64| DVec2::from_angle((72.0 * k).to_radians());
        let q = form(&[d(2.0), d(3.0), d(4.0)]);
        let t = 2.0;
        let x = [3.0 + t, 3.0 - 2.0 * 72f64.to_radians().cos() * t, 3.0 + t];
        let bounds = [(2, i64::MAX); 3];
        assert_eq!(closest(&q, &x, &bounds), Some(vec![3, 3, 3]));
        // rounding each side gives 5, 2, 5, which does not close
        assert_eq!(x.map(|v| v.round()), [5.0, 2.0, 5.0]);
    }

    #[test]
    fn closest_keeps_the_bounds_and_rounds_what_nothing_ties() {
        let q = Mat::from_fn(2, 2, |i, j| if i == j { 1.0 } else { 0.0 });
        assert_eq!(
            closest(&q, &[3.4, 0.2], &[(1, 10), (1, 10)]),
            Some(vec![3, 1])
        );
        assert_eq!(
            closest(&q, &[12.6, 5.5001], &[(1, 10), (1, 10)]),
            Some(vec![10, 6])
        );
    }
}
