//! What a rewrite yields and how every rewrite runs: the rule kinds and events, the
//! [`Rewrite`] with its index maps, [`transaction`] (undo on error or a failed check) and
//! [`finish`] (compact, rebuild the parts, package the event), and the structural helpers the
//! rule files share (removing instances, deriving chains from docks, naming new instances).

use std::collections::{HashMap, HashSet};

use clay_dsl::compiled::{AssemblyData, Chain, CompiledGrammar, InstanceSite, Part, PartKind};
use glam::DVec2;
use serde::Serialize;

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
    /// The frame after which the rule ran (set by the session's rules; 0 from the pure rewrites).
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
