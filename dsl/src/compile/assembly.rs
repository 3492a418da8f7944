//! Builds the initial assembly from the `model` block: expands chains, resolves docks, places
//! every instance (explicit `at`/`rotate`, else through its docks, breadth-first in declaration
//! order), shares the vertices of docked sites, and finds the stretch chains.

use std::collections::{HashMap, HashSet, VecDeque};

use glam::DVec2;

use super::codes;
use super::limits::{DOCK_TOLERANCE, MAX_MODEL_INSTANCES};
use super::rules::{dock_motion, rotate, site_centre};
use super::state::{Compiler, fmt};
use crate::compiled::*;
use crate::diagnostic::Diagnostic;
use crate::syntax::{self, ElementIndexKind, ModelStmt, Span};

/// At most this many diagnostics of one kind from the model: a broken chain of a million
/// elements should not print a million errors.
const MAX_REPEATS: usize = 10;

struct Inst {
    name: String,
    piece: usize,
    at: Option<DVec2>,
    rotate: f64,
    rotate_span: Option<Span>,
    span: Span,
}

struct DockInfo {
    a: InstanceSite,
    b: InstanceSite,
    span: Span,
}

enum Named {
    Single(usize),
    Chain {
        first: usize,
        count: usize,
    },
    /// Declared but broken (already reported): references to it are not reported again.
    Broken,
    /// Declared only in the branch of an `if` that is off: `cond` would have to be `on`.
    Elsewhere {
        cond: String,
        on: bool,
    },
}

/// E014 at `span`: the model would pass `MAX_MODEL_INSTANCES` (reported once per model).
fn too_many_instances(c: &mut Compiler, span: Span, label: String) {
    c.error(
        Diagnostic::error(
            codes::TOO_MANY,
            format!("the model would have more than {MAX_MODEL_INSTANCES} instances"),
            span,
            label,
        )
        .with_hint(format!(
            "a model holds at most {MAX_MODEL_INSTANCES} instances; start with a shorter chain, \
             the stretch rule inserts more as you sculpt"
        )),
    );
}

// Long because: one ordered walk (instances, chains, docks, placement by docks) over tables each step fills for the next.
pub(super) fn build(c: &mut Compiler, model: Option<&syntax::ModelBlock>) -> AssemblyData {
    let mut insts: Vec<Inst> = Vec::new();
    let mut docks: Vec<DockInfo> = Vec::new();
    let mut names: HashMap<String, (Named, Span)> = HashMap::new();
    let piece_rule = piece_rules(c);
    c.check_choices();
    let mut stmts: Vec<&ModelStmt> = Vec::new();
    let mut elsewhere: HashMap<String, (Named, Span)> = HashMap::new();
    active(
        c,
        model.map_or(&[], |m| &m.stmts),
        &mut stmts,
        &mut elsewhere,
    );
    let seed = (c.consts.params.iter())
        .find(|p| p.kind == ParamKind::Seed)
        .and_then(|p| Some((p.name.clone(), p.value.number()?)));
    let mut too_many = false;
    for &stmt in &stmts {
        match stmt {
            ModelStmt::Instance(d) => {
                if let Some((_, first)) = names.get(&d.name.name) {
                    c.duplicate("instance", &d.name, *first);
                    continue;
                }
                let piece = resolve_model_piece(c, &d.piece);
                let at = d.at.as_ref().map(|p| c.point(p));
                let full = insts.len() >= MAX_MODEL_INSTANCES;
                if full && piece.is_some() && !too_many {
                    too_many_instances(c, d.name.span, "one instance more".into());
                    too_many = true;
                }
                let (Some(piece), false) = (piece, full) else {
                    names.insert(d.name.name.clone(), (Named::Broken, d.name.span));
                    continue;
                };
                names.insert(
                    d.name.name.clone(),
                    (Named::Single(insts.len()), d.name.span),
                );
                insts.push(Inst {
                    name: d.name.name.clone(),
                    piece,
                    at,
                    rotate: d.rotate.as_ref().and_then(|r| c.eval(r)).unwrap_or(0.0),
                    rotate_span: d.rotate.as_ref().map(|r| r.span),
                    span: d.name.span,
                });
            }
            ModelStmt::Chain(d) => {
                if let Some((_, first)) = names.get(&d.name.name) {
                    c.duplicate("instance", &d.name, *first);
                    continue;
                }
                names.insert(d.name.name.clone(), (Named::Broken, d.name.span));
                let piece = resolve_model_piece(c, &d.piece);
                let count = c.whole(&d.count, "the chain length", 1);
                let at = d.at.as_ref().map(|p| c.point(p));
                let turn = d.rotate.as_ref().and_then(|r| c.eval(r)).unwrap_or(0.0);
                let (Some(piece), Some(count)) = (piece, count) else {
                    continue;
                };
                if count > (MAX_MODEL_INSTANCES - insts.len().min(MAX_MODEL_INSTANCES)) as u64 {
                    if !too_many {
                        too_many_instances(c, d.count.span, format!("a chain of {count}"));
                    }
                    too_many = true;
                    continue;
                }
                let count = count as usize;
                let sites = match &d.along {
                    Some((f, t)) => {
                        let f = c.resolve_site(piece, f);
                        let t = c.resolve_site(piece, t);
                        match (f, t) {
                            (Some(f), Some(t)) => {
                                let (sf, st) = (
                                    c.pieces[piece].sites[f].clone(),
                                    c.pieces[piece].sites[t].clone(),
                                );
                                let (fs, ts) = (
                                    d.along.as_ref().map_or(d.span, |a| a.0.span),
                                    d.along.as_ref().map_or(d.span, |a| a.1.span),
                                );
                                if c.sites_fit(&st, &sf, ts, fs) {
                                    Some((f, t))
                                } else {
                                    None
                                }
                            }
                            _ => None,
                        }
                    }
                    None => match piece_rule[piece] {
                        Some(r) => Some((c.stretch_rules[r].from, c.stretch_rules[r].to)),
                        // The piece's stretch rule had errors, already reported.
                        None if c.stretch_named.get(piece).copied().unwrap_or(false) => None,
                        None => {
                            let pname = c.pieces[piece].name.clone();
                            c.error(
                                Diagnostic::error(codes::CHAIN_SITES, format!("chain of `{pname}` has no sites to dock along"), d.piece.span, "no stretch rule for this piece")
                                    .with_hint(format!("add `along FROM -> TO`, or a rule `stretch {pname} from FROM to TO`")),
                            );
                            None
                        }
                    },
                };
                let Some((from, to)) = sites else { continue };
                let first = insts.len();
                let elements = match (&seed, piece_rule[piece]) {
                    (Some((name, seed)), Some(r)) if c.stretch_rules[r].variants.len() > 1 => {
                        if let Some(k) = c.consts.table.get_mut(name) {
                            k.used = true;
                        }
                        drawn(&c.stretch_rules[r], count, *seed, first)
                    }
                    _ => vec![piece; count],
                };
                for (k, &piece) in elements.iter().enumerate() {
                    insts.push(Inst {
                        name: format!("{}[{k}]", d.name.name),
                        piece,
                        at: if k == 0 { at } else { None },
                        rotate: if k == 0 { turn } else { 0.0 },
                        rotate_span: if k == 0 {
                            d.rotate.as_ref().map(|r| r.span)
                        } else {
                            None
                        },
                        span: d.name.span,
                    });
                    if k > 0 {
                        docks.push(DockInfo {
                            a: InstanceSite {
                                instance: first + k - 1,
                                site: to,
                            },
                            b: InstanceSite {
                                instance: first + k,
                                site: from,
                            },
                            span: d.span,
                        });
                    }
                }
                names.insert(
                    d.name.name.clone(),
                    (Named::Chain { first, count }, d.name.span),
                );
            }
            ModelStmt::Dock(_) | ModelStmt::If(_) => {}
        }
    }
    for (name, e) in elsewhere {
        names.entry(name).or_insert(e);
    }
    // Docks after all instances: a dock may name an instance declared further down.
    let mut docked: HashMap<InstanceSite, Span> = HashMap::new();
    for d in docks.iter() {
        docked.insert(d.a, d.span);
        docked.insert(d.b, d.span);
    }
    for &stmt in &stmts {
        let ModelStmt::Dock(d) = stmt else { continue };
        let failed_before = c.dock_failed;
        let a = resolve_instance_site(c, &names, &insts, &d.a);
        let b = resolve_instance_site(c, &names, &insts, &d.b);
        let (Some(a), Some(b)) = (a, b) else {
            c.dock_failed = true;
            continue;
        };
        // Any failure below leaves the dock out; unplaced instances are then its consequence.
        c.dock_failed = true;
        if a == b {
            c.error(
                Diagnostic::error(
                    codes::SELF_DOCK,
                    "a site cannot dock with itself",
                    d.b.span,
                    "same site as the other side",
                )
                .with_secondary(d.a.span, "this site")
                .with_hint("dock two different sites"),
            );
            continue;
        }
        let mut twice = false;
        for (side, path) in [(a, &d.a), (b, &d.b)] {
            if let Some(&first) = docked.get(&side) {
                c.error(
                    Diagnostic::error(codes::DOCKED_TWICE, format!("site `{}.{}` is already docked", insts[side.instance].name, path.site.name), path.span, "docked again here")
                        .with_secondary(first, "first docked here")
                        .with_hint("a site docks with one other site at a time; use another site or a junction piece"),
                );
                twice = true;
            }
        }
        if twice {
            continue;
        }
        let sa = c.pieces[insts[a.instance].piece].sites[a.site].clone();
        let sb = c.pieces[insts[b.instance].piece].sites[b.site].clone();
        if !c.sites_fit(&sa, &sb, d.a.span, d.b.span) {
            continue;
        }
        c.dock_failed = failed_before;
        docked.insert(a, d.span);
        docked.insert(b, d.span);
        docks.push(DockInfo { a, b, span: d.span });
    }
    let model_span = model.map_or(Span::default(), |m| m.keyword);
    let motions = place(c, &insts, &docks, model_span);
    let (positions, vertices) = share_vertices(c, &insts, &docks, &motions);
    if !c.diags.has_errors() {
        check_coincidence(c, &insts, &docks, &motions);
    }
    let chains = find_chains(c, &insts, &docks, &piece_rule);
    let n = insts.len();
    AssemblyData {
        positions,
        instances: insts
            .into_iter()
            .zip(vertices)
            .enumerate()
            .map(|(i, (inst, vertices))| Instance {
                id: i as u64,
                name: inst.name,
                piece: inst.piece,
                vertices,
                state: 0,
            })
            .collect(),
        docks: docks.iter().map(|d| Dock { a: d.a, b: d.b }).collect(),
        chains,
        parts: Vec::new(),
        next_id: n as u64,
    }
}

/// The statements `if` blocks switch on, in source order, into `out`; the names the others
/// declare into `elsewhere` (with the value their switch would need). Expressions in the
/// statements switched off are still evaluated, so that their constants count as used.
fn active<'a>(
    c: &mut Compiler,
    stmts: &'a [ModelStmt],
    out: &mut Vec<&'a ModelStmt>,
    elsewhere: &mut HashMap<String, (Named, Span)>,
) {
    for stmt in stmts {
        let ModelStmt::If(b) = stmt else {
            out.push(stmt);
            continue;
        };
        let on = c.switch(&b.cond);
        let otherwise: &'a [ModelStmt] = b.otherwise.as_deref().unwrap_or(&[]);
        let (taken, skipped) = match on {
            Some(true) => (&b.then[..], Some((otherwise, false))),
            Some(false) => (otherwise, Some((&b.then[..], true))),
            None => {
                // An `if` on no `bool` (reported): neither branch, and no word about their names.
                for branch in [&b.then[..], otherwise] {
                    off(c, branch, elsewhere, &mut |_| Named::Broken);
                }
                continue;
            }
        };
        active(c, taken, out, elsewhere);
        if let Some((branch, needs)) = skipped {
            let cond = b.cond.name.clone();
            off(c, branch, elsewhere, &mut |_| Named::Elsewhere {
                cond: cond.clone(),
                on: needs,
            });
        }
    }
}

/// Records the names a switched-off branch declares and touches its expressions.
fn off(
    c: &mut Compiler,
    stmts: &[ModelStmt],
    elsewhere: &mut HashMap<String, (Named, Span)>,
    named: &mut dyn FnMut(&str) -> Named,
) {
    let mut all = Vec::new();
    ModelStmt::walk(stmts, &mut all);
    for stmt in all {
        let (name, piece, exprs): (_, _, Vec<&syntax::Expr>) = match stmt {
            ModelStmt::Instance(d) => (&d.name, &d.piece, d.rotate.iter().collect()),
            ModelStmt::Chain(d) => (
                &d.name,
                &d.piece,
                std::iter::once(&d.count).chain(&d.rotate).collect(),
            ),
            ModelStmt::If(b) => {
                c.switch(&b.cond);
                continue;
            }
            ModelStmt::Dock(_) => continue,
        };
        let at = match stmt {
            ModelStmt::Instance(d) => d.at.as_ref(),
            ModelStmt::Chain(d) => d.at.as_ref(),
            _ => None,
        };
        for e in exprs
            .into_iter()
            .chain(at.into_iter().flat_map(|p| [&p.x, &p.y]))
        {
            c.eval(e);
        }
        c.chosen_piece(piece);
        elsewhere
            .entry(name.name.clone())
            .or_insert((named(&name.name), name.span));
    }
}

/// The piece a model statement names: a piece's name, or a `choice` parameter's, which picks
/// the piece it is set to.
fn resolve_model_piece(c: &mut Compiler, id: &syntax::Ident) -> Option<usize> {
    match c.chosen_piece(id) {
        Some(chosen) if chosen.name.is_empty() => None,
        Some(chosen) => c.piece_index.get(&chosen.name).copied(),
        None => c.resolve_piece(id),
    }
}

/// The pieces of a chain of `count` elements drawn with `seed` from its rule's variants: as
/// many of each as its frequency asks (largest remainders first), in an order the seed
/// shuffles (with the chain's first instance, so that two chains differ).
fn drawn(rule: &StretchRule, count: usize, seed: f64, salt: usize) -> Vec<usize> {
    if rule.variants.is_empty() {
        return vec![rule.piece; count];
    }
    let exact: Vec<f64> = (rule.variants.iter())
        .map(|v| v.frequency * count as f64)
        .collect();
    let mut counts: Vec<usize> = exact.iter().map(|e| e.floor() as usize).collect();
    let mut order: Vec<usize> = (0..counts.len()).collect();
    order.sort_by(|&a, &b| (exact[b] - exact[b].floor()).total_cmp(&(exact[a] - exact[a].floor())));
    for &i in order
        .iter()
        .cycle()
        .take(count.saturating_sub(counts.iter().sum()))
    {
        counts[i] += 1;
    }
    let mut pieces: Vec<usize> = (rule.variants.iter().zip(&counts))
        .flat_map(|(v, &n)| std::iter::repeat_n(v.piece, n))
        .collect();
    // Fisher-Yates with splitmix64: the order must be the same on every machine and version,
    // which a general-purpose random crate does not promise.
    let mut state = (seed as u64) ^ (salt as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let mut next = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    };
    for i in (1..pieces.len()).rev() {
        let j = (next() % (i as u64 + 1)) as usize;
        pieces.swap(i, j);
    }
    pieces
}

/// The stretch rule each piece belongs to (as its piece or a variant).
fn piece_rules(c: &Compiler) -> Vec<Option<usize>> {
    let mut out = vec![None; c.pieces.len()];
    for (r, rule) in c.stretch_rules.iter().enumerate() {
        out[rule.piece] = Some(r);
        for v in &rule.variants {
            out[v.piece] = Some(r);
        }
    }
    out
}

fn resolve_instance_site(
    c: &mut Compiler,
    names: &HashMap<String, (Named, Span)>,
    insts: &[Inst],
    p: &syntax::InstanceSitePath,
) -> Option<InstanceSite> {
    let instance = match (names.get(&p.instance.name), p.index) {
        (None, _) => {
            let known: Vec<&str> = names.keys().map(String::as_str).collect();
            c.unknown("instance", &p.instance, known, None);
            return None;
        }
        (Some((Named::Broken, _)), _) => return None,
        (Some((Named::Elsewhere { cond, on }, span)), _) => {
            let block = if *on { "" } else { "the `else` of " };
            c.error(
                Diagnostic::error(
                    codes::UNKNOWN,
                    format!(
                        "instance `{}` is in the model only when `{cond}` is {on}",
                        p.instance.name
                    ),
                    p.instance.span,
                    format!("`{cond}` is {} here", !on),
                )
                .with_secondary(*span, format!("declared in {block}`if {cond}`"))
                .with_hint(format!(
                    "move this `dock` into {block}`if {cond} {{ ... }}`, next to the instance"
                )),
            );
            return None;
        }
        (Some((Named::Single(i), _)), None) => *i,
        (Some((Named::Single(_), _)), Some(ix)) => {
            c.error(
                Diagnostic::error(
                    codes::BAD_ELEMENT,
                    format!("`{}` is a single instance, not a chain", p.instance.name),
                    ix.span,
                    "no elements to index",
                )
                .with_hint(format!("write `{}.{}`", p.instance.name, p.site.name)),
            );
            return None;
        }
        (Some((Named::Chain { count, .. }, _)), None) => {
            c.error(
                Diagnostic::error(
                    codes::BAD_ELEMENT,
                    format!(
                        "`{}` is a chain of {count}; name one element",
                        p.instance.name
                    ),
                    p.instance.span,
                    "a chain, not an instance",
                )
                .with_hint(format!(
                    "write `{0}[0].{1}` or `{0}[last].{1}`",
                    p.instance.name, p.site.name
                )),
            );
            return None;
        }
        (Some((Named::Chain { first, count }, _)), Some(ix)) => match ix.index {
            ElementIndexKind::Last => first + count - 1,
            ElementIndexKind::At(k) if (k as usize as u64) == k && (k as usize) < *count => {
                first + k as usize
            }
            ElementIndexKind::At(k) => {
                c.error(
                    Diagnostic::error(
                        codes::BAD_ELEMENT,
                        format!("chain `{}` has no element {k}", p.instance.name),
                        ix.span,
                        format!("elements are 0 to {}", count - 1),
                    )
                    .with_hint(format!("use an index from 0 to {} or `last`", count - 1)),
                );
                return None;
            }
        },
    };
    let site = c.resolve_site(insts[instance].piece, &p.site)?;
    Some(InstanceSite { instance, site })
}

/// Rigid motion `(angle, translation)` of every instance.
fn place(
    c: &mut Compiler,
    insts: &[Inst],
    docks: &[DockInfo],
    model_span: Span,
) -> Vec<(f64, DVec2)> {
    let n = insts.len();
    let mut adj: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (k, d) in docks.iter().enumerate() {
        adj[d.a.instance].push(k);
        adj[d.b.instance].push(k);
    }
    let mut motion: Vec<Option<(f64, DVec2)>> = vec![None; n];
    let mut queue = VecDeque::new();
    for (i, inst) in insts.iter().enumerate() {
        if let Some(at) = inst.at {
            motion[i] = Some((inst.rotate.to_radians(), at));
            queue.push_back(i);
        }
    }
    let mut ignored_rotate = 0;
    let mut bfs = |c: &mut Compiler,
                   motion: &mut Vec<Option<(f64, DVec2)>>,
                   queue: &mut VecDeque<usize>| {
        while let Some(i) = queue.pop_front() {
            let (angle_a, shift_a) = motion[i].unwrap_or((0.0, DVec2::ZERO));
            for &k in &adj[i] {
                let d = &docks[k];
                let (mine, other) = if d.a.instance == i {
                    (d.a, d.b)
                } else {
                    (d.b, d.a)
                };
                if motion[other.instance].is_some() {
                    continue;
                }
                let pa = &c.pieces[insts[i].piece];
                let sa = &pa.sites[mine.site];
                let centre = rotate(site_centre(sa, &pa.states[0].positions), angle_a) + shift_a;
                let out = rotate(sa.out, angle_a);
                let pb = &c.pieces[insts[other.instance].piece];
                motion[other.instance] = Some(dock_motion(
                    centre,
                    out,
                    &pb.sites[other.site],
                    &pb.states[0].positions,
                ));
                if let Some(span) = insts[other.instance].rotate_span {
                    if ignored_rotate < MAX_REPEATS {
                        c.diags.push(
                            Diagnostic::warning(codes::IGNORED_ROTATE, format!("`rotate` of `{}` has no effect", insts[other.instance].name), span, "ignored")
                                .with_secondary(d.span, "the instance is turned by this dock")
                                .with_hint("an instance without `at` is placed through its dock; give it `at (x, y)` to place it yourself"),
                        );
                    }
                    ignored_rotate += 1;
                }
                queue.push_back(other.instance);
            }
        }
    };
    bfs(c, &mut motion, &mut queue);
    // The first instance sits at the origin when nothing else places it.
    if n > 0 && motion[0].is_none() {
        motion[0] = Some((insts[0].rotate.to_radians(), DVec2::ZERO));
        queue.push_back(0);
        bfs(c, &mut motion, &mut queue);
    }
    let mut reported = 0;
    for i in 0..n {
        if motion[i].is_some() {
            continue;
        }
        if reported < MAX_REPEATS && !c.dock_failed {
            c.error(
                Diagnostic::error(codes::UNPLACED, format!("cannot place instance `{}`", insts[i].name), insts[i].span, "no `at` and not docked to a placed instance")
                    .with_secondary(model_span, "only the first instance goes to the origin by default")
                    .with_hint(format!("give `{}` a position with `at (x, y)`, or dock it to an instance that is placed", insts[i].name)),
            );
        }
        reported += 1;
        // Place its component at the origin so it is reported once.
        motion[i] = Some((0.0, DVec2::ZERO));
        queue.push_back(i);
        bfs(c, &mut motion, &mut queue);
    }
    motion
        .into_iter()
        .map(|m| m.unwrap_or((0.0, DVec2::ZERO)))
        .collect()
}

fn find(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

/// Global vertices: docked site vertices (i with n-1-i) are one vertex, placed where the first
/// instance (in declaration order) puts it.
fn share_vertices(
    c: &Compiler,
    insts: &[Inst],
    docks: &[DockInfo],
    motions: &[(f64, DVec2)],
) -> (Vec<DVec2>, Vec<Vec<usize>>) {
    let mut offset = Vec::with_capacity(insts.len() + 1);
    let mut total = 0;
    for inst in insts {
        offset.push(total);
        total += c.pieces[inst.piece].vertices.len();
    }
    let mut parent: Vec<usize> = (0..total).collect();
    for d in docks {
        let sa = &c.pieces[insts[d.a.instance].piece].sites[d.a.site];
        let sb = &c.pieces[insts[d.b.instance].piece].sites[d.b.site];
        let n = sa.vertices.len().min(sb.vertices.len());
        for i in 0..n {
            let x = find(&mut parent, offset[d.a.instance] + sa.vertices[i]);
            let y = find(
                &mut parent,
                offset[d.b.instance] + sb.vertices[sb.vertices.len() - 1 - i],
            );
            if x != y {
                // The earlier one stays the root, so positions come from the first instance.
                let (lo, hi) = (x.min(y), x.max(y));
                parent[hi] = lo;
            }
        }
    }
    let mut global = vec![usize::MAX; total];
    let mut positions = Vec::new();
    let mut vertices = Vec::with_capacity(insts.len());
    for (i, inst) in insts.iter().enumerate() {
        let piece = &c.pieces[inst.piece];
        let (angle, shift) = motions[i];
        let mut vs = Vec::with_capacity(piece.vertices.len());
        for v in 0..piece.vertices.len() {
            let root = find(&mut parent, offset[i] + v);
            if global[root] == usize::MAX {
                global[root] = positions.len();
                positions.push(rotate(piece.states[0].positions[v], angle) + shift);
            }
            vs.push(global[root]);
        }
        vertices.push(vs);
    }
    (positions, vertices)
}

fn check_coincidence(
    c: &mut Compiler,
    insts: &[Inst],
    docks: &[DockInfo],
    motions: &[(f64, DVec2)],
) {
    let mut reported = 0;
    for d in docks {
        let (ia, ib) = (&insts[d.a.instance], &insts[d.b.instance]);
        let (pa, pb) = (&c.pieces[ia.piece], &c.pieces[ib.piece]);
        let (sa, sb) = (&pa.sites[d.a.site], &pb.sites[d.b.site]);
        let n = sa.vertices.len();
        if n != sb.vertices.len() {
            continue;
        }
        let world =
            |p: &Piece, v: usize, m: (f64, DVec2)| rotate(p.states[0].positions[v], m.0) + m.1;
        for i in 0..n {
            let (va, vb) = (sa.vertices[i], sb.vertices[n - 1 - i]);
            let gap =
                world(pa, va, motions[d.a.instance]).distance(world(pb, vb, motions[d.b.instance]));
            if gap > DOCK_TOLERANCE {
                if reported < MAX_REPEATS {
                    let msg = format!(
                        "docked vertices do not meet: `{}` of `{}` is {} m from `{}` of `{}`",
                        pa.vertices[va],
                        ia.name,
                        fmt(gap),
                        pb.vertices[vb],
                        ib.name
                    );
                    c.diags.push(
                        Diagnostic::error(codes::NOT_COINCIDENT, msg, d.span, format!("`{}.{}` and `{}.{}` do not fit", ia.name, sa.name, ib.name, sb.name))
                            .with_hint("check the sites' vertex positions and counter-clockwise order, and the instances' `at`/`rotate`: vertex i of one site meets vertex n-1-i of the other"),
                    );
                }
                reported += 1;
                break;
            }
        }
    }
}

/// Maximal runs of instances of one stretch rule docked `to` -> `from`, in order; every such
/// instance is in exactly one chain (a ring is cut open at its first instance).
fn find_chains(
    c: &Compiler,
    insts: &[Inst],
    docks: &[DockInfo],
    piece_rule: &[Option<usize>],
) -> Vec<Chain> {
    let n = insts.len();
    let mut next = vec![usize::MAX; n];
    let mut has_prev = vec![false; n];
    for d in docks {
        let (ra, rb) = (
            piece_rule[insts[d.a.instance].piece],
            piece_rule[insts[d.b.instance].piece],
        );
        let (Some(r), Some(r2)) = (ra, rb) else {
            continue;
        };
        if r != r2 {
            continue;
        }
        let rule = &c.stretch_rules[r];
        let link = if d.a.site == rule.to && d.b.site == rule.from {
            Some((d.a.instance, d.b.instance))
        } else if d.a.site == rule.from && d.b.site == rule.to {
            Some((d.b.instance, d.a.instance))
        } else {
            None
        };
        if let Some((x, y)) = link
            && x != y
        {
            next[x] = y;
            has_prev[y] = true;
        }
    }
    let mut seen = vec![false; n];
    let mut chains = Vec::new();
    let walk = |start: usize, seen: &mut Vec<bool>| {
        let mut run = Vec::new();
        let mut i = start;
        let mut visited = HashSet::new();
        while i != usize::MAX && !seen[i] && visited.insert(i) {
            seen[i] = true;
            run.push(i);
            i = next[i];
        }
        run
    };
    for i in 0..n {
        if let Some(r) = piece_rule[insts[i].piece]
            && !has_prev[i]
            && !seen[i]
        {
            chains.push(Chain {
                rule: r,
                instances: walk(i, &mut seen),
                trend: 0,
            });
        }
    }
    for i in 0..n {
        if let Some(r) = piece_rule[insts[i].piece]
            && !seen[i]
        {
            chains.push(Chain {
                rule: r,
                instances: walk(i, &mut seen),
                trend: 0,
            });
        }
    }
    chains.sort_by_key(|ch| ch.instances[0]);
    chains
}
