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

use super::rewrite::{
    PartsBefore, Rewrite, RuleEvent, RuleKind, finish, generated_name, remove_instances,
    transaction,
};
use crate::fit::{self, PointMap};

/// The most elements one rewrite inserts into a chain (and so one frame: a chain is rewritten
/// once a frame): growth stays linear in the frames, whatever the gesture.
pub const MAX_GROWTH: usize = 64;

/// Index of the `one`, `two` and `three` states in a stretch part.
pub const ONE: usize = clay_dsl::compiled::STRETCH_ONE;
pub const TWO: usize = clay_dsl::compiled::STRETCH_TWO;
pub const THREE: usize = clay_dsl::compiled::STRETCH_THREE;

/// Stretch parts that ask for a rewrite: `(part, (chain, first))` of the first part in
/// `three`, or in `one` when the chain is longer than the rule's `min`, at most one per chain.
/// O(parts).
pub fn candidates(grammar: &CompiledGrammar, data: &AssemblyData) -> Vec<(usize, (usize, usize))> {
    let mut seen = HashSet::new();
    let mut out = Vec::new();
    for (pi, part) in data.parts.iter().enumerate() {
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
            out.push((pi, (chain, first)));
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

/// Positions of the `count`-element rest layout for every piece vertex of every element, in
/// the frame of the part's state of that many elements' length (`one`, or `two` scaled along
/// the axis to `count` elements), and the map from that frame to the current pose of the two
/// old elements: each element's affine map, blended along the axis, or (`whole`) one affine
/// map fitted to both.
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
        refs: &[DVec2],
        count: usize,
        old: [&[usize]; 2],
        positions: &[DVec2],
        whole: bool,
    ) -> Option<Self> {
        let nv = old[0].len();
        let two = &states[TWO];
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
        if whole {
            // One map for the part, fitted to its two ends (the first element's `from` site,
            // the second's `to` site): the new elements evenly over its span, however unevenly
            // its two elements share it (pass 1 gathers a stretch into one of them).
            let ends = (layout.from_site.iter().map(|&v| (0u8, v)))
                .chain(layout.to_site.iter().map(|&v| (1u8, v)));
            let (mut from, mut to) = (Vec::new(), Vec::new());
            for (e, v) in ends {
                from.push(refs[layout.index(e, v)?]);
                to.push(positions[old[e as usize][v]]);
            }
            if from.len() >= 3 {
                let map = fit::affine(&from, &to);
                maps = [map, map];
            }
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
/// active state and the solver's claim ([`crate::solver::FrameReport::claims`]: how many
/// elements its span holds): `three` stretches it to that many elements (at least three),
/// `one` shrinks it to one, or a longer run of the chain when the claim is below one, keeping
/// an element in `held` (stable ids of the instances handles hold). Errors (data unchanged) when the part
/// does not exist, is in `two`, a shrink would go below `min` or remove a held element, or the
/// result fails the check.
pub fn rewrite_part(
    grammar: &CompiledGrammar,
    data: &mut AssemblyData,
    at: (usize, usize),
    elements: i64,
    held: &HashSet<u64>,
) -> Result<Rewrite, String> {
    let (chain, first) = at;
    let part = data
        .parts
        .iter()
        .find(|p| p.kind == PartKind::Stretch { chain, first })
        .ok_or_else(|| format!("no stretch part over chain {chain} element {first}"))?;
    match part.active {
        THREE => stretch(grammar, data, chain, first, elements.max(3) as usize),
        ONE => shrink(grammar, data, chain, first, elements.min(1), held),
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

/// Two elements -> `count` (at least three; no more than the rule's `max` lets the chain have,
/// nor more new ones than the chain has elements). The first and last keep their ids and
/// outer site vertices; the new ones go between them, each the variant that brings the
/// chain's histogram closest to the rule's frequencies.
// Long because: one transaction: every index it rewrites must change together.
pub fn stretch(
    grammar: &CompiledGrammar,
    data: &mut AssemblyData,
    chain: usize,
    first: usize,
    count: usize,
) -> Result<Rewrite, String> {
    let before = PartsBefore::record(data);
    transaction(grammar, data, |data| {
        let c = data.chains.get(chain).ok_or("no such chain")?;
        let rule = &grammar.stretch_rules[c.rule];
        let room = rule
            .max
            .map_or(usize::MAX, |max| max.saturating_sub(c.instances.len()));
        let room = room.min(clay_dsl::MAX_INSTANCES.saturating_sub(data.instances.len()));
        // at most doubling the chain, and at most MAX_GROWTH elements, in one rewrite: a hand
        // thrown a kilometre away fills the length over many frames, each of them bounded, and
        // a chain cannot double itself frame after frame into the millions (issue 47: a wall's
        // end dragged by 1e9 m ran to the million-instance cap)
        let inserted = count
            .saturating_sub(2)
            .clamp(1, c.instances.len().clamp(1, MAX_GROWTH))
            .min(room);
        if inserted == 0 {
            return Err(format!("chain {chain} is at the rule's maximum"));
        }
        let count = inserted + 2;
        let (ia, ib) = element_pair(c, chain, first)?;
        let states =
            part_states(data, chain, first).ok_or("the stretch part has no three states")?;
        let layout = Layout::new(grammar, rule);
        let (va, vb) = (
            data.instances[ia].vertices.clone(),
            data.instances[ib].vertices.clone(),
        );
        // `two` scaled along the axis to `count` elements: `inserted` steps of `three - two`
        let refs: Vec<DVec2> = states[TWO]
            .iter()
            .zip(&states[THREE])
            .map(|(&two, &three)| two + (three - two) * inserted as f64)
            .collect();
        let place = Placement::new(
            &layout,
            &states,
            &refs,
            count,
            [&va, &vb],
            &data.positions,
            true,
        )
        .ok_or("the stretch rule's part does not describe an axis")?;
        let mut pieces = chain_pieces(data, c);
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
        // B: same vertices; everything but its `to` site re-laid as the last element.
        for (v, &g) in vb.iter().enumerate() {
            if !layout.to_site.contains(&v) {
                data.positions[g] = place.place(place.rest[count - 1][v]);
            }
        }
        data.instances[ia].vertices = a_vertices;
        let a_to = InstanceSite {
            instance: ia,
            site: rule.to,
        };
        let b_from = InstanceSite {
            instance: ib,
            site: rule.from,
        };
        let di = find_dock(data, a_to, b_from).ok_or("the two elements are not docked")?;
        // The new elements 1..count-1: each `from` is the previous element's `to`, the last
        // one's `to` is B's `from` (the old shared vertices), the rest fresh.
        let mut previous = (ia, data.instances[ia].vertices.clone());
        let mut names = Vec::new();
        let mut ids = Vec::new();
        for j in 1..count - 1 {
            let mut vertices = vec![usize::MAX; nv];
            for (v, slot) in vertices.iter_mut().enumerate() {
                *slot = if let Some(i) = layout.from_site.iter().position(|&x| x == v) {
                    previous.1[layout.to_site[n - 1 - i]]
                } else if j == count - 2
                    && let Some(i) = layout.to_site.iter().position(|&x| x == v)
                {
                    vb[layout.from_site[n - 1 - i]]
                } else {
                    fresh(data, place.place(place.rest[j][v]))
                };
            }
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
            pieces.push(piece);
            let id = data.next_id;
            data.next_id += 1;
            let ni = data.instances.len();
            let name = generated_name(&data.instances[ia].name, id);
            data.instances.push(Instance {
                id,
                name: name.clone(),
                piece,
                vertices: vertices.clone(),
                state: 0,
            });
            let dock = Dock {
                a: InstanceSite {
                    instance: previous.0,
                    site: rule.to,
                },
                b: InstanceSite {
                    instance: ni,
                    site: rule.from,
                },
            };
            if j == 1 {
                data.docks[di] = dock;
            } else {
                data.docks.push(dock);
            }
            data.chains[chain].instances.insert(first + j, ni);
            previous = (ni, vertices);
            names.push(name);
            ids.push(id);
        }
        data.docks.push(Dock {
            a: InstanceSite {
                instance: previous.0,
                site: rule.to,
            },
            b: b_from,
        });
        data.chains[chain].trend = 1;
        let (ida, idb) = (data.instances[ia].id, data.instances[ib].id);
        let mut touched: HashSet<u64> = ids.iter().copied().collect();
        touched.extend([ida, idb]);
        let total = data.chains[chain].instances.len();
        let middle = data.chains[chain].instances[first + count / 2];
        let mid = &data.instances[middle].vertices;
        let at = mid.iter().map(|&v| data.positions[v]).sum::<DVec2>() / mid.len().max(1) as f64;
        let piece_name = &grammar.pieces[data.instances[middle].piece].name;
        let event = RuleEvent {
            kind: RuleKind::Stretch,
            frame: 0,
            at,
            instances: [ida, idb].into_iter().chain(ids).collect(),
            detail: format!(
                "`{}` and `{}` became {} {piece_name}s: {} inserted; {} has {total} now",
                data.instances[ia].name,
                data.instances[ib].name,
                number_word(count),
                listed(&names),
                chain_name(&data.instances[ia].name, chain),
            ),
        };
        Ok(finish(grammar, data, &before, &touched, event))
    })
}

/// `three` for 3, and so on up to ten; digits beyond.
fn number_word(n: usize) -> String {
    const WORDS: [&str; 11] = [
        "zero", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten",
    ];
    WORDS
        .get(n)
        .map_or_else(|| n.to_string(), |w| (*w).to_string())
}

/// Names in backticks, the first few and a count of the rest.
fn listed(names: &[String]) -> String {
    const SHOWN: usize = 3;
    let mut out: Vec<String> = names.iter().take(SHOWN).map(|n| format!("`{n}`")).collect();
    if names.len() > SHOWN {
        out.push(format!("and {} more", names.len() - SHOWN));
    }
    out.join(", ")
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

/// Two elements -> one, or a longer run of the chain -> one when the part was squeezed
/// shorter than one element (`elements`, the solver's claim, says how many elements its span
/// holds, 1 or fewer; the run loses `2 - elements` of them, never going below the rule's
/// `min`). The run grows from the part's two elements to both sides, never over a held
/// element; the element kept (the held one, else by the rule's frequencies, the first on
/// ties) takes the run's outer sites, the others are removed with their unshared vertices.
// Long because: one transaction: every index it rewrites must change together.
pub fn shrink(
    grammar: &CompiledGrammar,
    data: &mut AssemblyData,
    chain: usize,
    first: usize,
    elements: i64,
    held: &HashSet<u64>,
) -> Result<Rewrite, String> {
    let before = PartsBefore::record(data);
    transaction(grammar, data, |data| {
        let c = data.chains.get(chain).ok_or("no such chain")?;
        let rule = &grammar.stretch_rules[c.rule];
        let len = c.instances.len();
        if len <= rule.min.max(1) {
            return Err(format!(
                "chain {chain} has {len} elements, the rule's minimum"
            ));
        }
        element_pair(c, chain, first)?;
        let is_held = |k: usize| held.contains(&data.instances[c.instances[k]].id);
        if is_held(first) && is_held(first + 1) {
            return Err("both elements are held; not shrinking".into());
        }
        let remove = (2 - elements.min(1)).clamp(1, (len - rule.min.max(1)) as i64) as usize;
        // the run [lo, hi]: the part's two elements, then one more at a time on either side
        let (mut lo, mut hi) = (first, first + 1);
        let mut side = 0;
        while hi - lo < remove {
            let can_left = lo > 0 && !is_held(lo - 1) && !(is_held(lo) && is_held(hi));
            let can_right = hi + 1 < len && !is_held(hi + 1) && !(is_held(lo) && is_held(hi));
            match (can_left, can_right) {
                (true, true) if side == 0 => lo -= 1,
                (true, true) => hi += 1,
                (true, false) => lo -= 1,
                (false, true) => hi += 1,
                (false, false) => break,
            }
            side ^= 1;
        }
        let run: Vec<usize> = c.instances[lo..=hi].to_vec();
        let states = part_states(data, chain, first).ok_or("the stretch part has no one state")?;
        let layout = Layout::new(grammar, rule);
        let (ia, ib) = (run[0], run[run.len() - 1]);
        let (va, vb) = (
            data.instances[ia].vertices.clone(),
            data.instances[ib].vertices.clone(),
        );
        let place = Placement::new(
            &layout,
            &states,
            &states[ONE],
            1,
            [&va, &vb],
            &data.positions,
            false,
        )
        .ok_or("the stretch rule's part does not describe an axis")?;
        let pieces = chain_pieces(data, c);
        let keep = match run
            .iter()
            .position(|&i| held.contains(&data.instances[i].id))
        {
            Some(k) => run[k],
            None => {
                // the first element whose removal of the others fits the frequencies best
                let error = |keep: usize| {
                    let mut rest = pieces.clone();
                    for &i in &run {
                        if i != keep
                            && let Some(at) =
                                rest.iter().position(|&p| p == data.instances[i].piece)
                        {
                            rest.remove(at);
                        }
                    }
                    histogram_error(rule, &rest, (rule.piece, 0))
                };
                let mut best = run[0];
                for &i in &run[1..] {
                    if error(i) < error(best) - 1e-12 {
                        best = i;
                    }
                }
                best
            }
        };
        let gone: Vec<usize> = run.iter().copied().filter(|&i| i != keep).collect();
        // Only the chain docks may touch a removed element: anything else would be lost.
        let site_ok = |s: InstanceSite| {
            !gone.contains(&s.instance) || s.site == rule.from || s.site == rule.to
        };
        if data.docks.iter().any(|d| !site_ok(d.a) || !site_ok(d.b)) {
            return Err("an element to remove is docked at a side site; not shrinking".into());
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
        // the docks inside the run go; its outer docks (the run's first `from`, its last
        // `to`) now belong to the kept element
        let inside = |s: InstanceSite| run.contains(&s.instance);
        data.docks.retain(|d| !(inside(d.a) && inside(d.b)));
        for d in &mut data.docks {
            for s in [&mut d.a, &mut d.b] {
                if gone.contains(&s.instance) {
                    s.instance = keep;
                }
            }
        }
        let kid = data.instances[keep].id;
        let gone_ids: Vec<u64> = gone.iter().map(|&i| data.instances[i].id).collect();
        let gone_names: Vec<String> = gone
            .iter()
            .map(|&i| data.instances[i].name.clone())
            .collect();
        let kept_name = data.instances[keep].name.clone();
        let run_names: Vec<String> = run
            .iter()
            .map(|&i| data.instances[i].name.clone())
            .collect();
        data.chains[chain].trend = -1;
        remove_instances(data, &gone.iter().copied().collect());
        let mut touched: HashSet<u64> = gone_ids.iter().copied().collect();
        touched.insert(kid);
        let ki = data
            .instances
            .iter()
            .position(|i| i.id == kid)
            .ok_or("kept element vanished")?;
        let kv = &data.instances[ki].vertices;
        let at = kv.iter().map(|&v| data.positions[v]).sum::<DVec2>() / kv.len().max(1) as f64;
        let count = data.chains.get(chain).map_or(0, |c| c.instances.len());
        let became = if run_names.len() == 2 {
            format!("`{}` and `{}`", run_names[0], run_names[1])
        } else {
            format!(
                "{} {}s from `{}` to `{}`",
                number_word(run_names.len()),
                grammar.pieces[data.instances[ki].piece].name,
                run_names[0],
                run_names[run_names.len() - 1]
            )
        };
        let event = RuleEvent {
            kind: RuleKind::Shrink,
            frame: 0,
            at,
            instances: std::iter::once(kid).chain(gone_ids).collect(),
            detail: format!(
                "{became} became one {}: {} removed; {} has {count} now",
                grammar.pieces[data.instances[ki].piece].name,
                listed(&gone_names),
                chain_name(&kept_name, chain),
            ),
        };
        Ok(finish(grammar, data, &before, &touched, event))
    })
}
