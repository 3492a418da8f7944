//! Stretch and shrink (paper 5.1, Fig. 7b): a two-element stretch part that pass 1 left in its
//! `three` state has its two elements replaced by three spanning the same stretch; one left in
//! `one` has them replaced by one (never below the rule's `min`). The new elements are laid
//! into the current deformed pose, and the parts around the change are rebuilt in `two`.
//!
//! Laying out: the part's `two` state gives the rest layout of elements 0 and 1 and the axis
//! step `d` between them; element 2 is element 1 moved by `d`. That 3-element (or, for a
//! shrink, 1-element) layout spans the same axial range as the `three` (`one`) state, so each
//! new vertex is mapped by the affine maps fitted from the `three` (`one`) state of each old
//! element to its current pose, blended by the vertex's axial position. The chain's outer site
//! vertices (shared with neighbours) keep their global index and position.

use std::collections::HashSet;

use clay_dsl::compiled::{
    AssemblyData, Chain, CompiledGrammar, Dock, Instance, InstanceSite, PartKind, StretchRule,
};
use glam::DVec2;

use super::{
    PartsBefore, Rewrite, RuleEvent, RuleKind, finish, generated_name, remove_instances,
    transaction,
};
use crate::fit::{self, PointMap};

/// Index of the `one`, `two` and `three` states in a stretch part.
pub const ONE: usize = clay_dsl::compiled::STRETCH_ONE;
pub const TWO: usize = clay_dsl::compiled::STRETCH_TWO;
pub const THREE: usize = clay_dsl::compiled::STRETCH_THREE;

/// Stretch parts that ask for a rewrite: `(chain, first)` of the first part in `three`, or in
/// `one` when the chain is longer than the rule's `min`, at most one per chain. O(parts).
pub fn candidates(grammar: &CompiledGrammar, data: &AssemblyData) -> Vec<(usize, usize)> {
    let mut seen = HashSet::new();
    let mut out = Vec::new();
    for part in &data.parts {
        let PartKind::Stretch { chain, first } = part.kind else {
            continue;
        };
        let Some(c) = data.chains.get(chain) else {
            continue;
        };
        let Some(rule) = grammar.stretch_rules.get(c.rule) else {
            continue;
        };
        let wants = match part.active {
            THREE => true,
            ONE => c.instances.len() > rule.min.max(1),
            _ => false,
        };
        if wants && seen.insert(chain) {
            out.push((chain, first));
        }
    }
    out
}

/// The variants of a rule with their target frequencies (the rule's own piece when none).
fn variants(rule: &StretchRule) -> Vec<(usize, f64)> {
    if rule.variants.is_empty() {
        vec![(rule.piece, 1.0)]
    } else {
        rule.variants
            .iter()
            .map(|v| (v.piece, v.frequency))
            .collect()
    }
}

/// Squared distance of a chain's variant histogram (with `delta` applied) to the rule's
/// frequencies.
fn histogram_error(rule: &StretchRule, pieces: &[usize], delta: (usize, i64)) -> f64 {
    let vs = variants(rule);
    let total = pieces.len() as i64 + delta.1;
    if total <= 0 {
        return f64::MAX;
    }
    vs.iter()
        .map(|&(p, f)| {
            let mut count = pieces.iter().filter(|&&q| q == p).count() as i64;
            if p == delta.0 {
                count += delta.1;
            }
            let share = count as f64 / total as f64;
            (share - f) * (share - f)
        })
        .sum()
}

/// The geometry of a rule's two-element part, in terms of piece vertices.
struct Layout<'a> {
    rule: &'a StretchRule,
    from_site: &'a [usize],
    to_site: &'a [usize],
}

impl<'a> Layout<'a> {
    fn new(grammar: &'a CompiledGrammar, rule: &'a StretchRule) -> Self {
        let piece = &grammar.pieces[rule.piece];
        Self {
            rule,
            from_site: &piece.sites[rule.from].vertices,
            to_site: &piece.sites[rule.to].vertices,
        }
    }

    /// Index into the part's vertices of piece vertex `v` of element `e` (element 1's `from`
    /// vertices are element 0's `to` vertices).
    fn index(&self, e: u8, v: usize) -> Option<usize> {
        if e == 1
            && let Some(i) = self.from_site.iter().position(|&x| x == v)
        {
            let n = self.from_site.len();
            return self.index(0, *self.to_site.get(n - 1 - i)?);
        }
        self.rule
            .part
            .vertices
            .iter()
            .position(|ev| ev.element == e && ev.vertex == v)
    }

    fn site_centre(&self, state: &[DVec2], e: u8, site: &[usize]) -> Option<DVec2> {
        let mut sum = DVec2::ZERO;
        for &v in site {
            sum += state[self.index(e, v)?];
        }
        Some(sum / site.len().max(1) as f64)
    }
}

/// Positions of the `count`-element rest layout (count 1 or 3) for every piece vertex of
/// every element, in the frame of the part's `one`/`three` state, and the blended affine map
/// from that frame to the current pose of the two old elements.
struct Placement {
    /// `rest[j][v]`: rest position of vertex v of new element j.
    rest: Vec<Vec<DVec2>>,
    maps: [PointMap; 2],
    axis: DVec2,
    /// Axial coordinate of each old element's centroid in the reference state.
    centres: [f64; 2],
}

impl Placement {
    fn new(
        layout: &Layout,
        states: &[Vec<DVec2>],
        reference: usize,
        count: usize,
        old: [&[usize]; 2],
        positions: &[DVec2],
    ) -> Option<Self> {
        let nv = old[0].len();
        let two = &states[TWO];
        let refs = &states[reference];
        // Axis step from element 0 to element 1 in the `two` state.
        let mut d = DVec2::ZERO;
        let mut k = 0.0;
        for v in 0..nv {
            if layout.from_site.contains(&v) {
                continue;
            }
            d += two[layout.index(1, v)?] - two[layout.index(0, v)?];
            k += 1.0;
        }
        if k == 0.0 {
            return None;
        }
        d /= k;
        let axis = d.try_normalize()?;
        // The scaled states keep element 0's `from` centre fixed; re-base the layout there.
        let shift = layout.site_centre(refs, 0, layout.from_site)?
            - layout.site_centre(two, 0, layout.from_site)?;
        let rest = (0..count)
            .map(|j| {
                (0..nv)
                    .map(|v| {
                        let base = two[layout.index(0, v)?];
                        Some(base + d * j as f64 + shift)
                    })
                    .collect::<Option<Vec<DVec2>>>()
            })
            .collect::<Option<Vec<_>>>()?;
        let mut maps = [PointMap::IDENTITY; 2];
        let mut centres = [0.0; 2];
        for e in 0..2u8 {
            let from: Vec<DVec2> = (0..nv)
                .map(|v| layout.index(e, v).map(|i| refs[i]))
                .collect::<Option<_>>()?;
            let to: Vec<DVec2> = old[e as usize].iter().map(|&g| positions[g]).collect();
            maps[e as usize] = fit::affine(&from, &to);
            centres[e as usize] =
                from.iter().map(|p| p.dot(axis)).sum::<f64>() / from.len().max(1) as f64;
        }
        Some(Self {
            rest,
            maps,
            axis,
            centres,
        })
    }

    /// Current-pose position of a rest point: the two elements' maps blended along the axis.
    fn place(&self, q: DVec2) -> DVec2 {
        let span = self.centres[1] - self.centres[0];
        let w = if span.abs() > 1e-12 {
            ((q.dot(self.axis) - self.centres[0]) / span).clamp(0.0, 1.0)
        } else {
            0.5
        };
        self.maps[0].apply(q) * (1.0 - w) + self.maps[1].apply(q) * w
    }
}

/// Rewrites the stretch part over elements `first`, `first + 1` of `chain` according to its
/// active state (`three`: stretch, `one`: shrink). Errors (data unchanged) when the part does
/// not exist, is in `two`, a shrink would go below `min`, or the result fails the check.
pub fn rewrite_part(
    grammar: &CompiledGrammar,
    data: &mut AssemblyData,
    chain: usize,
    first: usize,
) -> Result<Rewrite, String> {
    let part = data
        .parts
        .iter()
        .find(|p| p.kind == PartKind::Stretch { chain, first })
        .ok_or_else(|| format!("no stretch part over chain {chain} element {first}"))?;
    match part.active {
        THREE => stretch(grammar, data, chain, first),
        ONE => shrink(grammar, data, chain, first),
        s => Err(format!(
            "chain {chain} element {first}: part is in state {s}, nothing to do"
        )),
    }
}

fn part_states(data: &AssemblyData, chain: usize, first: usize) -> Option<Vec<Vec<DVec2>>> {
    let part = data
        .parts
        .iter()
        .find(|p| p.kind == PartKind::Stretch { chain, first })?;
    if part.states.len() < 3 {
        return None;
    }
    Some(part.states.iter().map(|s| s.positions.clone()).collect())
}

fn find_dock(data: &AssemblyData, x: InstanceSite, y: InstanceSite) -> Option<usize> {
    data.docks
        .iter()
        .position(|d| (d.a == x && d.b == y) || (d.a == y && d.b == x))
}

/// Two elements -> three. The first and last keep their ids and outer site vertices; the new
/// one goes in the middle and is the variant that brings the chain's histogram closest to
/// the rule's frequencies.
// Long because: one transaction: every index it rewrites must change together.
pub fn stretch(
    grammar: &CompiledGrammar,
    data: &mut AssemblyData,
    chain: usize,
    first: usize,
) -> Result<Rewrite, String> {
    let before = PartsBefore::record(data);
    transaction(grammar, data, |data| {
        let c = data.chains.get(chain).ok_or("no such chain")?;
        let rule = &grammar.stretch_rules[c.rule];
        let (ia, ib) = element_pair(c, chain, first)?;
        let states =
            part_states(data, chain, first).ok_or("the stretch part has no three states")?;
        let layout = Layout::new(grammar, rule);
        let (va, vb) = (
            data.instances[ia].vertices.clone(),
            data.instances[ib].vertices.clone(),
        );
        let place = Placement::new(&layout, &states, THREE, 3, [&va, &vb], &data.positions)
            .ok_or("the stretch rule's part does not describe an axis")?;
        let pieces = chain_pieces(data, c);
        let piece = variants(rule)
            .into_iter()
            .map(|(p, _)| p)
            .min_by(|&p, &q| {
                histogram_error(rule, &pieces, (p, 1)).total_cmp(&histogram_error(
                    rule,
                    &pieces,
                    (q, 1),
                ))
            })
            .unwrap_or(rule.piece);
        let n = layout.from_site.len();
        let nv = va.len();
        let fresh = |data: &mut AssemblyData, p: DVec2| {
            data.positions.push(p);
            data.positions.len() - 1
        };
        // A: new `to` vertices; everything but its `from` site re-laid as element 0.
        let mut a_vertices = va.clone();
        for &v in layout.to_site {
            a_vertices[v] = fresh(data, place.place(place.rest[0][v]));
        }
        for (v, &g) in a_vertices.iter().enumerate() {
            if !layout.from_site.contains(&v) {
                data.positions[g] = place.place(place.rest[0][v]);
            }
        }
        // N: from = A's new to, to = B's from (the old shared vertices), the rest fresh.
        let mut n_vertices = vec![usize::MAX; nv];
        for (v, slot) in n_vertices.iter_mut().enumerate() {
            *slot = if let Some(i) = layout.from_site.iter().position(|&x| x == v) {
                a_vertices[layout.to_site[n - 1 - i]]
            } else if let Some(i) = layout.to_site.iter().position(|&x| x == v) {
                vb[layout.from_site[n - 1 - i]]
            } else {
                fresh(data, place.place(place.rest[1][v]))
            };
        }
        // B: same vertices; everything but its `to` site re-laid as element 2.
        for (v, &g) in vb.iter().enumerate() {
            if !layout.to_site.contains(&v) {
                data.positions[g] = place.place(place.rest[2][v]);
            }
        }
        data.instances[ia].vertices = a_vertices;
        let id = data.next_id;
        data.next_id += 1;
        let ni = data.instances.len();
        let name = generated_name(&data.instances[ia].name, id);
        data.instances.push(Instance {
            id,
            name: name.clone(),
            piece,
            vertices: n_vertices,
            state: 0,
        });
        let a_to = InstanceSite {
            instance: ia,
            site: rule.to,
        };
        let b_from = InstanceSite {
            instance: ib,
            site: rule.from,
        };
        let di = find_dock(data, a_to, b_from).ok_or("the two elements are not docked")?;
        let n_to = InstanceSite {
            instance: ni,
            site: rule.to,
        };
        let n_from = InstanceSite {
            instance: ni,
            site: rule.from,
        };
        data.docks[di] = Dock { a: n_to, b: b_from };
        data.docks.push(Dock { a: a_to, b: n_from });
        data.chains[chain].instances.insert(first + 1, ni);
        let (ida, idb) = (data.instances[ia].id, data.instances[ib].id);
        let touched: HashSet<u64> = [ida, idb, id].into();
        let count = data.chains[chain].instances.len();
        let mid = &data.instances[ni].vertices;
        let at = mid.iter().map(|&v| data.positions[v]).sum::<DVec2>() / mid.len().max(1) as f64;
        let event = RuleEvent {
            kind: RuleKind::Stretch,
            frame: 0,
            at,
            instances: vec![ida, idb, id],
            detail: format!(
                "`{}` and `{}` became three {}s: `{name}` inserted; {} has {count} now",
                data.instances[ia].name,
                data.instances[ib].name,
                grammar.pieces[piece].name,
                chain_name(&data.instances[ia].name, chain),
            ),
        };
        Ok(finish(grammar, data, &before, &touched, event))
    })
}

/// What the user calls a chain in messages: the model's name for it (`wall` of `wall[3]` or
/// `wall#12`), or
/// "chain 2" for elements without one.
fn chain_name(element: &str, chain: usize) -> String {
    // `wall[3]` from the model, `wall#12` for an element a rule inserted.
    match element.split_once(['[', '#']) {
        Some((name, _)) if !name.is_empty() => format!("`{name}`"),
        _ => format!("chain {chain}"),
    }
}

/// Instance indices of elements `first` and `first + 1` of a chain: the stretch part that
/// stretch and shrink rewrite.
fn element_pair(c: &Chain, chain: usize, first: usize) -> Result<(usize, usize), String> {
    match (c.instances.get(first), c.instances.get(first + 1)) {
        (Some(&a), Some(&b)) => Ok((a, b)),
        _ => Err(format!(
            "chain {chain} has no elements {first}, {}",
            first + 1
        )),
    }
}

/// The piece of every element of a chain, in order: the histogram the variants are matched to.
fn chain_pieces(data: &AssemblyData, c: &Chain) -> Vec<usize> {
    c.instances
        .iter()
        .map(|&i| data.instances[i].piece)
        .collect()
}

/// Two elements -> one. The one kept (by the rule's frequencies; the first on ties) takes the
/// outer sites of both; the other is removed with its unshared vertices.
pub fn shrink(
    grammar: &CompiledGrammar,
    data: &mut AssemblyData,
    chain: usize,
    first: usize,
) -> Result<Rewrite, String> {
    let before = PartsBefore::record(data);
    transaction(grammar, data, |data| {
        let c = data.chains.get(chain).ok_or("no such chain")?;
        let rule = &grammar.stretch_rules[c.rule];
        if c.instances.len() <= rule.min.max(1) {
            return Err(format!(
                "chain {chain} has {} elements, the rule's minimum",
                c.instances.len()
            ));
        }
        let (ia, ib) = element_pair(c, chain, first)?;
        let states = part_states(data, chain, first).ok_or("the stretch part has no one state")?;
        let layout = Layout::new(grammar, rule);
        let (va, vb) = (
            data.instances[ia].vertices.clone(),
            data.instances[ib].vertices.clone(),
        );
        let place = Placement::new(&layout, &states, ONE, 1, [&va, &vb], &data.positions)
            .ok_or("the stretch rule's part does not describe an axis")?;
        let pieces = chain_pieces(data, c);
        let (pa, pb) = (data.instances[ia].piece, data.instances[ib].piece);
        let keep_b = histogram_error(rule, &pieces, (pa, -1))
            < histogram_error(rule, &pieces, (pb, -1)) - 1e-12;
        let (keep, gone) = if keep_b { (ib, ia) } else { (ia, ib) };
        // Only the chain docks may touch the removed element: anything else would be lost.
        let a_to = InstanceSite {
            instance: ia,
            site: rule.to,
        };
        let b_from = InstanceSite {
            instance: ib,
            site: rule.from,
        };
        let inner = find_dock(data, a_to, b_from).ok_or("the two elements are not docked")?;
        let gone_site_ok =
            |s: InstanceSite| s.instance != gone || s.site == rule.from || s.site == rule.to;
        if data
            .docks
            .iter()
            .any(|d| !gone_site_ok(d.a) || !gone_site_ok(d.b))
        {
            return Err("the element to remove is docked at a side site; not shrinking".into());
        }
        let mut k_vertices = data.instances[keep].vertices.clone();
        for (v, slot) in k_vertices.iter_mut().enumerate() {
            if let Some(i) = layout.from_site.iter().position(|&x| x == v) {
                *slot = va[layout.from_site[i]];
            } else if let Some(i) = layout.to_site.iter().position(|&x| x == v) {
                *slot = vb[layout.to_site[i]];
            } else {
                data.positions[*slot] = place.place(place.rest[0][v]);
            }
        }
        data.instances[keep].vertices = k_vertices;
        data.docks.remove(inner);
        // The removed element's outer dock now belongs to the kept one.
        for d in &mut data.docks {
            for s in [&mut d.a, &mut d.b] {
                if s.instance == gone {
                    s.instance = keep;
                }
            }
        }
        let (kid, gid) = (data.instances[keep].id, data.instances[gone].id);
        let gone_name = data.instances[gone].name.clone();
        remove_instances(data, &HashSet::from([gone]));
        let touched: HashSet<u64> = [kid, gid].into();
        let ki = data
            .instances
            .iter()
            .position(|i| i.id == kid)
            .ok_or("kept element vanished")?;
        let kv = &data.instances[ki].vertices;
        let at = kv.iter().map(|&v| data.positions[v]).sum::<DVec2>() / kv.len().max(1) as f64;
        let count = data.chains.get(chain).map_or(0, |c| c.instances.len());
        let event = RuleEvent {
            kind: RuleKind::Shrink,
            frame: 0,
            at,
            instances: vec![kid, gid],
            detail: format!(
                "`{}` and `{gone_name}` became one {}: `{gone_name}` removed; {} has {count} now",
                data.instances[ki].name,
                grammar.pieces[data.instances[ki].piece].name,
                chain_name(&data.instances[ki].name, chain),
            ),
        };
        Ok(finish(grammar, data, &before, &touched, event))
    })
}
