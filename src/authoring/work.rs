//! An author's work on a drawing and the grammar computed from it: the cut points and the
//! rule declarations (piece and site type names, site types, the stretchable piece and its
//! variants, merge rules, posed rest states), run through the library's steps ([`compute`]:
//! graph, regions, pieces, then the declarations written into the syntax tree). The editor's
//! author mode keeps only the undo history and its UI; `clayc author` computes the same way.

use std::collections::{BTreeMap, HashMap, HashSet};

use glam::DVec2;

use super::drawing::Drawing;
use super::graph::{Graph, Region};
use super::pieces::{Design, StretchChoice};

/// The author's work: everything undo and redo restore.
#[derive(Clone, Debug, PartialEq)]
pub struct Work {
    pub drawing: Drawing,
    /// Cut points (metres, y up), in the order they were made.
    pub cuts: Vec<DVec2>,
    /// Site type renames: generated name -> the author's name. Keyed by the generated name so
    /// a rename survives the design being recomputed after a new cut or stroke.
    pub site_names: BTreeMap<String, String>,
    /// Piece renames: generated name (from the SVG ids, else `pieceN`) -> the author's name.
    /// Keyed by the generated name like `site_names`; the other declarations name pieces by
    /// their shown name.
    pub piece_names: BTreeMap<String, String>,
    pub stretch: Option<StretchChoice>,
    /// Merge rules, by piece and site names (the library's design has none: the editor adds
    /// them to the syntax tree before printing).
    pub merges: Vec<MergeChoice>,
    /// Site types set per site: `piece.site` -> a type (a generated name, a shown name, or a
    /// new one). Applied after the renames.
    pub site_types: BTreeMap<SiteName, String>,
    /// The stretch rule's `variants { ... }` (empty: none written).
    pub variants: Vec<VariantChoice>,
    /// Alternative rest states added by posing copies of pieces (the library's design has
    /// none: the editor adds them to the syntax tree before printing).
    pub states: Vec<StateChoice>,
    /// Points closer than this (metres) are one vertex; also the congruence tolerance.
    pub tolerance: f64,
}

impl Default for Work {
    fn default() -> Self {
        Self {
            drawing: Drawing::default(),
            cuts: Vec::new(),
            site_names: BTreeMap::new(),
            piece_names: BTreeMap::new(),
            stretch: None,
            merges: Vec::new(),
            site_types: BTreeMap::new(),
            variants: Vec::new(),
            states: Vec::new(),
            tolerance: 1e-3,
        }
    }
}

/// A site of a piece, by names: `piece.site`.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct SiteName {
    pub piece: String,
    pub site: String,
}

impl std::fmt::Display for SiteName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}.{}", self.piece, self.site)
    }
}

/// `merge mover onto target [into junction]` (docs/language.md).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MergeChoice {
    pub mover: SiteName,
    pub target: SiteName,
    pub junction: Option<SiteName>,
}

impl std::fmt::Display for MergeChoice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "merge {} onto {}", self.mover, self.target)?;
        if let Some(j) = &self.junction {
            write!(f, " into {j}")?;
        }
        Ok(())
    }
}

/// One entry of `variants { PIECE FREQ, ... }`.
#[derive(Clone, Debug, PartialEq)]
pub struct VariantChoice {
    pub piece: String,
    pub frequency: f64,
}

/// `state NAME { v0 (x, y) ... }` of a piece: one position per piece vertex, in the piece's
/// coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct StateChoice {
    pub piece: String,
    pub name: String,
    pub positions: Vec<DVec2>,
}

/// Every `piece.site` of a design.
pub fn site_names(design: &Design) -> Vec<SiteName> {
    design
        .pieces
        .iter()
        .flat_map(|p| {
            p.sites.iter().map(|s| SiteName {
                piece: p.name.clone(),
                site: s.name.clone(),
            })
        })
        .collect()
}

/// The design computed from the work, with the graph it was computed on (for drawing).
#[derive(Clone, Debug)]
pub struct Computed {
    pub graph: Graph,
    pub regions: Vec<Region>,
    pub design: Design,
    /// Generated site type names, parallel to `design.site_types` (which holds the shown ones).
    pub generated_site_types: Vec<String>,
    /// Generated piece names, parallel to `design.pieces` (which holds the shown ones).
    pub generated_piece_names: Vec<String>,
    pub text: String,
}

/// The grammar's keywords (docs/language.md). They are contextual, but a name that spells one
/// reads badly (`piece piece {`), so the editor refuses them as names.
use clay_dsl::analysis::KEYWORDS;

/// Why `s` cannot be a name in the grammar: an ASCII letter or `_`, then letters, digits and
/// `_`, and not a keyword.
pub fn check_name(s: &str) -> Result<(), String> {
    let mut chars = s.chars();
    let ok = chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !ok {
        return Err(format!(
            "`{s}` is not a name: use letters, digits and _, not starting with a digit"
        ));
    }
    if KEYWORDS.contains(&s) {
        return Err(format!(
            "`{s}` is a keyword of the grammar: pick another name"
        ));
    }
    Ok(())
}

/// Runs the library's steps on the work. A stretch choice that no longer fits the design (the
/// drawing or cuts changed under it) is dropped with a note rather than losing the design.
// Long because: the library's steps in order, then the declarations applied to the design and its syntax tree.
pub fn compute(work: &Work) -> Result<Computed, String> {
    if work.drawing.polylines.is_empty() {
        return Err("nothing drawn yet: import an SVG or draw on the canvas".into());
    }
    let tol = work.tolerance;
    let mut graph = Graph::build(&work.drawing, tol).map_err(|e| e.to_string())?;
    let sections = work
        .cuts
        .iter()
        .map(|&p| graph.cut(p, tol))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| e.to_string())?;
    let split = if sections.is_empty() {
        graph.loop_regions()
    } else {
        graph.regions(&sections)
    }
    .map_err(|e| e.to_string())?;
    let regions = split.regions;
    let mut design = super::pieces::find_pieces(&graph, &regions, &split.contacts, tol)
        .map_err(|e| e.to_string())?;
    design.notes.splice(0..0, split.notes);
    let generated_piece_names = name_pieces(&graph, &regions, work, &mut design);
    colour_pieces(&graph, &regions, &mut design);
    if let Some(choice) = &work.stretch
        && let Err(e) = design.make_stretchable(choice)
    {
        design
            .notes
            .push(format!("the stretch declaration no longer applies: {e}"));
    }
    let mut generated_site_types = design.site_types.clone();
    for t in &mut design.site_types {
        if let Some(n) = work.site_names.get(t) {
            t.clone_from(n);
        }
    }
    for (site, ty) in &work.site_types {
        let Some((p, si)) = find_site(&design, site) else {
            design.notes.push(format!(
                "the type of {site} no longer applies: there is no such site"
            ));
            continue;
        };
        let t = generated_site_types
            .iter()
            .position(|g| g == ty)
            .or_else(|| design.site_types.iter().position(|n| n == ty))
            .unwrap_or_else(|| {
                generated_site_types.push(ty.clone());
                let shown = work.site_names.get(ty).unwrap_or(ty);
                design.site_types.push(shown.clone());
                design.site_types.len() - 1
            });
        design.pieces[p].sites[si].site_type = t;
    }
    if !work.site_types.is_empty() {
        // A type that no site has any more is not written (its sites all took another).
        let used: Vec<bool> = (0..design.site_types.len())
            .map(|t| {
                design
                    .pieces
                    .iter()
                    .any(|p| p.sites.iter().any(|s| s.site_type == t))
            })
            .collect();
        let mut renumber = Vec::with_capacity(used.len());
        let mut next = 0;
        for &u in &used {
            renumber.push(next);
            next += usize::from(u);
        }
        for p in &mut design.pieces {
            for s in &mut p.sites {
                s.site_type = renumber[s.site_type];
            }
        }
        let mut keep = used.iter();
        design.site_types.retain(|_| *keep.next().unwrap_or(&true));
        let mut keep = used.iter();
        generated_site_types.retain(|_| *keep.next().unwrap_or(&true));
    }
    design.fit_docks();
    for d in &design.docks {
        if let (Some(a), Some(b)) = (piece_site(&design, d.a), piece_site(&design, d.b)) {
            let ty = |(p, s): (usize, usize)| design.pieces[p].sites[s].site_type;
            if ty(a) != ty(b) {
                let name = |(p, s): (usize, usize)| {
                    format!(
                        "{}.{}",
                        design.pieces[p].name, design.pieces[p].sites[s].name
                    )
                };
                design.notes.push(format!(
                    "{} and {} are docked but of different types",
                    name(a),
                    name(b)
                ));
            }
        }
    }
    let mut tree = design.to_syntax();
    // States first: rewriting a variant renames the vertices its states name.
    add_states(work, &mut design, &mut tree);
    add_variants(work, &mut design, &mut tree);
    let names = site_names(&design);
    let at = tree
        .items
        .iter()
        .position(|i| matches!(i, clay_dsl::syntax::Item::Model(_)))
        .unwrap_or(tree.items.len());
    let mut merges = Vec::new();
    for m in &work.merges {
        let sites = std::iter::once(&m.mover)
            .chain(Some(&m.target))
            .chain(m.junction.as_ref());
        match sites.clone().find(|s| !names.contains(s)) {
            Some(missing) => design.notes.push(format!(
                "`{m}` no longer applies: there is no site {missing}"
            )),
            None => merges.push(clay_dsl::syntax::Item::Merge(merge_decl(m))),
        }
    }
    tree.items.splice(at..at, merges);
    let text = clay_dsl::print_file(&tree);
    Ok(Computed {
        graph,
        regions,
        design,
        generated_site_types,
        generated_piece_names,
        text,
    })
}

/// Piece fills for pieces drawn without one (drawn on the canvas, or SVG paths with no fill):
/// the canvas shows and the grammar writes the same colour.
pub const PALETTE: [[u8; 3]; 8] = [
    [232, 176, 120],
    [150, 196, 230],
    [170, 214, 150],
    [226, 160, 200],
    [236, 214, 120],
    [180, 170, 230],
    [140, 210, 200],
    [220, 150, 140],
];

/// Where an instance came from in the drawing: its piece, and its region's fill and id.
struct InstanceSource<'g> {
    piece: usize,
    fill: Option<[u8; 3]>,
    id: Option<&'g str>,
}

/// The drawing's fill and id of each instance's region, by instance.
fn instance_sources<'g>(
    graph: &'g Graph,
    regions: &[Region],
    design: &Design,
) -> Vec<InstanceSource<'g>> {
    design
        .instances
        .iter()
        .map(|inst| {
            let source = regions
                .get(inst.region)
                .and_then(|r| r.source)
                .and_then(|s| graph.sources.get(s));
            InstanceSource {
                piece: inst.piece,
                fill: source.and_then(|s| s.0),
                id: source.and_then(|s| s.1.as_deref()),
            }
        })
        .collect()
}

/// Every piece's fill: the drawing's fill of one of its instances, else a palette colour (the
/// library would write one brown for all of them).
fn colour_pieces(graph: &Graph, regions: &[Region], design: &mut Design) {
    let mut fills: Vec<Option<[u8; 3]>> = vec![None; design.pieces.len()];
    for s in instance_sources(graph, regions, design) {
        if fills[s.piece].is_none() {
            fills[s.piece] = s.fill;
        }
    }
    for (pi, piece) in design.pieces.iter_mut().enumerate() {
        piece.fill = fills[pi].unwrap_or(PALETTE[pi % PALETTE.len()]);
    }
}

/// An SVG id as a name: `brick3` -> `brick` (as the library does), if it then is a name.
fn name_from_id(raw: &str) -> Option<String> {
    super::pieces::clean_name(raw).filter(|s| check_name(s).is_ok())
}

/// Names the pieces and their instances; returns the generated names. A piece is named after
/// the SVG id most of its instances have (any instance's, not just the first's); pieces with
/// more instances choose first, so a one-off piece never takes a repeated piece's id. Pieces
/// with no free id are `pieceN`. Then the author's renames apply (unless the name is taken).
fn name_pieces(graph: &Graph, regions: &[Region], work: &Work, design: &mut Design) -> Vec<String> {
    let n = design.pieces.len();
    let sources = instance_sources(graph, regions, design);
    let mut counts = vec![0usize; n];
    for s in &sources {
        counts[s.piece] += 1;
    }
    // Each piece's ids, most frequent first (ties: in instance order).
    let mut seen: Vec<Vec<(String, usize)>> = vec![Vec::new(); n];
    let mut where_seen: HashMap<(usize, String), usize> = HashMap::new();
    for s in &sources {
        let Some(name) = s.id.and_then(name_from_id) else {
            continue;
        };
        let list = &mut seen[s.piece];
        match where_seen.get(&(s.piece, name.clone())) {
            Some(&k) => list[k].1 += 1,
            None => {
                where_seen.insert((s.piece, name.clone()), list.len());
                list.push((name, 1));
            }
        }
    }
    let ids: Vec<Vec<String>> = seen
        .into_iter()
        .map(|mut list| {
            list.sort_by_key(|(_, k)| std::cmp::Reverse(*k));
            list.into_iter().map(|(s, _)| s).collect()
        })
        .collect();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&p| std::cmp::Reverse(counts[p]));
    let mut taken: HashSet<String> = ["base".to_string()].into_iter().collect();
    let mut names: Vec<Option<String>> = vec![None; n];
    for &p in &order {
        if let Some(id) = ids[p].iter().find(|i| !taken.contains(*i)) {
            taken.insert(id.clone());
            names[p] = Some(id.clone());
        }
    }
    let generated: Vec<String> = (0..n)
        .map(|p| {
            names[p].clone().unwrap_or_else(|| {
                let name = (p + 1..)
                    .map(|k| format!("piece{k}"))
                    .find(|g| !taken.contains(g))
                    .unwrap_or_default();
                taken.insert(name.clone());
                name
            })
        })
        .collect();
    let mut shown = generated.clone();
    for (p, g) in generated.iter().enumerate() {
        let Some(to) = work.piece_names.get(g) else {
            continue;
        };
        if shown.iter().enumerate().any(|(q, s)| q != p && s == to) {
            design.notes.push(format!(
                "the rename of `{g}` to `{to}` no longer applies: another piece is `{to}`"
            ));
        } else {
            shown[p].clone_from(to);
        }
    }
    for (piece, name) in design.pieces.iter_mut().zip(&shown) {
        piece.name.clone_from(name);
    }
    let of: Vec<usize> = design.instances.iter().map(|i| i.piece).collect();
    let places = super::pieces::instance_places(graph, design);
    for (inst, name) in design
        .instances
        .iter_mut()
        .zip(super::pieces::instance_names(
            &shown,
            &of,
            &places,
            work.tolerance,
        ))
    {
        inst.name = name;
    }
    generated
}

/// Piece and site index of `piece.site`.
pub fn find_site(design: &Design, s: &SiteName) -> Option<(usize, usize)> {
    let p = design.pieces.iter().position(|p| p.name == s.piece)?;
    let si = design.pieces[p]
        .sites
        .iter()
        .position(|x| x.name == s.site)?;
    Some((p, si))
}

/// Piece and site index of an instance site `(instance, site)`.
fn piece_site(design: &Design, (instance, site): (usize, usize)) -> Option<(usize, usize)> {
    let p = design.instances.get(instance)?.piece;
    design.pieces.get(p)?.sites.get(site)?;
    Some((p, site))
}

/// The piece sites docked with `start` directly or through other docks, `start` first: they
/// must share one site type, since the written types dock only with themselves.
pub fn docked_sites(design: &Design, start: (usize, usize)) -> Vec<(usize, usize)> {
    let mut out = vec![start];
    let mut k = 0;
    while k < out.len() {
        let current = out[k];
        k += 1;
        for d in &design.docks {
            let (Some(a), Some(b)) = (piece_site(design, d.a), piece_site(design, d.b)) else {
                continue;
            };
            for (x, y) in [(a, b), (b, a)] {
                if x == current && !out.contains(&y) {
                    out.push(y);
                }
            }
        }
    }
    out
}

/// The edges two pieces must share to be variants: the outline's when both have one (the
/// library adds its own diagonals to make an outline rigid, and the variant takes the
/// stretch piece's), otherwise all of them.
fn reference_edges(
    a: &super::pieces::PieceDesign,
    b: &super::pieces::PieceDesign,
) -> (Vec<[usize; 2]>, Vec<[usize; 2]>) {
    let edges = |x: &super::pieces::PieceDesign| -> Vec<[usize; 2]> {
        let mut e: Vec<[usize; 2]> = match (&a.outline, &b.outline, &x.outline) {
            (Some(_), Some(_), Some(o)) => {
                (0..o.len()).map(|k| [o[k], o[(k + 1) % o.len()]]).collect()
            }
            _ => x.edges.clone(),
        };
        for [i, j] in &mut e {
            (*i, *j) = ((*i).min(*j), (*i).max(*j));
        }
        e.sort_unstable();
        e.dedup();
        e
    };
    (edges(a), edges(b))
}

/// How piece `v` can be written as a variant of piece `p` (E041: the same vertices in the same
/// order and the same places, the same edges and sites; a variant differs only in its proxy
/// geometry, as the chain is solved in `p`'s shape): `map[i]` is `p`'s vertex for `v`'s vertex `i`. The library
/// numbers each piece's vertices by its own geometry, so the editor matches them through the
/// site names and the edges, and writes the variant with `p`'s graph and its own positions.
pub fn variant_map(design: &Design, p: usize, v: usize) -> Result<Vec<usize>, String> {
    let (a, b) = (&design.pieces[p], &design.pieces[v]);
    let n = a.positions.len();
    if n != b.positions.len() {
        return Err(format!(
            "`{}` has {} vertices, `{}` has {}",
            b.name,
            b.positions.len(),
            a.name,
            n
        ));
    }
    let other_sites = || {
        format!(
            "`{}` has other sites (names, types or vertex counts) than `{}`",
            b.name, a.name
        )
    };
    if a.sites.len() != b.sites.len() {
        return Err(other_sites());
    }
    let mut map: Vec<Option<usize>> = vec![None; n];
    for sa in &a.sites {
        let sb = b
            .sites
            .iter()
            .find(|s| s.name == sa.name)
            .ok_or_else(other_sites)?;
        if sb.site_type != sa.site_type || sb.vertices.len() != sa.vertices.len() {
            return Err(other_sites());
        }
        for (&i, &j) in sb.vertices.iter().zip(&sa.vertices) {
            match map[i] {
                Some(k) if k != j => return Err(other_sites()),
                _ => map[i] = Some(j),
            }
        }
    }
    let (ea, eb) = reference_edges(a, b);
    let other_edges = || format!("`{}` has other edges than `{}`", b.name, a.name);
    if ea.len() != eb.len() {
        return Err(other_edges());
    }
    // The vertices on no site: a small search for an assignment that maps the edges onto
    // the edges (pieces have a handful of vertices).
    fn extend(
        map: &mut Vec<Option<usize>>,
        ea: &[[usize; 2]],
        eb: &[[usize; 2]],
        budget: &mut u32,
    ) -> bool {
        let consistent = eb.iter().all(|&[i, j]| match (map[i], map[j]) {
            (Some(x), Some(y)) => ea.contains(&[x.min(y), x.max(y)]),
            _ => true,
        });
        if !consistent || *budget == 0 {
            return false;
        }
        *budget -= 1;
        let Some(free) = map.iter().position(Option::is_none) else {
            return true;
        };
        for target in 0..map.len() {
            if map.contains(&Some(target)) {
                continue;
            }
            map[free] = Some(target);
            if extend(map, ea, eb, budget) {
                return true;
            }
            map[free] = None;
        }
        false
    }
    let mut budget = 100_000;
    if !extend(&mut map, &ea, &eb, &mut budget) {
        return Err(other_edges());
    }
    let map: Vec<usize> = map.into_iter().map(|m| m.unwrap_or(0)).collect();
    let mut mapped: Vec<[usize; 2]> = eb
        .iter()
        .map(|&[i, j]| [map[i].min(map[j]), map[i].max(map[j])])
        .collect();
    mapped.sort_unstable();
    if mapped != ea {
        return Err(other_edges());
    }
    // E041: in place, vertex for vertex (a 1.2 m piece among 1 m ones would be solved 1 m
    // long, and its chain would shrink without being touched)
    let moved = (b.positions.iter().enumerate())
        .find(|&(i, q)| q.distance(a.positions[map[i]]) > clay_dsl::DOCK_TOLERANCE);
    if let Some((i, q)) = moved {
        return Err(format!(
            "`{}` has a vertex at ({:.4}, {:.4}) where `{}` has it at ({:.4}, {:.4}): a variant \
             differs only in its proxy geometry",
            b.name, q.x, q.y, a.name, a.positions[map[i]].x, a.positions[map[i]].y
        ));
    }
    Ok(map)
}

/// Writes the variants into the stretch rule, each variant piece rewritten with the stretch
/// piece's vertices, edges and sites at its own positions; or notes why they no longer apply.
// Long because: each variant is matched, checked and rewritten in place in the syntax tree; the steps share the match tables.
fn add_variants(work: &Work, design: &mut Design, tree: &mut clay_dsl::syntax::File) {
    use clay_dsl::syntax::{Expr, Ident, Item, PieceStmt, Span, VariantEntry, VariantsDecl};
    if work.variants.is_empty() {
        return;
    }
    let Some(sp) = design.pieces.iter().position(|p| p.stretch.is_some()) else {
        design
            .notes
            .push("the variants no longer apply: no piece is stretchable".into());
        return;
    };
    let mut maps = Vec::new();
    for v in &work.variants {
        let found = match design.pieces.iter().position(|p| p.name == v.piece) {
            None => Err(format!("there is no piece `{}`", v.piece)),
            Some(vi) => variant_map(design, sp, vi).map(|m| (vi, m)),
        };
        match found {
            Ok(m) => maps.push(m),
            Err(problem) => {
                design
                    .notes
                    .push(format!("the variants no longer apply: {problem}"));
                return;
            }
        }
    }
    let piece_decl = |tree: &clay_dsl::syntax::File, name: &str| {
        tree.items
            .iter()
            .position(|i| matches!(i, Item::Piece(p) if p.name.name == name))
    };
    let Some(at) = piece_decl(tree, &design.pieces[sp].name) else {
        return;
    };
    let Item::Piece(stretch_decl) = tree.items[at].clone() else {
        return;
    };
    for (vi, map) in &maps {
        if *vi == sp {
            continue;
        }
        let variant = &design.pieces[*vi];
        let Some(at) = piece_decl(tree, &variant.name) else {
            continue;
        };
        let Item::Piece(decl) = &mut tree.items[at] else {
            continue;
        };
        // Vertex names as written, in the variant's order and in the stretch piece's.
        let names = |stmts: &[PieceStmt]| -> Vec<Ident> {
            stmts
                .iter()
                .filter_map(|s| match s {
                    PieceStmt::Vertex(v) => Some(v.name.clone()),
                    _ => None,
                })
                .collect()
        };
        let (own, shared) = (names(&decl.stmts), names(&stretch_decl.stmts));
        let mut inverse = vec![0; map.len()];
        for (i, &j) in map.iter().enumerate() {
            inverse[j] = i;
        }
        let own_decl = decl.stmts.clone();
        let position = |j: usize| {
            own_decl.iter().find_map(|s| match s {
                PieceStmt::Vertex(v) if own.get(inverse[j]) == Some(&v.name) => Some(v.pos.clone()),
                _ => None,
            })
        };
        let mut stmts = Vec::new();
        for s in &stretch_decl.stmts {
            match s {
                PieceStmt::Vertex(v) => {
                    let j = shared.iter().position(|n| n == &v.name).unwrap_or(0);
                    let mut v = v.clone();
                    if let Some(p) = position(j) {
                        v.pos = p;
                    }
                    stmts.push(PieceStmt::Vertex(v));
                }
                PieceStmt::Edges(_) => stmts.push(s.clone()),
                PieceStmt::Site(site) => {
                    let mut site = site.clone();
                    if let Some(PieceStmt::Site(o)) = own_decl
                        .iter()
                        .find(|o| matches!(o, PieceStmt::Site(o) if o.name == site.name))
                    {
                        site.out = o.out.clone();
                    }
                    stmts.push(PieceStmt::Site(site));
                }
                _ => {}
            }
        }
        for s in own_decl {
            match s {
                PieceStmt::Vertex(_) | PieceStmt::Edges(_) | PieceStmt::Site(_) => {}
                PieceStmt::State(mut st) => {
                    // The state's positions follow the vertices to their new names.
                    for p in &mut st.positions {
                        if let Some(i) = own.iter().position(|n| n.name == p.name.name)
                            && let Some(n) = shared.get(map[i])
                        {
                            p.name = n.clone();
                        }
                    }
                    stmts.push(PieceStmt::State(st));
                }
                other => stmts.push(other),
            }
        }
        decl.stmts = stmts;
    }
    let entries = work
        .variants
        .iter()
        .map(|v| VariantEntry {
            piece: Ident {
                name: v.piece.clone(),
                span: Span::default(),
            },
            frequency: Expr::number(v.frequency, Span::default()),
            span: Span::default(),
        })
        .collect();
    for item in &mut tree.items {
        if let Item::Stretch(s) = item
            && s.piece.name == design.pieces[sp].name
        {
            s.variants = vec![VariantsDecl {
                entries,
                span: Span::default(),
            }];
            return;
        }
    }
}

/// Writes the alternative rest states into their pieces, or notes why they no longer apply.
fn add_states(work: &Work, design: &mut Design, tree: &mut clay_dsl::syntax::File) {
    use clay_dsl::syntax::{Expr, Ident, Item, PieceStmt, Point, Span, StateDecl, VertexDecl};
    let number = |value: f64| Expr::number((value * 1e6).round() / 1e6, Span::default());
    for st in &work.states {
        let piece = tree.items.iter_mut().find_map(|i| match i {
            Item::Piece(p) if p.name.name == st.piece => Some(p),
            _ => None,
        });
        let Some(piece) = piece else {
            design.notes.push(format!(
                "state `{}` no longer applies: there is no piece `{}`",
                st.name, st.piece
            ));
            continue;
        };
        let vertices: Vec<Ident> = piece
            .stmts
            .iter()
            .filter_map(|s| match s {
                PieceStmt::Vertex(v) => Some(v.name.clone()),
                _ => None,
            })
            .collect();
        if vertices.len() != st.positions.len() {
            design.notes.push(format!(
                "state `{}` no longer applies: `{}` now has {} vertices, the state {}",
                st.name,
                st.piece,
                vertices.len(),
                st.positions.len()
            ));
            continue;
        }
        let positions = vertices
            .into_iter()
            .zip(&st.positions)
            .map(|(name, p)| VertexDecl {
                name,
                pos: Point {
                    x: number(p.x),
                    y: number(p.y),
                    span: Span::default(),
                },
                span: Span::default(),
            })
            .collect();
        piece.stmts.push(PieceStmt::State(StateDecl {
            name: Ident {
                name: st.name.clone(),
                span: Span::default(),
            },
            positions,
            edges: Vec::new(),
            geometry: Vec::new(),
            derive: None,
            span: Span::default(),
        }));
    }
}

fn site_path(s: &SiteName) -> clay_dsl::syntax::SitePath {
    use clay_dsl::syntax::{Ident, SitePath, Span};
    let ident = |name: &str| Ident {
        name: name.to_string(),
        span: Span::default(),
    };
    SitePath {
        piece: ident(&s.piece),
        site: ident(&s.site),
        span: Span::default(),
    }
}

fn merge_decl(m: &MergeChoice) -> clay_dsl::syntax::MergeDecl {
    clay_dsl::syntax::MergeDecl {
        mover: site_path(&m.mover),
        target: site_path(&m.target),
        junction: m.junction.as_ref().map(site_path),
        within: None,
        span: clay_dsl::syntax::Span::default(),
    }
}
