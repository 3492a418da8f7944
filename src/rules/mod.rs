//! The smart-clay rules (paper 5.1): replacement, stretch/shrink, merge and cut, as pure
//! rewrites of `(&CompiledGrammar, &mut AssemblyData)` that each yield a [`RuleEvent`], and
//! [`Rules`], which runs them on a live [`Assembly`] after every solver frame.
//!
//! Every rewrite is a transaction: it either leaves an `AssemblyData` that passes
//! [`AssemblyData::check`] (with parts rebuilt from the grammar, untouched parts keeping their
//! active state, and untouched instances keeping their ids) or restores the data and returns
//! an error. Per-frame cost of finding rule applications is linear in the number of parts and
//! free sites; a rewrite itself costs O(instances + docks + vertices) and happens rarely.

pub mod cut;
pub use crate::fit;
pub mod merge;
pub mod proximity;
pub mod replace;
pub mod stretch;

use std::collections::{HashMap, HashSet};

use clay_dsl::compiled::{AssemblyData, Chain, CompiledGrammar, InstanceSite, Part, PartKind};
use glam::DVec2;
use serde::Serialize;

use crate::assembly::Assembly;
use crate::solver::FrameReport;

/// What kind of rule fired (paper 5.1), as logged and counted in the summary.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RuleKind {
    Replace,
    Stretch,
    Shrink,
    Merge,
    Cut,
}

impl RuleKind {
    pub const ALL: [RuleKind; 5] = [
        RuleKind::Replace,
        RuleKind::Stretch,
        RuleKind::Shrink,
        RuleKind::Merge,
        RuleKind::Cut,
    ];

    /// The name used in summaries and logs (`"stretch"`).
    pub fn name(self) -> &'static str {
        match self {
            RuleKind::Replace => "replace",
            RuleKind::Stretch => "stretch",
            RuleKind::Shrink => "shrink",
            RuleKind::Merge => "merge",
            RuleKind::Cut => "cut",
        }
    }
}

/// One application of a rule.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RuleEvent {
    pub kind: RuleKind,
    /// The frame after which the rule ran (set by [`Rules`]; 0 from the pure rewrites).
    pub frame: u64,
    /// Where it happened (the centre of the rewritten region), in metres.
    pub at: DVec2,
    /// Stable ids of the instances involved: for stretch the kept ones then the new one; for
    /// shrink the kept one then the removed one; for merge the mover, the replaced target and
    /// the junction (or the target for a weld); for cut the two sides and any new instance.
    pub instances: Vec<u64>,
    /// A short human description (`chain 0 at element 3: 2 -> 3 elements`).
    pub detail: String,
}

/// A structural rewrite: its event, and how old indices map to new ones so that callers can
/// carry per-vertex and per-part data (handles, rotations) across it.
#[derive(Clone, Debug, PartialEq)]
pub struct Rewrite {
    pub event: RuleEvent,
    /// Old global vertex index -> new one (`None`: the vertex was removed).
    pub vertex_map: Vec<Option<usize>>,
    /// Old part index -> new part index (`None`: the part was removed or rebuilt).
    pub part_map: Vec<Option<usize>>,
}

/// Identity of a part in terms of stable instance ids, so that parts can be matched across a
/// rewrite that renumbers instances, chains and parts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum PartKey {
    Piece(u64),
    Stretch(u64, u64),
}

fn part_key(data: &AssemblyData, part: &Part) -> Option<PartKey> {
    match part.kind {
        PartKind::Piece { instance } => data.instances.get(instance).map(|i| PartKey::Piece(i.id)),
        PartKind::Stretch { chain, first } => {
            let c = data.chains.get(chain)?;
            let a = data.instances.get(*c.instances.get(first)?)?.id;
            let b = data.instances.get(*c.instances.get(first + 1)?)?.id;
            Some(PartKey::Stretch(a, b))
        }
    }
}

/// The old parts' keys and active states, recorded before a rewrite changes indices.
pub(crate) struct PartsBefore {
    keys: Vec<Option<PartKey>>,
    active: Vec<usize>,
    /// Global vertex count before the rewrite (vertex maps cover these only).
    pub(crate) vertices: usize,
}

impl PartsBefore {
    pub(crate) fn record(data: &AssemblyData) -> Self {
        Self {
            keys: data.parts.iter().map(|p| part_key(data, p)).collect(),
            active: data.parts.iter().map(|p| p.active).collect(),
            vertices: data.positions.len(),
        }
    }
}

/// Rebuilds every part from the grammar after a rewrite. Parts over the same instances as
/// before keep their active state unless they cover an instance whose id is in `touched`
/// (those restart in their default state: `two` for stretch parts, the instance's state for
/// piece parts). Returns the old -> new part map (rebuilt parts map to `None`).
pub(crate) fn rebuild_parts(
    grammar: &CompiledGrammar,
    data: &mut AssemblyData,
    before: &PartsBefore,
    touched: &HashSet<u64>,
) -> Vec<Option<usize>> {
    let mut old_by_key: HashMap<PartKey, usize> = HashMap::new();
    for (i, k) in before.keys.iter().enumerate() {
        if let Some(k) = k {
            old_by_key.insert(*k, i);
        }
    }
    let mut parts = grammar.parts(data);
    let mut part_map = vec![None; before.keys.len()];
    for (ni, part) in parts.iter_mut().enumerate() {
        let Some(key) = part_key(data, part) else {
            continue;
        };
        let hit = match key {
            PartKey::Piece(a) => touched.contains(&a),
            PartKey::Stretch(a, b) => touched.contains(&a) || touched.contains(&b),
        };
        if hit {
            continue;
        }
        if let Some(&oi) = old_by_key.get(&key) {
            if matches!(part.kind, PartKind::Stretch { .. })
                && before.active[oi] < part.states.len()
            {
                part.active = before.active[oi];
            }
            part_map[oi] = Some(ni);
        }
    }
    data.parts = parts;
    part_map
}

/// Ends a rewrite: drops the vertices no instance uses any more, rebuilds the parts (keeping the
/// active state of parts over untouched instances) and packages the event with the old -> new
/// index maps. Every rule's rewrite leaves through here.
pub(crate) fn finish(
    grammar: &CompiledGrammar,
    data: &mut AssemblyData,
    before: &PartsBefore,
    touched: &HashSet<u64>,
    event: RuleEvent,
) -> Rewrite {
    let mut vertex_map = compact_vertices(data);
    vertex_map.truncate(before.vertices);
    let part_map = rebuild_parts(grammar, data, before, touched);
    Rewrite {
        event,
        vertex_map,
        part_map,
    }
}

/// Removes the instances at the given indices, renumbering docks (docks touching a removed
/// instance are dropped) and chains (removed elements are dropped; empty chains vanish).
pub(crate) fn remove_instances(data: &mut AssemblyData, removed: &HashSet<usize>) {
    if removed.is_empty() {
        return;
    }
    let mut map = vec![None; data.instances.len()];
    let mut next = 0;
    for (i, slot) in map.iter_mut().enumerate() {
        if !removed.contains(&i) {
            *slot = Some(next);
            next += 1;
        }
    }
    let mut i = 0;
    data.instances.retain(|_| {
        let keep = !removed.contains(&i);
        i += 1;
        keep
    });
    let remap = |s: InstanceSite| {
        map[s.instance].map(|instance| InstanceSite {
            instance,
            site: s.site,
        })
    };
    data.docks = data
        .docks
        .iter()
        .filter_map(|d| {
            Some(clay_dsl::compiled::Dock {
                a: remap(d.a)?,
                b: remap(d.b)?,
            })
        })
        .collect();
    for chain in &mut data.chains {
        chain.instances = chain.instances.iter().filter_map(|&i| map[i]).collect();
    }
    data.chains.retain(|c| !c.instances.is_empty());
    // Parts are rebuilt by the caller; drop them now so no stale index survives.
    data.parts.clear();
}

/// Drops vertices no instance uses and renumbers the rest (order kept). Returns the old -> new
/// vertex map. Parts must be rebuilt afterwards.
pub(crate) fn compact_vertices(data: &mut AssemblyData) -> Vec<Option<usize>> {
    let n = data.positions.len();
    let mut used = vec![false; n];
    for inst in &data.instances {
        for &v in &inst.vertices {
            used[v] = true;
        }
    }
    let mut map = vec![None; n];
    let mut positions = Vec::with_capacity(n);
    for (v, &u) in used.iter().enumerate() {
        if u {
            map[v] = Some(positions.len());
            positions.push(data.positions[v]);
        }
    }
    data.positions = positions;
    for inst in &mut data.instances {
        for v in &mut inst.vertices {
            *v = map[*v].expect("used vertices are kept");
        }
    }
    map
}

/// Which stretch rule (if any) an instance's piece is an element of.
fn stretch_rule_of(grammar: &CompiledGrammar, piece: usize) -> Option<usize> {
    grammar
        .stretch_rules
        .iter()
        .position(|r| r.piece == piece || r.variants.iter().any(|v| v.piece == piece))
}

/// Derives the chains from the docks: maximal runs of elements of one stretch rule docked
/// `to` -> `from`. Used after merges and cuts, which split and join chains. Existing chains
/// come first in their old order (by their first element), so indices move little.
pub(crate) fn derive_chains(grammar: &CompiledGrammar, data: &mut AssemblyData) {
    let n = data.instances.len();
    let rule: Vec<Option<usize>> = data
        .instances
        .iter()
        .map(|i| stretch_rule_of(grammar, i.piece))
        .collect();
    let mut next = vec![None; n];
    let mut has_prev = vec![false; n];
    for d in &data.docks {
        for (x, y) in [(d.a, d.b), (d.b, d.a)] {
            let (Some(rx), Some(ry)) = (rule[x.instance], rule[y.instance]) else {
                continue;
            };
            let r = &grammar.stretch_rules[rx];
            if rx == ry && x.site == r.to && y.site == r.from && x.instance != y.instance {
                next[x.instance] = Some(y.instance);
                has_prev[y.instance] = true;
            }
        }
    }
    let mut visited = vec![false; n];
    let mut chains = Vec::new();
    let walk = |start: usize, visited: &mut Vec<bool>, chains: &mut Vec<Chain>| {
        let mut list = Vec::new();
        let mut at = Some(start);
        while let Some(i) = at {
            if visited[i] {
                break;
            }
            visited[i] = true;
            list.push(i);
            at = next[i];
        }
        if let Some(r) = rule[start] {
            chains.push(Chain {
                rule: r,
                instances: list,
                trend: 0,
            });
        }
    };
    // Start walks at old chain heads first (keeps the old chain order), then any other head,
    // then cycles (closed rings of elements) at their lowest index.
    let old_heads: Vec<usize> = data
        .chains
        .iter()
        .filter_map(|c| c.instances.first().copied())
        .collect();
    for &h in &old_heads {
        if h < n && rule[h].is_some() && !has_prev[h] && !visited[h] {
            walk(h, &mut visited, &mut chains);
        }
    }
    for i in 0..n {
        if rule[i].is_some() && !has_prev[i] && !visited[i] {
            walk(i, &mut visited, &mut chains);
        }
    }
    for i in 0..n {
        if rule[i].is_some() && !visited[i] {
            walk(i, &mut visited, &mut chains);
        }
    }
    data.chains = chains;
}

/// Centre of an instance site's current vertex positions.
pub fn site_centre(
    grammar: &CompiledGrammar,
    data: &AssemblyData,
    s: InstanceSite,
) -> Option<DVec2> {
    let vs = data.site_vertices(grammar, s)?;
    if vs.is_empty() {
        return None;
    }
    Some(vs.iter().map(|&v| data.positions[v]).sum::<DVec2>() / vs.len() as f64)
}

/// The current outward direction of an instance site (unit length): the site's `out` (given in
/// its piece's base-state coordinates) turned by the best rigid motion of the site's own vertices
/// from the base state to their current positions. Fitting the site's vertices, not the whole
/// instance, follows the site through its piece's rest state and deformation: the east end of a
/// road bent a quarter turn left faces north, not north-east as a fit of all its vertices would
/// say. A site of one vertex (or whose vertices coincide in the base state) has no direction of
/// its own, so its edge neighbours in the piece join the fit. `None` when the site does not exist,
/// a position is not finite, or the fit gives no rotation (its vertices collapsed onto a point).
pub fn site_out(grammar: &CompiledGrammar, data: &AssemblyData, s: InstanceSite) -> Option<DVec2> {
    let inst = data.instances.get(s.instance)?;
    let piece = grammar.pieces.get(inst.piece)?;
    let site = piece.sites.get(s.site)?;
    let base = &piece.states.first()?.positions;
    let first = *base.get(*site.vertices.first()?)?;
    let mut local = site.vertices.clone();
    if local.iter().all(|&v| base.get(v) == Some(&first)) {
        for e in &piece.edges {
            for (a, b) in [(e[0], e[1]), (e[1], e[0])] {
                if site.vertices.contains(&a) && !local.contains(&b) {
                    local.push(b);
                }
            }
        }
    }
    let from: Vec<DVec2> = local
        .iter()
        .map(|&v| base.get(v).copied())
        .collect::<Option<_>>()?;
    let to: Vec<DVec2> = local
        .iter()
        .map(|&v| data.positions.get(*inst.vertices.get(v)?).copied())
        .collect::<Option<_>>()?;
    fit::rigid_rotation(&from, &to)?
        .rotate(site.out)
        .try_normalize()
}

/// Runs `body` as a transaction: on error, or when the result fails [`AssemblyData::check`],
/// the data is restored and the error returned.
pub(crate) fn transaction<T>(
    grammar: &CompiledGrammar,
    data: &mut AssemblyData,
    body: impl FnOnce(&mut AssemblyData) -> Result<T, String>,
) -> Result<T, String> {
    let backup = data.clone();
    let result = body(data).and_then(|t| {
        data.check(grammar)
            .map(|()| t)
            .map_err(|e| format!("the rewrite broke the assembly ({e}); undone"))
    });
    if result.is_err() {
        *data = backup;
    }
    result
}

/// A name for an instance a rule inserts: the base of a related name plus the new id
/// (`wall[3]` -> `wall#17`).
pub(crate) fn generated_name(base: &str, id: u64) -> String {
    let stem = base.split(['[', '#']).next().unwrap_or(base);
    format!("{stem}#{id}")
}

/// Runs the rules on a live assembly after each solver frame, and the cut operation.
#[derive(Clone, Debug, Default)]
pub struct Rules {
    /// Frames seen so far (stamped on events).
    pub frame: u64,
    /// Every event so far, in order.
    pub log: Vec<RuleEvent>,
    /// Pairs of instances (stable ids, smaller first) a cut separated: they do not weld
    /// again until their sites have moved beyond the merge distance (paper 5.1: a
    /// connection is fixed until cut, and a cut is the user's explicit wish to part them).
    parted: Vec<(u64, u64)>,
}

fn unordered(a: u64, b: u64) -> (u64, u64) {
    (a.min(b), a.max(b))
}

impl Rules {
    pub fn new() -> Self {
        Self::default()
    }

    /// Applies the rules after one solver frame ([`Rules::after_pass1`] with the frame's
    /// pass-1 pose `pass1`, then [`Rules::after_pass2`]): for tests that drive the rules
    /// around a frame of their own.
    pub fn after_frame(
        &mut self,
        asm: &mut Assembly,
        report: &FrameReport,
        pass1: &[DVec2],
    ) -> Vec<RuleEvent> {
        let mut events = self.after_pass1(asm, report, pass1);
        events.extend(self.after_pass2(asm));
        events
    }

    /// The rules that decide the frame's topology, between the solver's passes (paper 5.2:
    /// pass 2 runs on the topology pass 1 determined): replacement events for the piece parts
    /// that switched state, and at most one stretch or shrink per chain (parts left in
    /// `three`/`one`, by their claims). Counts the frame. Bumps the assembly's generation if
    /// the structure changed, and carries rotations and handles across the renumbering.
    ///
    /// `pass1` is the frame's pass-1 pose (one position per vertex, or empty): a chain that
    /// stretches is laid out in it first. There the sparse norm has gathered the chain's
    /// stretch into the rewritten part and left the other elements at rest, so the elements
    /// the rule lays into that part's span come out at rest too; in the displayed pose, where
    /// least squares spreads the stretch over the whole chain, a part claiming many elements
    /// would have them squeezed into two elements' length. A chain that shrinks stays in the
    /// displayed pose: the sparse norm gathers a squeeze by folding the part onto itself, and
    /// the elements beyond the fold lie back over those before it.
    pub fn after_pass1(
        &mut self,
        asm: &mut Assembly,
        report: &FrameReport,
        pass1: &[DVec2],
    ) -> Vec<RuleEvent> {
        self.frame += 1;
        let grammar = asm.grammar_arc().clone();
        let mut events = replace::replacement_events(&grammar, asm.data_mut(), &report.switches);
        let mut rewrites = Vec::new();
        let held: HashSet<u64> = asm
            .handles()
            .iter()
            .filter_map(|h| h.held.as_ref().map(|x| x.id))
            .collect();
        let candidates = stretch::candidates(&grammar, asm.data());
        if pass1.len() == asm.data().positions.len() {
            let data = asm.data();
            let mut laid = Vec::new();
            let grows =
                |part: usize| data.parts.get(part).map(|p| p.active) == Some(stretch::THREE);
            for &(_, (chain, _)) in candidates.iter().filter(|c| grows(c.0)) {
                for &i in data.chains.get(chain).map_or(&[][..], |c| &c.instances) {
                    laid.extend(data.instances[i].vertices.iter().copied());
                }
            }
            let positions = asm.positions_mut();
            for v in laid {
                if pass1[v].is_finite() {
                    positions[v] = pass1[v];
                }
            }
        }
        for (part, at) in candidates {
            // Earlier rewrites in this loop never renumber chains, and elements only within
            // their own chain, so (chain, first) is still valid here; `part` indexes the
            // parts the frame ran on.
            let elements = report
                .claims
                .iter()
                .find(|c| c.0 == part)
                .map(|c| i64::from(c.1));
            let elements = elements.unwrap_or_else(|| {
                let active = asm.data().parts.get(part).map(|p| p.active);
                if active == Some(stretch::ONE) { 1 } else { 3 }
            });
            if let Ok(r) = stretch::rewrite_part(&grammar, asm.data_mut(), at, elements, &held) {
                self.carry(asm, &r);
                rewrites.push(r.event);
            }
        }
        events.extend(rewrites);
        self.stamp(&grammar, asm, events)
    }

    /// The rules that act on the displayed pose, after the solver's frame: at most one merge.
    pub fn after_pass2(&mut self, asm: &mut Assembly) -> Vec<RuleEvent> {
        let grammar = asm.grammar_arc().clone();
        let mut events = Vec::new();
        // a cut pair parts once no merge rule finds its sides within reach
        self.parted.retain(|&pair| {
            merge::find_in_reach(&grammar, asm.data(), |m, t| unordered(m, t) == pair).is_some()
        });
        let parted = &self.parted;
        if let Some(found) = merge::find_where(&grammar, asm.data(), |m, t| {
            !parted.contains(&unordered(m, t))
        }) && let Ok(r) = merge::apply(&grammar, asm.data_mut(), &found)
        {
            self.carry(asm, &r);
            events.push(r.event);
        }
        self.stamp(&grammar, asm, events)
    }

    /// Stamps `events` with the frame and logs them.
    fn stamp(
        &mut self,
        grammar: &CompiledGrammar,
        asm: &Assembly,
        mut events: Vec<RuleEvent>,
    ) -> Vec<RuleEvent> {
        for e in &mut events {
            e.frame = self.frame;
        }
        debug_assert!(
            asm.data().check(grammar).is_ok(),
            "{:?}",
            asm.data().check(grammar)
        );
        self.log.extend(events.iter().cloned());
        events
    }

    /// Cuts the dock nearest `point` (see [`cut::cut_at`]).
    pub fn cut(&mut self, asm: &mut Assembly, point: DVec2) -> Result<RuleEvent, String> {
        let grammar = asm.grammar_arc().clone();
        let r = cut::cut_at(&grammar, asm.data_mut(), point)?;
        // every pair among the instances on the cut's sides (its new instance included)
        let ids = &r.event.instances;
        for (k, &a) in ids.iter().enumerate() {
            for &b in &ids[k + 1..] {
                self.parted.push(unordered(a, b));
            }
        }
        self.carry(asm, &r);
        let mut e = r.event;
        e.frame = self.frame;
        self.log.push(e.clone());
        Ok(e)
    }

    /// Carries per-part rotations and handle vertices across a rewrite and bumps the
    /// assembly's generation.
    fn carry(&self, asm: &mut Assembly, r: &Rewrite) {
        let old_rot = asm.rotations().to_vec();
        for h in asm.handles_mut().iter_mut() {
            let mut vertices = Vec::with_capacity(h.vertices.len());
            let mut anchor = Vec::with_capacity(h.anchor.len());
            for (k, &v) in h.vertices.iter().enumerate() {
                if let Some(Some(nv)) = r.vertex_map.get(v) {
                    vertices.push(*nv);
                    anchor.push(h.anchor[k]);
                }
            }
            h.vertices = vertices;
            h.anchor = anchor;
        }
        asm.topology_changed();
        let rot = asm.rotations_mut();
        for (old, new) in r.part_map.iter().enumerate() {
            if let (Some(new), Some(&q)) = (new, old_rot.get(old))
                && let Some(slot) = rot.get_mut(*new)
            {
                *slot = q;
            }
        }
    }
}
