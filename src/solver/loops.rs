//! The piece graph of an assembly and its loops (`closure.rs`, `turns.rs`): the pieces between
//! chains as rigid bodies (pieces docked to each other one body, the held ones a single
//! ground, two chains docked end to end meeting at a body of their own) and the chains as the
//! edges between them. Each independent loop of it (round a ring of free hubs, or from one held
//! piece to another through the ground) is a condition the chains on it must meet together:
//! their lengths close it (`closure.rs`), their turns add up (`turns.rs`).

use clay_dsl::compiled::{AssemblyData, CompiledGrammar, InstanceSite};
use glam::DVec2;

use super::rounding::chain_of;
use crate::assembly::Assembly;

/// A loop's chains and the signs they run round it with (`1.0` from the first element to the
/// last).
pub(super) type Cycle = Vec<(usize, f64)>;

/// A step of a path between held pieces or round a loop of free ones (`turns.rs`,
/// [`free_loops`]).
#[derive(Debug, PartialEq)]
pub(super) enum Step {
    /// A chain, with `1.0` where the path runs from its first element to its last and
    /// `-1.0` the other way.
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
pub(super) fn free_loops(asm: &Assembly, pose: &[DVec2], held: &[u64]) -> Vec<Vec<Step>> {
    let Some(graph) = PieceGraph::of(asm.grammar(), asm.data(), pose, held) else {
        return Vec::new();
    };
    let mut loops = Vec::new();
    'cycles: for cycle in graph.cycles() {
        // per body on the loop: the site it is arrived at, the one it is left by
        // (ordered: the turns are summed in this order, the same in every run)
        let mut at: std::collections::BTreeMap<usize, [Option<Option<InstanceSite>>; 2]> =
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
        let mut steps: Vec<Step> = (cycle.iter()).map(|&(c, s)| Step::Chain(c, s)).collect();
        for sites in at.values() {
            match *sites {
                // two chains docked end to end: no piece between them
                [Some(None), Some(None)] => {}
                [Some(Some(a)), Some(Some(b))] if a.instance == b.instance => {
                    steps.push(Step::Piece {
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
/// as the edges between them, with each chain's direction in the pose.
pub(super) struct PieceGraph {
    /// Per chain: its end bodies (near, far); `None` for a chain a handle holds (its ends are
    /// each tied to the ground).
    ends: Vec<Option<(usize, usize)>>,
    /// Per chain: the unit direction from its first site to its last in the pose, when no
    /// handle holds one of its elements.
    pub(super) direction: Vec<Option<DVec2>>,
    /// Per chain: the piece site its near and far ends dock to (`None`: another chain's end,
    /// or nothing).
    docked: Vec<[Option<InstanceSite>; 2]>,
    bodies: usize,
    ground: usize,
}

impl PieceGraph {
    pub(super) fn of(
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
            direction.push((!holds_one && d.length() > 0.0).then(|| d.normalize()));
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
    pub(super) fn cycles(&self) -> Vec<Cycle> {
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
