//! Merging (paper 5.1, Fig. 7c): a free mover site that comes within a merge rule's distance
//! of a compatible site welds to it. Without a junction the two free sites simply share their
//! vertices from then on; with one, the target's instance is replaced by the junction piece
//! (rigidly fitted over it, taking over its docks by site name) and the mover docks with the
//! junction's stem. A merged connection is a dock like any other: only a cut undoes it.
//!
//! Two sites weld only when they face each other: the dot product of their current outward
//! directions ([`site_out`]) is at most [`FACING_DOT`], so a site within reach that faces the
//! same way or across (a street end passing alongside another street's side) does not weld.
//! Which side of the target the mover is on is not tested (see [`FACING_DOT`]).

use std::collections::HashSet;

use clay_dsl::compiled::{AssemblyData, CompiledGrammar, Dock, Instance, InstanceSite};
use glam::DVec2;

use super::proximity::SiteGrid;
use super::rewrite::{
    PartsBefore, Rewrite, RuleEvent, RuleKind, derive_chains, finish, generated_name,
    remove_instances, transaction,
};
use super::sites::{site_centre, site_out};
use crate::fit;

/// The most the dot product of two sites' current `out` directions may be for a merge to weld
/// them: -cos 45 degrees, so the two directions are within 45 degrees of exactly opposite
/// (head-on). Halfway between facing (-1) and perpendicular (0): a street end that runs along
/// another street's side, or has turned a quarter away from it, never welds, while a drag that
/// bends or turns the mover by less than 45 degrees still merges. The weld then snaps the two
/// sites together, turning each by at most the remaining angle, which the solver absorbs.
///
/// The mover need not be in front of the target (the offset between the centres is not
/// tested): within the merge distance, a mover that overshot its target in one frame of a fast
/// drag (the pieces overlapping by less than that distance) is still facing it and welds, so a
/// merge does not depend on the drag's speed; the weld itself puts the sites together.
pub const FACING_DOT: f64 = -std::f64::consts::FRAC_1_SQRT_2;

/// Whether two outward directions face each other closely enough to weld (see [`FACING_DOT`]).
pub fn facing(a: DVec2, b: DVec2) -> bool {
    a.dot(b) <= FACING_DOT
}

/// A merge the rules found: `mover` came within `distance` of `target`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MergeMatch {
    /// Index into the grammar's merge rules.
    pub rule: usize,
    pub mover: InstanceSite,
    pub target: InstanceSite,
    pub distance: f64,
}

fn docked_sites(data: &AssemblyData) -> HashSet<InstanceSite> {
    data.docks.iter().flat_map(|d| [d.a, d.b]).collect()
}

/// The closest mover/target pair over all merge rules, if any is within its rule's distance
/// and the two sites face each other ([`facing`]). O(instances + docks) to list the free
/// sites, then O(1) per free mover site (grid lookup). The rules call [`find_where`]; this
/// is for tests.
#[cfg(any(test, feature = "testing"))]
pub fn find(grammar: &CompiledGrammar, data: &AssemblyData) -> Option<MergeMatch> {
    find_where(grammar, data, |_, _| true)
}

/// [`find`] among the mover/target instance pairs (by stable id) that `accept` allows: the
/// rules keep a connection that was cut from welding again until its sides have parted.
pub fn find_where(
    grammar: &CompiledGrammar,
    data: &AssemblyData,
    accept_ids: impl Fn(u64, u64) -> bool,
) -> Option<MergeMatch> {
    search(grammar, data, accept_ids, true)
}

/// [`find_where`] whichever way the sites face: the closest pair within reach. The rules ask
/// this to tell when the sides of a cut have parted (moved beyond the merge distance); turning
/// a side away is no parting, so it does not weld again when turned back.
pub fn find_in_reach(
    grammar: &CompiledGrammar,
    data: &AssemblyData,
    accept_ids: impl Fn(u64, u64) -> bool,
) -> Option<MergeMatch> {
    search(grammar, data, accept_ids, false)
}

fn search(
    grammar: &CompiledGrammar,
    data: &AssemblyData,
    accept_ids: impl Fn(u64, u64) -> bool,
    face: bool,
) -> Option<MergeMatch> {
    if grammar.merge_rules.is_empty() {
        return None;
    }
    let docked = docked_sites(data);
    // Instances directly docked to each other: a street end never merges into its own
    // neighbour's side.
    let neighbours: HashSet<(usize, usize)> = data
        .docks
        .iter()
        .flat_map(|d| [(d.a.instance, d.b.instance), (d.b.instance, d.a.instance)])
        .collect();
    let mut best: Option<MergeMatch> = None;
    for (ri, rule) in grammar.merge_rules.iter().enumerate() {
        let (Some(mp), Some(tp)) = (
            grammar.pieces.get(rule.mover.piece),
            grammar.pieces.get(rule.target.piece),
        ) else {
            continue;
        };
        let (Some(ms), Some(ts)) = (
            mp.sites.get(rule.mover.site),
            tp.sites.get(rule.target.site),
        ) else {
            continue;
        };
        if !grammar.types_dock(ms.site_type, ts.site_type) || ms.vertices.len() != ts.vertices.len()
        {
            continue;
        }
        let distance = rule.distance(&grammar.solver);
        let mut grid = SiteGrid::new(distance);
        for (i, inst) in data.instances.iter().enumerate() {
            let s = InstanceSite {
                instance: i,
                site: rule.target.site,
            };
            if inst.piece == rule.target.piece
                && !docked.contains(&s)
                && let Some(c) = site_centre(grammar, data, s)
            {
                grid.insert(s, c);
            }
        }
        for (i, inst) in data.instances.iter().enumerate() {
            let m = InstanceSite {
                instance: i,
                site: rule.mover.site,
            };
            if inst.piece != rule.mover.piece || docked.contains(&m) {
                continue;
            }
            let Some(c) = site_centre(grammar, data, m) else {
                continue;
            };
            // A site whose direction is unknown (collapsed) faces nothing.
            let out = site_out(grammar, data, m);
            if face && out.is_none() {
                continue;
            }
            let accept = |t: InstanceSite| {
                t.instance != i
                    && !neighbours.contains(&(i, t.instance))
                    && accept_ids(inst.id, data.instances[t.instance].id)
                    && (!face
                        || out
                            .zip(site_out(grammar, data, t))
                            .is_some_and(|(a, b)| facing(a, b)))
            };
            if let Some((t, d)) = grid.nearest(c, distance, accept)
                && best.is_none_or(|b| d < b.distance)
            {
                best = Some(MergeMatch {
                    rule: ri,
                    mover: m,
                    target: t,
                    distance: d,
                });
            }
        }
    }
    best
}

/// Replaces global vertex `from[i]` by `to[i]` in every instance.
fn weld_vertices(data: &mut AssemblyData, from: &[usize], to: &[usize]) {
    for inst in &mut data.instances {
        for v in &mut inst.vertices {
            if let Some(i) = from.iter().position(|x| x == v) {
                *v = to[i];
            }
        }
    }
}

/// Appends an instance of `piece` placed over instance `old` and taking its place: the best
/// rigid fit of the new piece's sites to `old`'s sites of the same names places it; sites of
/// the same name (and size) reuse `old`'s global vertices, so `old`'s docks carry over by site
/// name (they are re-pointed here). Vertices of other sites are new. Fails if a dock of `old`
/// (other than `dropping`) has no same-named site on `piece`. Returns the new index; the
/// caller removes `old`.
pub(crate) fn take_over(
    grammar: &CompiledGrammar,
    data: &mut AssemblyData,
    old: usize,
    piece: usize,
) -> Result<usize, String> {
    let op = &grammar.pieces[data.instances[old].piece];
    let np = &grammar.pieces[piece];
    // Site correspondences by name and size.
    let pairs: Vec<(usize, usize)> = op
        .sites
        .iter()
        .enumerate()
        .filter_map(|(os, s)| {
            let ns = np.sites.iter().position(|t| t.name == s.name)?;
            (np.sites[ns].vertices.len() == s.vertices.len()).then_some((os, ns))
        })
        .collect();
    if pairs.is_empty() {
        return Err(format!(
            "`{}` shares no site name with `{}`; cannot place it over it",
            np.name, op.name
        ));
    }
    let old_vertices = data.instances[old].vertices.clone();
    let mut from = Vec::new();
    let mut to = Vec::new();
    for &(os, ns) in &pairs {
        for (k, &nv) in np.sites[ns].vertices.iter().enumerate() {
            from.push(np.states[0].positions[nv]);
            to.push(data.positions[old_vertices[op.sites[os].vertices[k]]]);
        }
    }
    let map = fit::rigid(&from, &to);
    let mut vertices = vec![usize::MAX; np.vertices.len()];
    for &(os, ns) in &pairs {
        for (k, &nv) in np.sites[ns].vertices.iter().enumerate() {
            vertices[nv] = old_vertices[op.sites[os].vertices[k]];
        }
    }
    for (v, slot) in vertices.iter_mut().enumerate() {
        if *slot == usize::MAX {
            data.positions.push(map.apply(np.states[0].positions[v]));
            *slot = data.positions.len() - 1;
        }
    }
    let id = data.next_id;
    data.next_id += 1;
    let ni = data.instances.len();
    data.instances.push(Instance {
        id,
        name: generated_name(&np.name, id),
        piece,
        vertices,
        state: 0,
    });
    for d in &mut data.docks {
        for s in [&mut d.a, &mut d.b] {
            if s.instance == old {
                let &(_, ns) = pairs.iter().find(|(os, _)| *os == s.site).ok_or_else(|| {
                    format!(
                        "`{}` has no site `{}` to take over",
                        np.name, op.sites[s.site].name
                    )
                })?;
                *s = InstanceSite {
                    instance: ni,
                    site: ns,
                };
            }
        }
    }
    Ok(ni)
}

/// Applies a merge found by [`find`] (or built by hand).
pub fn apply(
    grammar: &CompiledGrammar,
    data: &mut AssemblyData,
    m: &MergeMatch,
) -> Result<Rewrite, String> {
    let before = PartsBefore::record(data);
    let rule = grammar
        .merge_rules
        .get(m.rule)
        .ok_or_else(|| format!("no merge rule {}", m.rule))?
        .clone();
    transaction(grammar, data, |data| {
        let docked = docked_sites(data);
        if docked.contains(&m.mover) {
            return Err("the mover site is already docked".into());
        }
        let mv = data
            .site_vertices(grammar, m.mover)
            .ok_or("the mover site does not exist")?;
        let mover_id = data.instances[m.mover.instance].id;
        let target_id = data
            .instances
            .get(m.target.instance)
            .ok_or("the target does not exist")?
            .id;
        let mover_name = data.instances[m.mover.instance].name.clone();
        let target_name = data.instances[m.target.instance].name.clone();
        let (ids, touched, detail, at) = match rule.junction {
            None => {
                if docked.contains(&m.target) {
                    return Err("the target site is already docked".into());
                }
                let tv = data
                    .site_vertices(grammar, m.target)
                    .ok_or("the target site does not exist")?;
                if tv.len() != mv.len() || tv.iter().any(|v| mv.contains(v)) {
                    return Err("the sites do not fit together".into());
                }
                let at = site_centre(grammar, data, m.target).unwrap_or(DVec2::ZERO);
                let opposite: Vec<usize> = tv.iter().rev().copied().collect();
                weld_vertices(data, &mv, &opposite);
                data.docks.push(Dock {
                    a: m.mover,
                    b: m.target,
                });
                (
                    vec![mover_id, target_id],
                    HashSet::from([mover_id, target_id]),
                    format!("`{mover_name}` welded to `{target_name}`"),
                    at,
                )
            }
            Some(j) => {
                let ji = take_over(grammar, data, m.target.instance, j.piece)?;
                let junction_id = data.instances[ji].id;
                let junction_name = data.instances[ji].name.clone();
                let stem = InstanceSite {
                    instance: ji,
                    site: j.site,
                };
                let sv = data
                    .site_vertices(grammar, stem)
                    .ok_or("the junction's stem site does not exist")?;
                if sv.len() != mv.len() {
                    return Err("the mover and the junction's stem differ in size".into());
                }
                let at = site_centre(grammar, data, stem).unwrap_or(DVec2::ZERO);
                let opposite: Vec<usize> = sv.iter().rev().copied().collect();
                weld_vertices(data, &mv, &opposite);
                data.docks.push(Dock {
                    a: m.mover,
                    b: stem,
                });
                remove_instances(data, &HashSet::from([m.target.instance]));
                (
                    vec![mover_id, target_id, junction_id],
                    HashSet::from([mover_id, target_id, junction_id]),
                    format!(
                        "`{mover_name}` merged onto `{target_name}`, which became `{junction_name}`"
                    ),
                    at,
                )
            }
        };
        derive_chains(grammar, data);
        let event = RuleEvent {
            kind: RuleKind::Merge,
            frame: 0,
            at,
            instances: ids,
            detail,
        };
        Ok(finish(grammar, data, &before, &touched, event))
    })
}
