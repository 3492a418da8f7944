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

use clay_dsl::compiled::{AssemblyData, CompiledGrammar, InstanceSite};
use faer::{Mat, Side};
use glam::DVec2;

use super::rounding::{Relaxed, chain_of};
use super::turns::chain_is_straight;
use crate::assembly::Assembly;

/// The weight (per element squared, against the misfit in element lengths squared) that
/// keeps the counts near the relaxed lengths: an exact fit ten elements from them weighs as
/// much as a misfit of a tenth of an element.
const NEAR: f64 = 1e-4;

/// The most lattice points [`closest`] visits before it gives up.
const VISITS: usize = 200_000;

/// A loop's closing condition: the chains in it and the signs they run round it with.
type Cycle = Vec<(usize, f64)>;

/// Counts for the straight chains in loops of the piece graph (held pieces one ground) that
/// close them best, when they close better than the chains' own counts by the hysteresis
/// margin (paper 4.3): `(chain, first, count)` changes, as the relaxation proposes them.
/// `lengths` are the relaxed chains' at `pose`.
pub(super) fn counts_that_close(
    asm: &Assembly,
    pose: &[DVec2],
    lengths: &[Relaxed],
    held: &[u64],
    hysteresis: f64,
) -> Vec<(usize, usize, usize)> {
    let (data, grammar) = (asm.data(), asm.grammar());
    let Some(graph) = PieceGraph::of(grammar, data, pose, held) else {
        return Vec::new();
    };
    let cycles = graph.cycles();
    // the variables: the relaxed straight chains some loop runs through
    let vars: Vec<&Relaxed> = (lengths.iter())
        .filter(|r| graph.direction[r.chain].is_some())
        .filter(|r| cycles.iter().any(|c| c.iter().any(|&(k, _)| k == r.chain)))
        .collect();
    if vars.is_empty() {
        return Vec::new();
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
    let Some(best) = closest(&qn, &x, &bounds) else {
        return Vec::new();
    };
    let then: Vec<f64> = best.iter().map(|&n| n as f64).collect();
    if best.iter().zip(&vars).all(|(&n, r)| n as usize == r.count)
        || misfit(&then) >= (1.0 - hysteresis) * now
    {
        return Vec::new();
    }
    (vars.iter().zip(&best))
        .filter_map(|(r, &n)| r.towards(n as usize))
        .collect()
}

/// A step round a loop of free pieces ([`free_loops`]).
#[derive(Debug, PartialEq)]
pub(super) enum LoopStep {
    /// A chain, `1.0` run from its first element to its last, `-1.0` the other way.
    Chain(usize, f64),
    /// A piece, entered at one site and left at another.
    Piece {
        instance: usize,
        enter: usize,
        leave: usize,
    },
}

/// The independent loops of the piece graph that no held piece is on (a ring of hubs and
/// arcs let go): each as its chains and the pieces between them, each entered and left at
/// its sites. Its turns add up to a whole turn, which is what its turning chains' counts
/// must match together (`turns.rs`). A loop through a body of several pieces docked
/// together is left out (no one site enters it).
pub(super) fn free_loops(asm: &Assembly, pose: &[DVec2], held: &[u64]) -> Vec<Vec<LoopStep>> {
    let Some(graph) = PieceGraph::of(asm.grammar(), asm.data(), pose, held) else {
        return Vec::new();
    };
    let mut loops = Vec::new();
    'cycles: for cycle in graph.cycles() {
        // per body on the loop: the site it is arrived at, the one it is left by
        let mut at: std::collections::HashMap<usize, [Option<Option<InstanceSite>>; 2]> =
            Default::default();
        for &(c, sign) in &cycle {
            let Some((near, far)) = graph.ends[c] else {
                continue 'cycles;
            };
            let [n, f] = graph.docked[c];
            let (leave, arrive) = if sign > 0.0 {
                ((near, n), (far, f))
            } else {
                ((far, f), (near, n))
            };
            at.entry(leave.0).or_default()[1] = Some(leave.1);
            at.entry(arrive.0).or_default()[0] = Some(arrive.1);
        }
        if at.contains_key(&graph.ground) {
            continue;
        }
        let mut steps: Vec<LoopStep> = (cycle.iter())
            .map(|&(c, s)| LoopStep::Chain(c, s))
            .collect();
        for sites in at.values() {
            match *sites {
                // two chains docked end to end: no piece between them
                [Some(None), Some(None)] => {}
                [Some(Some(a)), Some(Some(b))] if a.instance == b.instance => {
                    steps.push(LoopStep::Piece {
                        instance: a.instance,
                        enter: a.site,
                        leave: b.site,
                    });
                }
                _ => continue 'cycles,
            }
        }
        loops.push(steps);
    }
    loops
}

/// The pieces between chains as rigid bodies (the held ones a single ground) and the chains
/// as the edges between them, with each straight chain's direction in the pose.
struct PieceGraph {
    /// Per chain: its end bodies (near, far); `None` for a chain a handle holds (its ends are
    /// each tied to the ground).
    ends: Vec<Option<(usize, usize)>>,
    /// Per chain: its unit direction in the pose when it is straight and no handle holds
    /// one of its elements (the chains whose counts may change here).
    direction: Vec<Option<DVec2>>,
    /// Per chain: the piece site its near and far ends dock to (`None`: another chain's end,
    /// or nothing).
    docked: Vec<[Option<InstanceSite>; 2]>,
    bodies: usize,
    ground: usize,
}

impl PieceGraph {
    fn of(
        grammar: &CompiledGrammar,
        data: &AssemblyData,
        pose: &[DVec2],
        held: &[u64],
    ) -> Option<Self> {
        let n = data.instances.len();
        let chains = data.chains.len();
        let chain_of = chain_of(data);
        // union-find elements: the instances, the ground (n), each chain's near and far end
        // (n + 1 + 2c, n + 2 + 2c: two chains docked end to end meet at a body of their own)
        let ground = n;
        let end_node = |c: usize, far: bool| n + 1 + 2 * c + usize::from(far);
        let mut parent: Vec<usize> = (0..n + 1 + 2 * chains).collect();
        let mut partner = std::collections::HashMap::new();
        for d in &data.docks {
            partner.insert(d.a, d.b);
            partner.insert(d.b, d.a);
            let (a, b) = (d.a.instance, d.b.instance);
            if chain_of.get(a)?.is_none() && chain_of.get(b)?.is_none() {
                union(&mut parent, a, b);
            }
        }
        for (i, inst) in data.instances.iter().enumerate() {
            if chain_of[i].is_none() && held.contains(&inst.id) {
                union(&mut parent, i, ground);
            }
        }
        // each chain's end sites, and which chain end each is
        let mut sites = Vec::with_capacity(chains);
        let mut end_at = std::collections::HashMap::new();
        for (c, chain) in data.chains.iter().enumerate() {
            let rule = grammar.stretch_rules.get(chain.rule)?;
            let (&first, &last) = (chain.instances.first()?, chain.instances.last()?);
            let near = InstanceSite {
                instance: first,
                site: rule.from,
            };
            let far = InstanceSite {
                instance: last,
                site: rule.to,
            };
            end_at.insert(near, end_node(c, false));
            end_at.insert(far, end_node(c, true));
            sites.push((near, far));
        }
        let mut direction = Vec::with_capacity(chains);
        let mut docked = vec![[None; 2]; chains];
        for (c, chain) in data.chains.iter().enumerate() {
            let rule = grammar.stretch_rules.get(chain.rule)?;
            let piece = grammar.pieces.get(rule.piece)?;
            let site_centre = |at: InstanceSite| -> Option<DVec2> {
                let inst = data.instances.get(at.instance)?;
                let vs = &piece.sites.get(at.site)?.vertices;
                let sum: Option<DVec2> = (vs.iter())
                    .map(|&v| pose.get(*inst.vertices.get(v)?).copied())
                    .sum();
                Some(sum? / vs.len().max(1) as f64)
            };
            let (near, far) = sites[c];
            for (end, far_end) in [(near, false), (far, true)] {
                let Some(other) = partner.get(&end) else {
                    continue;
                };
                let to = match end_at.get(other) {
                    Some(&e) => e,
                    None if chain_of.get(other.instance)?.is_none() => {
                        docked[c][usize::from(far_end)] = Some(*other);
                        other.instance
                    }
                    None => continue,
                };
                union(&mut parent, end_node(c, far_end), to);
            }
            let holds_one = (chain.instances.iter()).any(|&i| held.contains(&data.instances[i].id));
            if holds_one {
                // a held element is ground: the chain ties both its ends to it
                union(&mut parent, end_node(c, false), ground);
                union(&mut parent, end_node(c, true), ground);
            }
            let d = site_centre(far)? - site_centre(near)?;
            let straight = chain_is_straight(rule) && !holds_one && d.length() > 0.0;
            direction.push(straight.then(|| d.normalize()));
        }
        let ends = (0..chains)
            .map(|c| {
                let held = direction[c].is_none()
                    && (data.chains[c].instances.iter())
                        .any(|&i| held.contains(&data.instances[i].id));
                let (a, b) = (
                    root(&mut parent, end_node(c, false)),
                    root(&mut parent, end_node(c, true)),
                );
                (!held).then_some((a, b))
            })
            .collect();
        Some(Self {
            ends,
            direction,
            docked,
            bodies: parent.len(),
            ground: root(&mut parent, ground),
        })
    }

    /// Each independent loop's closing condition: a spanning forest of the bodies from the
    /// ground (then from any body), and for each chain outside it the loop it closes.
    fn cycles(&self) -> Vec<Cycle> {
        let mut adjacent: Vec<Vec<(usize, usize, f64)>> = vec![Vec::new(); self.bodies];
        for (c, e) in self.ends.iter().enumerate() {
            if let Some((a, b)) = *e {
                adjacent[a].push((c, b, 1.0));
                adjacent[b].push((c, a, -1.0));
            }
        }
        // the path from each body's tree root to it, as signed chains
        let mut path: Vec<Option<Cycle>> = vec![None; self.bodies];
        let mut tree = vec![false; self.ends.len()];
        let order = std::iter::once(self.ground).chain(0..self.bodies);
        for start in order {
            if path[start].is_some() || adjacent[start].is_empty() {
                continue;
            }
            path[start] = Some(Vec::new());
            let mut queue = std::collections::VecDeque::from([start]);
            while let Some(a) = queue.pop_front() {
                for &(c, b, sign) in &adjacent[a] {
                    if path[b].is_none() {
                        let mut p = path[a].clone().unwrap_or_default();
                        p.push((c, sign));
                        path[b] = Some(p);
                        tree[c] = true;
                        queue.push_back(b);
                    }
                }
            }
        }
        let mut cycles = Vec::new();
        for (c, e) in self.ends.iter().enumerate() {
            let Some((a, b)) = *e else { continue };
            if tree[c] {
                continue;
            }
            // root -> a, then the chain a -> b, then b -> root backwards
            let mut cycle: Cycle = path[a].clone().unwrap_or_default();
            cycle.push((c, 1.0));
            for &(k, sign) in path[b].iter().flatten() {
                cycle.push((k, -sign));
            }
            cycles.push(cancel(cycle));
        }
        cycles
    }
}

/// A loop's chains with the ones it runs along both ways dropped.
fn cancel(cycle: Cycle) -> Cycle {
    let mut out: Cycle = Vec::new();
    for (c, s) in cycle {
        match out.iter().position(|&(k, _)| k == c) {
            Some(i) => {
                out[i].1 += s;
            }
            None => out.push((c, s)),
        }
    }
    out.retain(|&(_, s)| s != 0.0);
    out
}

fn root(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

fn union(parent: &mut [usize], a: usize, b: usize) {
    let (a, b) = (root(parent, a), root(parent, b));
    if a != b {
        parent[a] = b;
    }
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
