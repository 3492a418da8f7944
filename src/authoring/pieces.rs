//! From regions to a grammar design: regions equal up to a rigid motion become one piece with
//! several instances, contacts become typed docking sites and docks, a piece can be made
//! stretchable, and the design is written out as a `.clay` syntax tree.

use std::collections::{BTreeMap, HashMap, HashSet};

use clay_dsl::syntax::*;
use glam::DVec2;

use super::AuthorError;
use super::graph::{Contact, Graph, Region};

/// Fill of regions drawn without one.
const DEFAULT_FILL: [u8; 3] = [0xb5, 0x65, 0x1d];
/// Width (metres) of the polylines that draw regions without a closed outline.
const STROKE_WIDTH: f64 = 0.05;

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

fn round6(x: f64) -> f64 {
    let r = (x * 1e6).round() / 1e6;
    if r == 0.0 { 0.0 } else { r }
}

fn round_point(p: DVec2) -> DVec2 {
    DVec2::new(round6(p.x), round6(p.y))
}

fn rotate(p: DVec2, angle: f64) -> DVec2 {
    DVec2::from_angle(angle).rotate(p)
}

/// The rigid motion taking region `rep` onto region `other` within `tol`, as (angle,
/// translation, `map[i]` = index in `other` of vertex `i` of `rep`); of all motions that fit
/// (a symmetric shape has several) the one turning least.
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
    let mut best: Option<(f64, DVec2, Vec<usize>)> = None;
    for angle in angles {
        let shift = co - rotate(cr, angle);
        let mut map = Vec::with_capacity(rep.len());
        let mut used = vec![false; other.len()];
        for p in rep {
            let q = rotate(*p, angle) + shift;
            let hit = (0..other.len())
                .filter(|&j| !used[j])
                .min_by(|&a, &b| other[a].distance(q).total_cmp(&other[b].distance(q)));
            match hit {
                Some(j) if other[j].distance(q) <= 2.0 * tol => {
                    used[j] = true;
                    map.push(j);
                }
                _ => break,
            }
        }
        if map.len() != rep.len() {
            continue;
        }
        if !rep_edges
            .iter()
            .all(|e| other_edges.contains(&[map[e[0]].min(map[e[1]]), map[e[0]].max(map[e[1]])]))
        {
            continue;
        }
        if best.as_ref().is_none_or(|b| angle.abs() < b.0.abs() - 1e-9) {
            best = Some((angle, shift, map));
        }
    }
    best
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
    for (ri, region) in regions.iter().enumerate() {
        let (pts, edges) = local(region);
        let found = reps.iter().enumerate().find_map(|(pi, rep)| {
            congruence(&rep.points, &rep.edges, &pts, &edges, tol).map(|m| (pi, m))
        });
        let (piece, angle, shift, map) = match found {
            Some((pi, (angle, shift, map))) => (pi, angle, shift, map),
            None => {
                design.pieces.push(new_piece(graph, region, &pts, &edges));
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
    name_pieces(graph, regions, &mut design);
    // Contacts -> sites (per piece, keyed by their vertex set) and docks.
    let mut type_keys: Vec<(usize, Vec<i64>)> = Vec::new();
    for c in contacts {
        let (ia, ib) = (instance_of_region[c.a], instance_of_region[c.b]);
        let sa = site_for(
            &mut design,
            &mut type_keys,
            ia,
            &c.pairs.iter().map(|p| p.0).collect::<Vec<_>>(),
        );
        let sb = site_for(
            &mut design,
            &mut type_keys,
            ib,
            &c.pairs.iter().map(|p| p.1).collect::<Vec<_>>(),
        );
        let (Some(sa), Some(sb)) = (sa, sb) else {
            continue;
        };
        // Docked sites meet like gear teeth: vertex i of one is vertex n-1-i of the other.
        let va = &design.pieces[design.instances[ia].piece].sites[sa].vertices;
        let vb = &design.pieces[design.instances[ib].piece].sites[sb].vertices;
        let n = va.len();
        let meets = vb.len() == n
            && (0..n).all(|i| {
                let ga = design.instances[ia].vertices[va[i]];
                let gb = design.instances[ib].vertices[vb[n - 1 - i]];
                c.pairs.contains(&(ga, gb))
            });
        if meets {
            design.docks.push(DockDesign {
                a: (ia, sa),
                b: (ib, sb),
            });
        } else {
            design.notes.push(format!(
                "`{}` and `{}` touch, but their shared vertices do not pair up as docked sites need (vertex i with vertex n-1-i); they are left undocked",
                design.instances[ia].name, design.instances[ib].name
            ));
        }
    }
    for p in &mut design.pieces {
        name_sites(p);
    }
    design.site_types = (0..type_keys.len())
        .map(|i| {
            if type_keys.len() == 1 {
                "joint".to_string()
            } else {
                format!("joint{}", i + 1)
            }
        })
        .collect();
    Ok(design)
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
    let mut edges: Vec<[usize; 2]> = edges.iter().copied().collect();
    edges.sort_unstable();
    // A quadrilateral of edges can shear; a fan of diagonals makes the outline rigid.
    if let Some(o) = &outline {
        for k in 2..o.len().saturating_sub(1) {
            let e = [o[0].min(o[k]), o[0].max(o[k])];
            if !edges.contains(&e) {
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

/// Names pieces after the drawing's ids (`brick3` -> `brick`) when they are unambiguous,
/// else `piece1`, `piece2`, ...; instances are the piece name and a number.
fn name_pieces(graph: &Graph, regions: &[Region], design: &mut Design) {
    let mut taken: HashSet<String> = ["base".to_string()].into_iter().collect();
    for (pi, piece) in design.pieces.iter_mut().enumerate() {
        let first = design
            .instances
            .iter()
            .find(|i| i.piece == pi)
            .map(|i| i.region);
        let drawn = first
            .and_then(|r| regions[r].source)
            .and_then(|s| graph.sources.get(s))
            .and_then(|s| s.1.as_deref())
            .and_then(clean_name);
        let name = match drawn {
            Some(n) if !taken.contains(&n) => n,
            _ => format!("piece{}", pi + 1),
        };
        taken.insert(name.clone());
        piece.name = name;
    }
    let mut counts = vec![0usize; design.pieces.len()];
    for inst in &mut design.instances {
        inst.name = format!("{}{}", design.pieces[inst.piece].name, counts[inst.piece]);
        counts[inst.piece] += 1;
    }
}

/// The site of `instance`'s piece made of the given graph vertices (created on first use).
fn site_for(
    design: &mut Design,
    type_keys: &mut Vec<(usize, Vec<i64>)>,
    instance: usize,
    graph_vertices: &[usize],
) -> Option<usize> {
    let inst = &design.instances[instance];
    let mut vs: Vec<usize> = graph_vertices
        .iter()
        .map(|g| inst.vertices.iter().position(|v| v == g))
        .collect::<Option<_>>()?;
    let piece = &mut design.pieces[inst.piece];
    let mut sorted = vs.clone();
    sorted.sort_unstable();
    if let Some(i) = piece.sites.iter().position(|s| {
        let mut k = s.vertices.clone();
        k.sort_unstable();
        k == sorted
    }) {
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
    vs.sort_by(|&a, &b| rel(a).total_cmp(&rel(b)));
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
    // Sites of one shape (vertex count and distances) share a type.
    let mut dists: Vec<i64> = Vec::new();
    for (i, &a) in vs.iter().enumerate() {
        for &b in &vs[i + 1..] {
            dists.push((pos[a].distance(pos[b]) * 1e3).round() as i64);
        }
    }
    dists.sort_unstable();
    let tkey = (vs.len(), dists);
    let site_type = match type_keys.iter().position(|k| *k == tkey) {
        Some(t) => t,
        None => {
            type_keys.push(tkey);
            type_keys.len() - 1
        }
    };
    piece.sites.push(SiteDesign {
        name: String::new(),
        site_type,
        vertices: vs,
        out,
    });
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

impl Design {
    /// Makes one piece stretchable (paper 5.1) between two opposite sites.
    pub fn make_stretchable(&mut self, choice: &StretchChoice) -> Result<(), AuthorError> {
        let (piece, from, to) = match *choice {
            StretchChoice::Sites { piece, from, to } => (piece, from, to),
            StretchChoice::Auto => self.auto_stretch()?,
        };
        let p = self
            .pieces
            .get(piece)
            .ok_or_else(|| AuthorError(format!("there is no piece {piece}")))?;
        let (Some(a), Some(b)) = (p.sites.get(from), p.sites.get(to)) else {
            return Err(AuthorError(format!(
                "piece `{}` has no sites {from} and {to}",
                p.name
            )));
        };
        if from == to || a.out.dot(b.out) >= -0.5 {
            return Err(AuthorError(format!(
                "sites `{}` and `{}` of piece `{}` do not point opposite ways; a stretchable piece repeats between two opposite sites",
                a.name, b.name, p.name
            )));
        }
        self.pieces[piece].stretch = Some([from, to]);
        Ok(())
    }

    fn auto_stretch(&self) -> Result<(usize, usize, usize), AuthorError> {
        let mut counts = vec![0usize; self.pieces.len()];
        for i in &self.instances {
            counts[i.piece] += 1;
        }
        let piece = (0..self.pieces.len())
            .max_by_key(|&p| (counts[p], std::cmp::Reverse(p)))
            .unwrap_or(0);
        let mut pairs: BTreeMap<(usize, usize), usize> = BTreeMap::new();
        for d in &self.docks {
            if self.instances[d.a.0].piece == piece
                && self.instances[d.b.0].piece == piece
                && d.a.1 != d.b.1
            {
                *pairs
                    .entry((d.a.1.min(d.b.1), d.a.1.max(d.b.1)))
                    .or_default() += 1;
            }
        }
        let sites = &self.pieces[piece].sites;
        let best = pairs
            .into_iter()
            .filter(|((a, b), _)| sites[*a].out.dot(sites[*b].out) < -0.5)
            .max_by_key(|&((a, b), n)| (n, std::cmp::Reverse((a, b))))
            .map(|(k, _)| k);
        let Some((a, b)) = best else {
            return Err(AuthorError(format!(
                "no two instances of `{}` are docked through opposite sites, so there is no row to stretch",
                self.pieces[piece].name
            )));
        };
        // From the west (or south) site to the east (or north) one, so rows read left to right.
        let key = |s: usize| (sites[s].out.x, sites[s].out.y);
        let (from, to) = if key(a) < key(b) { (a, b) } else { (b, a) };
        Ok((piece, from, to))
    }

    /// Maximal runs of instances of a stretchable piece docked `to` -> `from`, in order; runs
    /// of two or more are written as chains.
    pub fn chains(&self) -> Vec<Vec<usize>> {
        let mut next: HashMap<usize, usize> = HashMap::new();
        let mut has_prev: HashSet<usize> = HashSet::new();
        for d in &self.docks {
            for (x, y) in [(d.a, d.b), (d.b, d.a)] {
                let pi = self.instances[x.0].piece;
                let Some([from, to]) = self.pieces[pi].stretch else {
                    continue;
                };
                if self.instances[y.0].piece == pi
                    && x.1 == to
                    && y.1 == from
                    && !next.contains_key(&x.0)
                    && !has_prev.contains(&y.0)
                {
                    next.insert(x.0, y.0);
                    has_prev.insert(y.0);
                }
            }
        }
        let mut seen = HashSet::new();
        let mut chains = Vec::new();
        // Starts: instances with a successor and no predecessor; then whatever is left (rings).
        let starts: Vec<usize> = (0..self.instances.len())
            .filter(|i| next.contains_key(i) && !has_prev.contains(i))
            .chain((0..self.instances.len()).filter(|i| next.contains_key(i)))
            .collect();
        for s in starts {
            if seen.contains(&s) {
                continue;
            }
            let mut run = vec![s];
            seen.insert(s);
            let mut cur = s;
            while let Some(&n) = next.get(&cur) {
                if !seen.insert(n) {
                    break;
                }
                run.push(n);
                cur = n;
            }
            if run.len() >= 2 {
                chains.push(run);
            }
        }
        chains
    }

    /// The design as a `.clay` syntax tree (default spans); print it with
    /// [`clay_dsl::print_file`].
    pub fn to_syntax(&self) -> File {
        let mut items = Vec::new();
        for t in &self.site_types {
            items.push(Item::SiteType(SiteTypeDecl {
                name: ident(t),
                docks: Vec::new(),
                span: Span::default(),
            }));
        }
        for p in &self.pieces {
            items.push(Item::Piece(self.piece_decl(p)));
        }
        for p in &self.pieces {
            if let Some([from, to]) = p.stretch {
                items.push(Item::Stretch(StretchDecl {
                    piece: ident(&p.name),
                    from: ident(&p.sites[from].name),
                    to: ident(&p.sites[to].name),
                    min: vec![number(2.0)],
                    max: Vec::new(),
                    variants: Vec::new(),
                    span: Span::default(),
                }));
            }
        }
        items.push(Item::Model(self.model_block()));
        File {
            items,
            span: Span::default(),
        }
    }

    fn piece_decl(&self, p: &PieceDesign) -> PieceDecl {
        let v = |i: usize| ident(&format!("v{i}"));
        let mut stmts: Vec<PieceStmt> = p
            .positions
            .iter()
            .enumerate()
            .map(|(i, pos)| {
                PieceStmt::Vertex(VertexDecl {
                    name: v(i),
                    pos: point(*pos),
                    span: Span::default(),
                })
            })
            .collect();
        let mut paths: Vec<Vec<Ident>> = Vec::new();
        let mut written: HashSet<[usize; 2]> = HashSet::new();
        if let Some(o) = &p.outline {
            let mut path: Vec<Ident> = o.iter().map(|&i| v(i)).collect();
            path.push(v(o[0]));
            paths.push(path);
            for k in 0..o.len() {
                let (a, b) = (o[k], o[(k + 1) % o.len()]);
                written.insert([a.min(b), a.max(b)]);
            }
        }
        for e in &p.edges {
            if written.insert(*e) {
                paths.push(vec![v(e[0]), v(e[1])]);
            }
        }
        if !paths.is_empty() {
            stmts.push(PieceStmt::Edges(EdgesDecl {
                paths,
                span: Span::default(),
            }));
        }
        for s in &p.sites {
            stmts.push(PieceStmt::Site(SiteDecl {
                name: ident(&s.name),
                site_type: ident(&self.site_types[s.site_type]),
                vertices: s.vertices.iter().map(|&i| v(i)).collect(),
                vertices_span: Span::default(),
                out: point(s.out),
                span: Span::default(),
            }));
        }
        let binding = Some((
            if p.stretch.is_some() {
                BindingKw::Skinned
            } else {
                BindingKw::Rigid
            },
            Span::default(),
        ));
        let fill = Colour {
            rgba: [p.fill[0], p.fill[1], p.fill[2], 255],
            span: Span::default(),
        };
        match &p.outline {
            Some(o) => stmts.push(PieceStmt::Geometry(GeometryDecl {
                shape: ShapeDecl::Polygon {
                    outer: o.iter().map(|&i| point(p.positions[i])).collect(),
                    holes: Vec::new(),
                },
                binding,
                fill,
                extrude: None,
                keyword: Span::default(),
                span: Span::default(),
            })),
            None => {
                for e in &p.edges {
                    stmts.push(PieceStmt::Geometry(GeometryDecl {
                        shape: ShapeDecl::Polyline {
                            width: number(STROKE_WIDTH),
                            points: vec![point(p.positions[e[0]]), point(p.positions[e[1]])],
                        },
                        binding,
                        fill,
                        extrude: None,
                        keyword: Span::default(),
                        span: Span::default(),
                    }));
                }
            }
        }
        PieceDecl {
            name: ident(&p.name),
            extends: None,
            stmts,
            span: Span::default(),
        }
    }

    // Long because: the model block's items in order (instances, chains, placement, docks).
    fn model_block(&self) -> ModelBlock {
        let chains = self.chains();
        let mut chain_of: HashMap<usize, (usize, usize)> = HashMap::new();
        let mut chain_names = Vec::new();
        let mut per_piece: HashMap<usize, usize> = HashMap::new();
        for (c, run) in chains.iter().enumerate() {
            for (k, &i) in run.iter().enumerate() {
                chain_of.insert(i, (c, k));
            }
            let piece = self.instances[run[0]].piece;
            let n = per_piece.entry(piece).or_insert(0);
            *n += 1;
            let base = format!("{}_chain", self.pieces[piece].name);
            chain_names.push(if *n == 1 { base } else { format!("{base}{n}") });
        }
        // One instance per connected group is placed with `at`; the rest through their docks.
        let n = self.instances.len();
        let mut parent: Vec<usize> = (0..n).collect();
        fn find(p: &mut [usize], mut x: usize) -> usize {
            while p[x] != x {
                p[x] = p[p[x]];
                x = p[x];
            }
            x
        }
        for d in &self.docks {
            let (a, b) = (find(&mut parent, d.a.0), find(&mut parent, d.b.0));
            parent[a.max(b)] = a.min(b);
        }
        let mut placed_root: HashMap<usize, usize> = HashMap::new();
        for run in &chains {
            let r = find(&mut parent, run[0]);
            placed_root.entry(r).or_insert(run[0]);
        }
        for i in 0..n {
            let r = find(&mut parent, i);
            placed_root.entry(r).or_insert(i);
        }
        let anchored: HashSet<usize> = placed_root.values().copied().collect();
        let place = |i: usize| -> (Option<Point>, Option<Expr>) {
            if !anchored.contains(&i) {
                return (None, None);
            }
            let inst = &self.instances[i];
            let mut deg = round6(inst.angle.to_degrees());
            if deg <= -180.0 {
                deg += 360.0;
            }
            (
                Some(point(round_point(inst.at))),
                (deg != 0.0).then(|| number(deg)),
            )
        };
        let mut stmts = Vec::new();
        for (i, inst) in self.instances.iter().enumerate() {
            let (at, rotate) = place(i);
            match chain_of.get(&i) {
                Some(&(c, 0)) => stmts.push(ModelStmt::Chain(ChainDecl {
                    name: ident(&chain_names[c]),
                    piece: ident(&self.pieces[inst.piece].name),
                    count: number(chains[c].len() as f64),
                    along: None,
                    at,
                    rotate,
                    span: Span::default(),
                })),
                Some(_) => {}
                None => stmts.push(ModelStmt::Instance(InstanceDecl {
                    name: ident(&inst.name),
                    piece: ident(&self.pieces[inst.piece].name),
                    at,
                    rotate,
                    span: Span::default(),
                })),
            }
        }
        let site_path = |(i, s): (usize, usize)| -> InstanceSitePath {
            let site = ident(&self.pieces[self.instances[i].piece].sites[s].name);
            match chain_of.get(&i) {
                Some(&(c, k)) => InstanceSitePath {
                    instance: ident(&chain_names[c]),
                    index: Some(ElementIndex {
                        index: ElementIndexKind::At(k as u64),
                        span: Span::default(),
                    }),
                    site,
                    span: Span::default(),
                },
                None => InstanceSitePath {
                    instance: ident(&self.instances[i].name),
                    index: None,
                    site,
                    span: Span::default(),
                },
            }
        };
        for d in &self.docks {
            // Docks inside a chain are implied by the chain.
            let internal = |x: (usize, usize), y: (usize, usize)| match (
                chain_of.get(&x.0),
                chain_of.get(&y.0),
            ) {
                (Some(&(c1, k1)), Some(&(c2, k2))) => c1 == c2 && k2 == k1 + 1,
                _ => false,
            };
            if internal(d.a, d.b) || internal(d.b, d.a) {
                continue;
            }
            stmts.push(ModelStmt::Dock(DockDecl {
                a: site_path(d.a),
                b: site_path(d.b),
                span: Span::default(),
            }));
        }
        ModelBlock {
            stmts,
            keyword: Span::default(),
            span: Span::default(),
        }
    }
}

fn ident(name: &str) -> Ident {
    Ident {
        name: name.to_string(),
        span: Span::default(),
    }
}

fn number(value: f64) -> Expr {
    Expr::number(value, Span::default())
}

fn point(p: DVec2) -> Point {
    Point {
        x: number(round6(p.x)),
        y: number(round6(p.y)),
        span: Span::default(),
    }
}
