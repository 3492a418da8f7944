//! From regions to a grammar design: regions equal up to a rigid motion become one piece with
//! several instances, contacts become typed docking sites and docks. Making a piece
//! stretchable and writing the design out as a `.clay` syntax tree are `write.rs`'s.

use std::collections::{HashMap, HashSet};

use glam::DVec2;

use super::drawing::AuthorError;
use super::graph::{Contact, Graph, Region};

/// Fill of regions drawn without one.
const DEFAULT_FILL: [u8; 3] = [0xb5, 0x65, 0x1d];

/// A docking site of a designed piece.
#[derive(Clone, Debug, PartialEq)]
pub struct SiteDesign {
    pub name: String,
    pub site_type: usize,
    /// Piece vertices, counter-clockwise around the piece.
    pub vertices: Vec<usize>,
    /// Unit outward direction.
    pub out: DVec2,
}

/// A designed piece, in its own coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct PieceDesign {
    pub name: String,
    pub positions: Vec<DVec2>,
    /// Edges as drawn, plus diagonals that make an outlined piece rigid.
    pub edges: Vec<[usize; 2]>,
    /// The boundary, counter-clockwise, when the piece is one closed outline.
    pub outline: Option<Vec<usize>>,
    pub sites: Vec<SiteDesign>,
    pub fill: [u8; 3],
    /// `[from, to]` sites when the piece is stretchable.
    pub stretch: Option<[usize; 2]>,
}

/// One instance: where its piece goes, and which graph vertex each piece vertex is.
#[derive(Clone, Debug, PartialEq)]
pub struct InstanceDesign {
    pub name: String,
    pub piece: usize,
    /// Rigid motion piece -> drawing: `rotate(p, angle) + at`.
    pub angle: f64,
    pub at: DVec2,
    pub region: usize,
    /// Graph vertex of each piece vertex.
    pub vertices: Vec<usize>,
}

/// Two instance sites docked: `(instance, site)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DockDesign {
    pub a: (usize, usize),
    pub b: (usize, usize),
}

/// How to pick the stretchable piece.
#[derive(Clone, Debug, PartialEq)]
pub enum StretchChoice {
    /// The piece with the most instances, between its two opposite sites docked most often
    /// between its own instances.
    Auto,
    /// This piece between these two of its sites (indices into [`Design::pieces`] and the
    /// piece's `sites`).
    Sites {
        piece: usize,
        from: usize,
        to: usize,
    },
}

/// A grammar in the making: everything [`Design::to_syntax`] writes out.
#[derive(Clone, Debug, PartialEq)]
pub struct Design {
    pub site_types: Vec<String>,
    pub pieces: Vec<PieceDesign>,
    pub instances: Vec<InstanceDesign>,
    pub docks: Vec<DockDesign>,
    /// Things the author should know (contacts that could not become docks, ...).
    pub notes: Vec<String>,
}

pub(crate) fn round6(x: f64) -> f64 {
    let r = (x * 1e6).round() / 1e6;
    if r == 0.0 { 0.0 } else { r }
}

pub(crate) fn round_point(p: DVec2) -> DVec2 {
    DVec2::new(round6(p.x), round6(p.y))
}

fn rotate(p: DVec2, angle: f64) -> DVec2 {
    DVec2::from_angle(angle).rotate(p)
}

/// The rigid motion taking region `rep` onto region `other` within `tol`, as (angle,
/// translation, `map[i]` = index in `other` of vertex `i` of `rep`); of all motions that fit
/// (a symmetric shape has several) the one turning least. Each vertex's partner is looked up
/// in a grid, so a fit costs about the number of vertices (issue 37).
fn congruence(
    rep: &[DVec2],
    rep_edges: &HashSet<[usize; 2]>,
    other: &[DVec2],
    other_edges: &HashSet<[usize; 2]>,
    tol: f64,
) -> Option<(f64, DVec2, Vec<usize>)> {
    if rep.len() != other.len() || rep_edges.len() != other_edges.len() || rep.is_empty() {
        return None;
    }
    let mean = |ps: &[DVec2]| ps.iter().copied().sum::<DVec2>() / ps.len() as f64;
    let (cr, co) = (mean(rep), mean(other));
    let far = (0..rep.len())
        .max_by(|&a, &b| (rep[a] - cr).length().total_cmp(&(rep[b] - cr).length()))?;
    let radius = (rep[far] - cr).length();
    let angles: Vec<f64> = if radius <= tol {
        vec![0.0]
    } else {
        other
            .iter()
            .filter(|o| ((**o - co).length() - radius).abs() <= 2.0 * tol)
            .map(|o| {
                let a = (*o - co).to_angle() - (rep[far] - cr).to_angle();
                (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
            })
            .collect()
    };
    // The motion turning least is the one wanted: try the angles in that order and take the
    // first that fits (a regular polygon of many corners fits at every one of them).
    let mut angles: Vec<(usize, f64)> = angles.into_iter().enumerate().collect();
    angles.sort_by(|x, y| x.1.abs().total_cmp(&y.1.abs()).then(x.0.cmp(&y.0)));
    let near = NearGrid::new(other, 2.0 * tol);
    for (_, angle) in angles {
        let shift = co - rotate(cr, angle);
        let mut map = Vec::with_capacity(rep.len());
        let mut used = vec![false; other.len()];
        for p in rep {
            let q = rotate(*p, angle) + shift;
            match near.nearest_unused(other, q, &used) {
                Some(j) => {
                    used[j] = true;
                    map.push(j);
                }
                None => break,
            }
        }
        if map.len() != rep.len() {
            continue;
        }
        if rep_edges
            .iter()
            .all(|e| other_edges.contains(&[map[e[0]].min(map[e[1]]), map[e[0]].max(map[e[1]])]))
        {
            return Some((angle, shift, map));
        }
    }
    None
}

/// Points bucketed in cells as wide as the distance asked about, for "the nearest point within
/// it": a look at nine cells instead of every point.
struct NearGrid {
    cell: f64,
    cells: HashMap<(i64, i64), Vec<usize>>,
}

impl NearGrid {
    fn new(points: &[DVec2], within: f64) -> Self {
        let mut grid = Self {
            cell: within,
            cells: HashMap::new(),
        };
        for (i, p) in points.iter().enumerate() {
            let c = grid.key(*p);
            grid.cells.entry(c).or_default().push(i);
        }
        grid
    }

    fn key(&self, p: DVec2) -> (i64, i64) {
        // Saturating: a point far beyond the drawing's limit only shares a cell with others.
        (
            (p.x / self.cell).floor() as i64,
            (p.y / self.cell).floor() as i64,
        )
    }

    /// The nearest point not yet `used` within the distance, the lowest index on a tie.
    fn nearest_unused(&self, points: &[DVec2], q: DVec2, used: &[bool]) -> Option<usize> {
        let (cx, cy) = self.key(q);
        let mut best: Option<(f64, usize)> = None;
        for dx in -1..=1i64 {
            for dy in -1..=1i64 {
                let c = (cx.saturating_add(dx), cy.saturating_add(dy));
                for &j in self.cells.get(&c).into_iter().flatten() {
                    let d = points[j].distance(q);
                    if !used[j] && d <= self.cell && best.is_none_or(|b| (d, j) < b) {
                        best = Some((d, j));
                    }
                }
            }
        }
        best.map(|(_, j)| j)
    }
}

/// What regions congruent within a tolerance have in common: their vertex and edge counts and
/// their radius of gyration (root mean square distance of the vertices from their centroid)
/// in steps of eight times the tolerance. Moving each vertex by up to twice the tolerance (as
/// [`congruence`] allows) moves the centroid and so each distance by up to four times it, so
/// congruent regions are in the same step or the next.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct ShapeClass {
    vertices: usize,
    edges: usize,
    step: i64,
}

impl ShapeClass {
    fn of(points: &[DVec2], edges: usize, tol: f64) -> Self {
        let n = points.len().max(1) as f64;
        let centre = points.iter().copied().sum::<DVec2>() / n;
        let gyration = (points
            .iter()
            .map(|p| p.distance_squared(centre))
            .sum::<f64>()
            / n)
            .sqrt();
        Self {
            vertices: points.len(),
            edges,
            step: (gyration / (8.0 * tol)).floor() as i64,
        }
    }

    /// This class and the steps either side.
    fn neighbours(self) -> impl Iterator<Item = ShapeClass> {
        (-1..=1).map(move |d| ShapeClass {
            step: self.step.saturating_add(d),
            ..self
        })
    }
}

/// Compass name of a direction.
fn compass(out: DVec2) -> &'static str {
    const NAMES: [&str; 8] = [
        "east",
        "north_east",
        "north",
        "north_west",
        "west",
        "south_west",
        "south",
        "south_east",
    ];
    let k = (out.to_angle() / std::f64::consts::FRAC_PI_4)
        .round()
        .rem_euclid(8.0) as usize;
    NAMES[k % 8]
}

/// A name usable in a `.clay` file: letters, digits and `_`, not starting with a digit.
pub(crate) fn clean_name(raw: &str) -> Option<String> {
    let s: String = raw
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    let s = s
        .trim_end_matches(|c: char| c.is_ascii_digit() || c == '_')
        .trim_start_matches(|c: char| c.is_ascii_digit() || c == '_');
    (!s.is_empty()).then(|| s.to_string())
}

/// Regions -> pieces, instances, site types, sites and docks.
// Long because: the piece-finding steps in order (congruence classes, site types, sites, docks) over shared tables.
pub fn find_pieces(
    graph: &Graph,
    regions: &[Region],
    contacts: &[Contact],
    tol: f64,
) -> Result<Design, AuthorError> {
    if regions.is_empty() {
        return Err(AuthorError("the drawing has no regions".into()));
    }
    struct Rep {
        points: Vec<DVec2>,
        edges: HashSet<[usize; 2]>,
    }
    let local = |r: &Region| -> (Vec<DVec2>, HashSet<[usize; 2]>) {
        let index: HashMap<usize, usize> = r
            .vertices
            .iter()
            .enumerate()
            .map(|(i, &v)| (v, i))
            .collect();
        let pts = r.vertices.iter().map(|&v| graph.positions[v]).collect();
        let edges = r
            .edges
            .iter()
            .map(|e| (index[&e[0]], index[&e[1]]))
            .map(|(a, b)| [a.min(b), a.max(b)])
            .collect();
        (pts, edges)
    };
    let mut reps: Vec<Rep> = Vec::new();
    let mut design = Design {
        site_types: Vec::new(),
        pieces: Vec::new(),
        instances: Vec::new(),
        docks: Vec::new(),
        notes: Vec::new(),
    };
    let mut instance_of_region = vec![usize::MAX; regions.len()];
    // Representatives by shape class, so that a region is compared only with those that could
    // be congruent to it (a drawing of two thousand different shapes asked every pair).
    let mut classes: HashMap<ShapeClass, Vec<usize>> = HashMap::new();
    for (ri, region) in regions.iter().enumerate() {
        let (pts, edges) = local(region);
        let class = ShapeClass::of(&pts, edges.len(), tol);
        let mut candidates: Vec<usize> = class
            .neighbours()
            .filter_map(|c| classes.get(&c))
            .flatten()
            .copied()
            .collect();
        candidates.sort_unstable();
        let found = candidates.iter().find_map(|&pi| {
            let rep = &reps[pi];
            congruence(&rep.points, &rep.edges, &pts, &edges, tol).map(|m| (pi, m))
        });
        let (piece, angle, shift, map) = match found {
            Some((pi, (angle, shift, map))) => (pi, angle, shift, map),
            None => {
                design.pieces.push(new_piece(graph, region, &pts, &edges));
                classes.entry(class).or_default().push(reps.len());
                reps.push(Rep {
                    points: pts.clone(),
                    edges,
                });
                (reps.len() - 1, 0.0, DVec2::ZERO, (0..pts.len()).collect())
            }
        };
        // Piece coordinates are the representative's, moved so its lower-left corner is at the
        // origin: drawing = rotate(piece + origin, angle) + shift.
        let origin = origin_of(&reps[piece].points);
        let vertices = map.iter().map(|&j| region.vertices[j]).collect();
        instance_of_region[ri] = design.instances.len();
        design.instances.push(InstanceDesign {
            name: String::new(),
            piece,
            angle,
            at: rotate(origin, angle) + shift,
            region: ri,
            vertices,
        });
    }
    name_pieces(graph, regions, &mut design, tol);
    // Contacts -> sites (per piece, keyed by their vertex set) and docks.
    let index_of: Vec<HashMap<usize, usize>> = design
        .instances
        .iter()
        .map(|i| {
            i.vertices
                .iter()
                .enumerate()
                .map(|(k, &v)| (v, k))
                .collect()
        })
        .collect();
    let mut sites = Sites::default();
    // Which instance each docked instance site docks with: a site docks once (E034).
    let mut docked: HashMap<(usize, usize), usize> = HashMap::new();
    for c in contacts {
        let (ia, ib) = (instance_of_region[c.a], instance_of_region[c.b]);
        if ia == usize::MAX || ib == usize::MAX || ia == ib {
            continue;
        }
        let firsts: Vec<usize> = c.pairs.iter().map(|p| p.0).collect();
        let seconds: Vec<usize> = c.pairs.iter().map(|p| p.1).collect();
        let sa = site_for(&mut design, &mut sites, &index_of[ia], ia, &firsts);
        let sb = site_for(&mut design, &mut sites, &index_of[ib], ib, &seconds);
        let (Some(sa), Some(sb)) = (sa, sb) else {
            continue;
        };
        // Docked sites meet like gear teeth: vertex i of one is vertex n-1-i of the other.
        let va = &design.pieces[design.instances[ia].piece].sites[sa].vertices;
        let vb = &design.pieces[design.instances[ib].piece].sites[sb].vertices;
        let n = va.len();
        let pairs: HashSet<(usize, usize)> = c.pairs.iter().copied().collect();
        let meets = vb.len() == n
            && (0..n).all(|i| {
                let ga = design.instances[ia].vertices[va[i]];
                let gb = design.instances[ib].vertices[vb[n - 1 - i]];
                pairs.contains(&(ga, gb))
            });
        let name = |i: usize| design.instances[i].name.clone();
        if !meets {
            design.notes.push(format!(
                "`{}` and `{}` touch, but their shared vertices do not pair up as docked sites need (vertex i with vertex n-1-i); they are left undocked",
                name(ia),
                name(ib)
            ));
            continue;
        }
        // Three shapes along one edge (overlapping shapes, a shape drawn twice slightly
        // apart): the first contact docks, the others are left undocked.
        if let Some(&(site_of, other)) = [((ia, sa), ib), ((ib, sb), ia)]
            .iter()
            .find_map(|(k, _)| docked.get(k).map(|o| (k, *o)))
            .as_ref()
        {
            design.notes.push(format!(
                "`{}` and `{}` touch where `{}` already docks with `{}` (a site docks once); they are left undocked",
                name(ia),
                name(ib),
                name(site_of.0),
                name(other)
            ));
            continue;
        }
        if design.turns_away((ia, sa), (ib, sb), tol) {
            design.notes.push(format!(
                "`{}` and `{}` touch, but docking them there would turn or move one away from where it is drawn; they are left undocked",
                name(ia),
                name(ib)
            ));
            continue;
        }
        docked.insert((ia, sa), ib);
        docked.insert((ib, sb), ia);
        design.docks.push(DockDesign {
            a: (ia, sa),
            b: (ib, sb),
        });
    }
    for p in &mut design.pieces {
        name_sites(p);
    }
    let count = unify_docked_types(&mut design, sites.types.len());
    design.site_types = (0..count)
        .map(|i| {
            if count == 1 {
                "joint".to_string()
            } else {
                format!("joint{}", i + 1)
            }
        })
        .collect();
    Ok(design)
}

/// Docked sites must be of one type (E030), and sites are typed by their shape to the
/// millimetre: two instances of pieces congruent within the tolerance can fall either side of
/// a rounding. Types joined by a dock become one, numbered again in the order they were made.
/// Returns the number of types.
fn unify_docked_types(design: &mut Design, count: usize) -> usize {
    let mut parent: Vec<usize> = (0..count).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    let type_of =
        |d: &Design, (i, s): (usize, usize)| design_site(d, i, s).map(|site| site.site_type);
    for dock in &design.docks {
        if let (Some(a), Some(b)) = (type_of(design, dock.a), type_of(design, dock.b)) {
            let (a, b) = (find(&mut parent, a), find(&mut parent, b));
            parent[a.max(b)] = a.min(b);
        }
    }
    // Roots are the lowest type of their class: numbering them in order keeps the types in
    // the order they were first made.
    let mut number = vec![0; count];
    let mut next = 0;
    for t in 0..count {
        let root = find(&mut parent, t);
        if root == t {
            number[t] = next;
            next += 1;
        } else {
            number[t] = number[root];
        }
    }
    for p in &mut design.pieces {
        for s in &mut p.sites {
            s.site_type = number[s.site_type];
        }
    }
    next
}

fn design_site(d: &Design, instance: usize, site: usize) -> Option<&SiteDesign> {
    d.pieces
        .get(d.instances.get(instance)?.piece)?
        .sites
        .get(site)
}

fn origin_of(points: &[DVec2]) -> DVec2 {
    round_point(
        points
            .iter()
            .copied()
            .fold(DVec2::splat(f64::INFINITY), DVec2::min),
    )
}

fn new_piece(
    graph: &Graph,
    region: &Region,
    pts: &[DVec2],
    edges: &HashSet<[usize; 2]>,
) -> PieceDesign {
    let origin = origin_of(pts);
    let positions: Vec<DVec2> = pts.iter().map(|p| round_point(*p - origin)).collect();
    let index: HashMap<usize, usize> = region
        .vertices
        .iter()
        .enumerate()
        .map(|(i, &v)| (v, i))
        .collect();
    let outline: Option<Vec<usize>> = region
        .outline
        .as_ref()
        .map(|o| o.iter().map(|v| index[v]).collect());
    let drawn = edges;
    let mut edges: Vec<[usize; 2]> = drawn.iter().copied().collect();
    edges.sort_unstable();
    // A quadrilateral of edges can shear; a fan of diagonals makes the outline rigid.
    if let Some(o) = &outline {
        for k in 2..o.len().saturating_sub(1) {
            let e = [o[0].min(o[k]), o[0].max(o[k])];
            if !drawn.contains(&e) {
                edges.push(e);
            }
        }
    }
    let fill = region
        .source
        .and_then(|s| graph.sources.get(s))
        .and_then(|s| s.0)
        .unwrap_or(DEFAULT_FILL);
    PieceDesign {
        name: String::new(),
        positions,
        edges,
        outline,
        sites: Vec::new(),
        fill,
        stretch: None,
    }
}

/// Names pieces after the drawing's ids (`brick3` -> `brick`) when they are unambiguous and
/// not a keyword, else `piece1`, `piece2`, ...; instances are named by [`instance_names`].
fn name_pieces(graph: &Graph, regions: &[Region], design: &mut Design, tol: f64) {
    let mut taken: HashSet<String> = ["base".to_string()].into_iter().collect();
    let mut first = vec![None; design.pieces.len()];
    for i in &design.instances {
        first[i.piece].get_or_insert(i.region);
    }
    for (pi, piece) in design.pieces.iter_mut().enumerate() {
        let drawn = first[pi]
            .and_then(|r| regions[r].source)
            .and_then(|s| graph.sources.get(s))
            .and_then(|s| s.1.as_deref())
            .and_then(clean_name)
            .filter(|n| !clay_dsl::analysis::KEYWORDS.contains(&n.as_str()));
        let name = match drawn {
            Some(n) if !taken.contains(&n) => n,
            _ => (pi + 1..)
                .map(|k| format!("piece{k}"))
                .find(|g| !taken.contains(g))
                .unwrap_or_default(),
        };
        taken.insert(name.clone());
        piece.name = name;
    }
    let piece_names: Vec<String> = design.pieces.iter().map(|p| p.name.clone()).collect();
    let of: Vec<usize> = design.instances.iter().map(|i| i.piece).collect();
    let places = instance_places(graph, design);
    for (inst, name) in
        design
            .instances
            .iter_mut()
            .zip(instance_names(&piece_names, &of, &places, tol))
    {
        inst.name = name;
    }
}

/// Where each instance of `design` is: the centroid of its vertices in the drawing.
pub(crate) fn instance_places(graph: &Graph, design: &Design) -> Vec<DVec2> {
    (design.instances.iter())
        .map(|i| {
            let points: Vec<DVec2> = (i.vertices.iter())
                .filter_map(|&v| graph.positions.get(v).copied())
                .collect();
            points.iter().sum::<DVec2>() / points.len().max(1) as f64
        })
        .collect()
}

/// Instance names, all different (E010): the piece's name and a count from 0 (`brick0`,
/// `brick1`), with `_` between when the name ends in a digit (`piece1_0`: `piece10` could be
/// `piece1`'s eleventh instance or `piece10`'s first). A name still taken (a piece renamed to
/// end in `_`, say) gets `_2`, `_3`, ... `of[i]` is instance `i`'s piece and `places[i]` where
/// it is: each piece counts its instances in reading order (top to bottom, then left to right,
/// places within `tol` counting as level), not in the order the drawing's regions were found.
pub(crate) fn instance_names(
    pieces: &[String],
    of: &[usize],
    places: &[DVec2],
    tol: f64,
) -> Vec<String> {
    let tol = if tol.is_finite() && tol > 0.0 {
        tol
    } else {
        1e-9
    };
    let level = |x: f64| (x / tol).round() as i64;
    let mut order: Vec<usize> = (0..of.len()).collect();
    order.sort_by_key(|&i| {
        let p = places.get(i).copied().unwrap_or(DVec2::ZERO);
        (-level(p.y), level(p.x), i)
    });
    let mut counts = vec![0usize; pieces.len()];
    let mut taken: HashSet<String> = HashSet::new();
    let mut names = vec![String::new(); of.len()];
    for i in order {
        let p = of[i];
        let name = &pieces[p];
        let sep = if name.ends_with(|c: char| c.is_ascii_digit()) {
            "_"
        } else {
            ""
        };
        let base = format!("{name}{sep}{}", counts[p]);
        counts[p] += 1;
        let unique = std::iter::once(base.clone())
            .chain((2..).map(|k| format!("{base}_{k}")))
            .find(|n| !taken.contains(n))
            .unwrap_or(base);
        taken.insert(unique.clone());
        names[i] = unique;
    }
    names
}

/// The sites made so far and their types: per piece, its sites by their sorted vertices; the
/// type of each site shape.
#[derive(Default)]
struct Sites {
    by_vertices: HashMap<(usize, Vec<usize>), usize>,
    types: HashMap<(usize, Vec<i64>), usize>,
}

/// The site of `instance`'s piece made of the given graph vertices (created on first use).
fn site_for(
    design: &mut Design,
    sites: &mut Sites,
    index_of: &HashMap<usize, usize>,
    instance: usize,
    graph_vertices: &[usize],
) -> Option<usize> {
    let inst = &design.instances[instance];
    let mut vs: Vec<usize> = graph_vertices
        .iter()
        .map(|g| index_of.get(g).copied())
        .collect::<Option<_>>()?;
    let piece = &mut design.pieces[inst.piece];
    let mut sorted = vs.clone();
    sorted.sort_unstable();
    let key = (inst.piece, sorted);
    if let Some(&i) = sites.by_vertices.get(&key) {
        return Some(i);
    }
    let pos = &piece.positions;
    let centre = pos.iter().copied().sum::<DVec2>() / pos.len() as f64;
    let site_centre = vs.iter().map(|&v| pos[v]).sum::<DVec2>() / vs.len() as f64;
    let towards = (site_centre - centre).to_angle();
    // Counter-clockwise around the piece, starting from the side before the site's middle.
    let rel = |v: usize| {
        let a = (pos[v] - centre).to_angle() - towards;
        (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
    };
    vs.sort_by(|&a, &b| rel(a).total_cmp(&rel(b)).then(a.cmp(&b)));
    let mut out = DVec2::ZERO;
    for w in vs.windows(2) {
        let d = pos[w[1]] - pos[w[0]];
        out += DVec2::new(d.y, -d.x);
    }
    if out.length() < 1e-9 {
        out = site_centre - centre;
    }
    let out = out.try_normalize().unwrap_or(DVec2::X);
    let out = round_point(out);
    // Sites of one shape share a type: the shape is the vertex count, the distances between
    // neighbours along the site and from its first vertex to each (to the millimetre), read
    // from whichever end gives the smaller list, so that a site and the one it docks with
    // (which runs the other way) agree. Linear in the vertices: a site along a shared curve
    // of thousands of points is no burden.
    let d = |a: usize, b: usize| (pos[a].distance(pos[b]) * 1e3).round() as i64;
    let shape = |order: &[usize]| -> Vec<i64> {
        let along = order.windows(2).map(|w| d(w[0], w[1]));
        let from_first = order.iter().skip(1).map(|&v| d(order[0], v));
        along.chain(from_first).collect()
    };
    let backwards: Vec<usize> = vs.iter().rev().copied().collect();
    let tkey = (vs.len(), shape(&vs).min(shape(&backwards)));
    let next = sites.types.len();
    let site_type = *sites.types.entry(tkey).or_insert(next);
    piece.sites.push(SiteDesign {
        name: String::new(),
        site_type,
        vertices: vs,
        out,
    });
    sites.by_vertices.insert(key, piece.sites.len() - 1);
    Some(piece.sites.len() - 1)
}

/// Names sites by compass direction of `out` (`east`, `north_west`, ...), numbered on clashes.
fn name_sites(piece: &mut PieceDesign) {
    let vertex_names: HashSet<String> = (0..piece.positions.len())
        .map(|i| format!("v{i}"))
        .collect();
    let mut used: HashMap<String, usize> = HashMap::new();
    for s in &mut piece.sites {
        let base = compass(s.out).to_string();
        let n = used.entry(base.clone()).or_insert(0);
        *n += 1;
        s.name = if *n == 1 { base } else { format!("{base}{n}") };
        debug_assert!(!vertex_names.contains(&s.name));
    }
}
