//! How a relaxation's chain lengths become counts (`relax.rs`, `docs/solver.md`): each chain
//! its nearest count, by the paper's hysteresis in elements, and chains in series (docked end
//! to end, or through a piece straight between them) together: the counts whose lengths
//! add up nearest the run's relaxed length, since only the run's length is fixed and its
//! elements may be of several lengths (a wall of bricks and a wall of stones in a row).

use clay_dsl::compiled::{AssemblyData, CompiledGrammar, InstanceSite};

use crate::assembly::Assembly;

/// A chain's relaxed length (its elements' lengths summed, in elements) against its count.
pub(super) struct Relaxed {
    pub(super) chain: usize,
    pub(super) count: usize,
    pub(super) length: f64,
    /// An element's length at rest, in metres.
    pub(super) element: f64,
    /// Its parts, `(first, span in elements)`.
    pub(super) parts: Vec<(usize, f64)>,
    pub(super) min: usize,
    pub(super) max: Option<usize>,
}

impl Relaxed {
    /// The count its relaxed length decides: the nearest count within the rule's bounds
    /// when the length is nearer it than the chain's count by the `hysteresis` margin (paper
    /// 4.3, in elements), else its count.
    pub(super) fn decide(&self, hysteresis: f64) -> usize {
        let mut want = self.length.round().max(self.min.max(1) as f64) as usize;
        if let Some(max) = self.max {
            want = want.min(max);
        }
        let (now, then) = (self.length - self.count as f64, self.length - want as f64);
        if then.abs() < (1.0 - hysteresis) * now.abs() {
            want
        } else {
            self.count
        }
    }

    /// `(chain, first, want)`: the change to `want` elements, at the part whose relaxed span
    /// is furthest from two elements that way; `None` when `want` is its count.
    pub(super) fn towards(&self, want: usize) -> Option<(usize, usize, usize)> {
        if want == self.count {
            return None;
        }
        let grow = want > self.count;
        let key = |s: f64| if grow { s } else { -s };
        let first = (self.parts.iter())
            .max_by(|a, b| key(a.1).total_cmp(&key(b.1)))?
            .0;
        Some((self.chain, first, want))
    }

    /// How far its length is from a whole count (0 to 0.5).
    pub(super) fn doubt(&self) -> f64 {
        (self.length - self.length.round()).abs()
    }
}

/// The chains in series (more than one): chains docked end to end, directly or through a
/// piece with two docked sites facing opposite ways and no other rest state (a window in a
/// wall) that no handle holds (the instances of stable ids `held`): a held piece fixes where
/// the chains either side of it end, each side's length on its own.
pub(super) fn runs(
    grammar: &CompiledGrammar,
    data: &AssemblyData,
    held: &[u64],
) -> Vec<Vec<usize>> {
    let n = data.chains.len();
    let chain_of = chain_of(data);
    let mut partner: std::collections::HashMap<InstanceSite, InstanceSite> = Default::default();
    let mut docks_of = vec![0usize; data.instances.len()];
    for d in &data.docks {
        partner.insert(d.a, d.b);
        partner.insert(d.b, d.a);
        for s in [d.a, d.b] {
            if let Some(k) = docks_of.get_mut(s.instance) {
                *k += 1;
            }
        }
    }
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    for (c, chain) in data.chains.iter().enumerate() {
        let Some(rule) = grammar.stretch_rules.get(chain.rule) else {
            continue;
        };
        let ends = [
            chain.instances.first().map(|&i| InstanceSite {
                instance: i,
                site: rule.from,
            }),
            chain.instances.last().map(|&i| InstanceSite {
                instance: i,
                site: rule.to,
            }),
        ];
        for end in ends.into_iter().flatten() {
            let Some(&next) = partner.get(&end) else {
                continue;
            };
            let other = match chain_of.get(next.instance).copied().flatten() {
                Some(c2) => Some(c2),
                None => through(grammar, data, &partner, &docks_of, next)
                    .filter(|_| {
                        (data.instances.get(next.instance)).is_none_or(|i| !held.contains(&i.id))
                    })
                    .and_then(|s| chain_of.get(s.instance).copied().flatten()),
            };
            if let Some(c2) = other.filter(|&c2| c2 != c) {
                let (a, b) = (root(&mut parent, c), root(&mut parent, c2));
                parent[a] = b;
            }
        }
    }
    let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    for c in 0..n {
        let r = root(&mut parent, c);
        groups.entry(r).or_default().push(c);
    }
    groups.into_values().filter(|g| g.len() > 1).collect()
}

/// Across a piece with exactly two docked sites facing opposite ways and no other rest
/// state, entered at `at`: the site docked to its other one.
fn through(
    grammar: &CompiledGrammar,
    data: &AssemblyData,
    partner: &std::collections::HashMap<InstanceSite, InstanceSite>,
    docks_of: &[usize],
    at: InstanceSite,
) -> Option<InstanceSite> {
    if docks_of.get(at.instance) != Some(&2) {
        return None;
    }
    let piece = &grammar.pieces[data.instances.get(at.instance)?.piece];
    // a piece with other rest states may turn the run (a bendable piece)
    if piece.states.len() > 1 {
        return None;
    }
    let (k, other) = (0..piece.sites.len())
        .filter(|&k| k != at.site)
        .find_map(|k| {
            partner
                .get(&InstanceSite {
                    instance: at.instance,
                    site: k,
                })
                .map(|&o| (k, o))
        })?;
    let (u, v) = (
        piece.sites[at.site].out.normalize_or_zero(),
        piece.sites[k].out.normalize_or_zero(),
    );
    (u.dot(v) < -0.99).then_some(other)
}

/// The counts of a run of chains in series (`run`, their relaxed lengths): of the counts
/// within [`SPREAD`] of each one's nearest and within its rule's bounds, those whose lengths
/// add up nearest the run's relaxed length, the fewest elements changed among equals. When
/// none of those fits within [`CLOSE`] of its shortest element, every count that fits in the
/// run's length is searched, and the fewest changes within [`CLOSE`] of the best fit win:
/// elements of several lengths may fit a length only in a count far from the current ones (a
/// wall of 0.949 m bricks and 2.509 m windows: 18.577 m is 9 and 4, nothing near 14 and 2),
/// and nearly as well in others (0.78 m and 1.705 m elements: 16.615 m is 6 and 7 exactly, 17
/// and 2 to 5.5 cm, a strain the model keeps: generated pulled case 748). Kept only when that
/// misfit is below `(1 - hysteresis)` of the current counts' (paper 4.3). `None` for a run
/// too long to search (more than [`LONGEST_RUN`] chains).
pub(super) fn decide_run(run: &[&Relaxed], hysteresis: f64) -> Option<Vec<usize>> {
    if run.len() > LONGEST_RUN {
        return None;
    }
    let total: f64 = run.iter().map(|r| r.length * r.element).sum();
    let misfit = |counts: &[usize]| {
        let sum: f64 = run
            .iter()
            .zip(counts)
            .map(|(r, &n)| n as f64 * r.element)
            .sum();
        (sum - total).abs()
    };
    let allowed =
        |r: &Relaxed, n: i64| n >= r.min.max(1) as i64 && r.max.is_none_or(|m| n <= m as i64);
    let near: Vec<Vec<usize>> = run
        .iter()
        .map(|r| {
            let centre = r.length.round() as i64;
            ((centre - SPREAD)..=(centre + SPREAD))
                .filter(|&n| allowed(r, n))
                .map(|n| n as usize)
                .collect()
        })
        .collect();
    let current: Vec<usize> = run.iter().map(|r| r.count).collect();
    let close = CLOSE * run.iter().map(|r| r.element).fold(f64::INFINITY, f64::min);
    let (mut m, mut counts) = fewest_changes(&near, &current, &misfit, 1e-9)?;
    if m > close {
        let wide: Vec<Vec<usize>> = run
            .iter()
            .map(|r| {
                let most = (total / r.element).ceil().min(WIDEST as f64) as i64 + 1;
                (0..=most)
                    .filter(|&n| allowed(r, n))
                    .map(|n| n as usize)
                    .collect()
            })
            .collect();
        let size: f64 = wide.iter().map(|w| w.len() as f64).product();
        if size <= WIDEST as f64
            && let Some((mw, cw)) = fewest_changes(&wide, &current, &misfit, close)
            && mw < m
        {
            (m, counts) = (mw, cw);
        }
    }
    Some(if m < (1.0 - hysteresis) * misfit(&current) {
        counts
    } else {
        current
    })
}

/// Of every combination of one count from each of `ranges`: the fewest elements changed from
/// `current` among those whose `misfit` is within `tolerance` of the least (the least misfit
/// among those), and its misfit.
fn fewest_changes(
    ranges: &[Vec<usize>],
    current: &[usize],
    misfit: &dyn Fn(&[usize]) -> f64,
    tolerance: f64,
) -> Option<(f64, Vec<usize>)> {
    let changed = |counts: &[usize]| -> usize {
        counts
            .iter()
            .zip(current)
            .map(|(a, b)| a.abs_diff(*b))
            .sum()
    };
    let mut least = f64::INFINITY;
    let mut counts = vec![0; ranges.len()];
    product(ranges, 0, &mut counts, &mut |c| {
        least = least.min(misfit(c))
    });
    let mut best: Option<(usize, f64, Vec<usize>)> = None;
    product(ranges, 0, &mut counts, &mut |c| {
        let m = misfit(c);
        if m > least + tolerance {
            return;
        }
        let key = (changed(c), m);
        if best
            .as_ref()
            .is_none_or(|b| key.0 < b.0 || (key.0 == b.0 && key.1 < b.1))
        {
            best = Some((key.0, key.1, c.to_vec()));
        }
    });
    best.map(|(_, m, c)| (m, c))
}

/// Calls `each` with every combination of one value from each of `ranges`.
fn product(ranges: &[Vec<usize>], k: usize, counts: &mut [usize], each: &mut dyn FnMut(&[usize])) {
    if k == ranges.len() {
        each(counts);
        return;
    }
    for &n in &ranges[k] {
        counts[k] = n;
        product(ranges, k + 1, counts, each);
    }
}

/// How far from its nearest count each chain of a run is searched ([`decide_run`]).
const SPREAD: i64 = 3;

/// The longest run searched whole ((2 SPREAD + 1)^3 = 343 combinations near its counts).
const LONGEST_RUN: usize = 3;

/// A run's fit counts as exact within this fraction of its shortest element ([`decide_run`]):
/// once the counts are whole, the misfit stays in the model as strain. At a tenth of an
/// element, a run of 0.866 m and 2.132 m elements kept two and four for seven and two, 6.6 cm
/// off, at energy 1.3e-3 (generated round case 497), and one of 0.78 m and 1.705 m elements
/// took 17 and two, 5.5 cm off, for six and seven (pulled case 748).
const CLOSE: f64 = 1e-3;

/// The most combinations of counts [`decide_run`] searches across a run's whole length.
const WIDEST: usize = 100_000;

/// The chain each instance is an element of, by instance index (`None`: no chain's).
pub(super) fn chain_of(data: &AssemblyData) -> Vec<Option<usize>> {
    let mut chain_of = vec![None; data.instances.len()];
    for (c, chain) in data.chains.iter().enumerate() {
        for &i in &chain.instances {
            if let Some(slot) = chain_of.get_mut(i) {
                *slot = Some(c);
            }
        }
    }
    chain_of
}

/// The stable ids of the instances the handles hold.
pub(super) fn held_elements(asm: &Assembly) -> Vec<u64> {
    (asm.handles().iter())
        .filter_map(|h| h.held.as_ref().map(|x| x.id))
        .collect()
}
