//! The 2D graph of a drawing: snapped vertices, undirected edges, the closed paths as vertex
//! loops; cutting it at points; and splitting it into regions and the contacts between them.

use std::collections::{BTreeMap, HashMap, HashSet};

use glam::DVec2;

use super::drawing::{AuthorError, Drawing};
use super::grid::{PointGrid, self_crossing};

/// Largest absolute coordinate accepted (metres). The compiler takes coordinates up to 1e9 m;
/// a piece is written relative to its lower-left corner and an instance's `at` is where that
/// corner goes after a rotation, so those can reach about four times the drawing's extent: a
/// tenth of the compiler's limit keeps every written number inside it (issue 37).
pub const MAX_COORDINATE: f64 = 1e8;

/// Smallest snap (and congruence) tolerance accepted (metres). The grammar is written to the
/// micrometre, so vertices kept apart by a finer tolerance could be written at one place (E023)
/// or an edge with no length (E022); ten micrometres keeps them apart after rounding.
pub const MIN_TOLERANCE: f64 = 1e-5;

/// A closed path of the drawing as a cycle of graph vertices.
#[derive(Clone, Debug, PartialEq)]
pub struct Loop {
    pub vertices: Vec<usize>,
    /// Index of the drawing polyline it came from.
    pub source: usize,
}

/// The drawing as a graph.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Graph {
    pub positions: Vec<DVec2>,
    /// Undirected edges, each stored once with the smaller vertex first.
    pub edges: Vec<[usize; 2]>,
    /// For each edge, the drawing polyline it came from (for colours and names).
    pub edge_source: Vec<usize>,
    pub loops: Vec<Loop>,
    /// Fill colour and name of each drawing polyline.
    pub sources: Vec<(Option<[u8; 3]>, Option<String>)>,
    /// The snap tolerance it was built with (metres).
    pub snap: f64,
}

/// A graph split into regions: the regions, the contacts between them, and notes on what was
/// left out and why.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Split {
    pub regions: Vec<Region>,
    pub contacts: Vec<Contact>,
    pub notes: Vec<String>,
}

/// A region: the vertices and edges that become one instance of a piece.
#[derive(Clone, Debug, PartialEq)]
pub struct Region {
    /// Graph vertices, in a fixed order.
    pub vertices: Vec<usize>,
    /// Edges between graph vertices.
    pub edges: Vec<[usize; 2]>,
    /// The boundary as a counter-clockwise cycle of graph vertices, when the region is one.
    pub outline: Option<Vec<usize>>,
    /// Index into [`Graph::sources`] of the polyline most of it came from.
    pub source: Option<usize>,
}

/// Two regions touching: `pairs` lists (vertex of `a`, vertex of `b`) that coincide; they
/// become a pair of docked sites.
#[derive(Clone, Debug, PartialEq)]
pub struct Contact {
    pub a: usize,
    pub b: usize,
    pub pairs: Vec<(usize, usize)>,
}

/// What one cut did: `negative[i]` and `positive[i]` are the two copies of a vertex of the cut
/// section, on either side of the cut line.
#[derive(Clone, Debug, PartialEq)]
pub struct CutSection {
    pub at: DVec2,
    pub negative: Vec<usize>,
    pub positive: Vec<usize>,
}

fn key(a: usize, b: usize) -> [usize; 2] {
    [a.min(b), a.max(b)]
}

/// Distance from `p` to the segment `a-b` and the parameter of the nearest point.
fn segment_distance(p: DVec2, a: DVec2, b: DVec2) -> (f64, f64) {
    let (q, t) = crate::plane::nearest_on_segment(p, a, b);
    ((q - p).length(), t)
}

impl Graph {
    /// Builds the graph: points within `snap` of each other become one vertex, a vertex within
    /// `snap` of another stroke's segment splits that segment (a T-junction), and repeated edges
    /// are kept once.
    pub fn build(drawing: &Drawing, snap: f64) -> Result<Graph, AuthorError> {
        check_tolerance("snap tolerance", snap)?;
        let mut g = Graph {
            snap,
            ..Graph::default()
        };
        let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
        let mut strokes: Vec<(Vec<usize>, bool)> = Vec::new();
        for line in &drawing.polylines {
            g.sources.push((line.fill, line.name.clone()));
        }
        for (k, line) in drawing.polylines.iter().enumerate() {
            let mut ids: Vec<usize> = Vec::new();
            for &p in &line.points {
                if !(p.is_finite() && p.abs().max_element() <= MAX_COORDINATE) {
                    return Err(AuthorError(format!(
                        "{} has a point at {}, beyond the {MAX_COORDINATE:e} m a drawing may reach; check its coordinates and the scale",
                        g.stroke_name(k),
                        metres(p)
                    )));
                }
                let id = g.snap_vertex(&mut grid, p, snap);
                if ids.last() != Some(&id) {
                    ids.push(id);
                }
            }
            let mut closed = line.closed;
            if ids.len() > 1 && ids.first() == ids.last() {
                ids.pop();
                closed = true;
            }
            strokes.push((ids, closed && line.points.len() >= 3));
        }
        // T-junctions: a vertex lying on another stroke's segment splits it, so that both
        // strokes share it (bricks in staggered courses, a wall meeting another's side). A
        // grid of the vertices keeps this to the cells along each segment (issue 37: asking
        // every vertex of every segment took seconds on a path of ten thousand points).
        let grid = PointGrid::new(&g.positions, snap);
        let mut near = Vec::new();
        for (ids, closed) in &mut strokes {
            if ids.len() < 2 {
                continue;
            }
            let n = ids.len();
            let segments = if *closed { n } else { n - 1 };
            let mut out = Vec::with_capacity(n);
            for i in 0..segments {
                let (a, b) = (ids[i], ids[(i + 1) % n]);
                out.push(a);
                let (pa, pb) = (g.positions[a], g.positions[b]);
                grid.near_segment(pa, pb, &mut near);
                let mut inner: Vec<(f64, usize)> = near
                    .iter()
                    .copied()
                    .filter(|&c| c != a && c != b)
                    .filter_map(|c| {
                        let (d, t) = segment_distance(g.positions[c], pa, pb);
                        (d <= snap && t > 0.0 && t < 1.0).then_some((t, c))
                    })
                    .collect();
                inner.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
                out.extend(inner.into_iter().map(|(_, c)| c));
            }
            if !*closed {
                out.push(ids[n - 1]);
            }
            *ids = out;
        }
        let mut seen = HashSet::new();
        for (k, (ids, closed)) in strokes.iter().enumerate() {
            let n = ids.len();
            let segments = if *closed && n >= 3 {
                n
            } else {
                n.saturating_sub(1)
            };
            for i in 0..segments {
                let e = key(ids[i], ids[(i + 1) % n]);
                if e[0] != e[1] && seen.insert(e) {
                    g.edges.push(e);
                    g.edge_source.push(k);
                }
            }
            if *closed && n >= 3 {
                g.loops.push(Loop {
                    vertices: ids.clone(),
                    source: k,
                });
            }
        }
        if g.edges.is_empty() {
            return Err(AuthorError(
                "the drawing has no strokes (no path with two distinct points)".into(),
            ));
        }
        Ok(g)
    }

    fn snap_vertex(
        &mut self,
        grid: &mut HashMap<(i64, i64), Vec<usize>>,
        p: DVec2,
        snap: f64,
    ) -> usize {
        let cell = ((p.x / snap).floor() as i64, (p.y / snap).floor() as i64);
        for dx in -1..=1 {
            for dy in -1..=1 {
                if let Some(list) = grid.get(&(cell.0 + dx, cell.1 + dy)) {
                    for &v in list {
                        if self.positions[v].distance(p) <= snap {
                            return v;
                        }
                    }
                }
            }
        }
        self.positions.push(p);
        let id = self.positions.len() - 1;
        grid.entry(cell).or_default().push(id);
        id
    }

    /// Inserts vertex `c` into edge `a-b` (and into every loop that runs along it).
    fn split_edge(&mut self, a: usize, b: usize, c: usize) {
        if let Some(i) = self.edges.iter().position(|e| *e == key(a, b)) {
            let source = self.edge_source[i];
            self.edges[i] = key(a, c);
            self.edges.push(key(c, b));
            self.edge_source.push(source);
        }
        for l in &mut self.loops {
            let n = l.vertices.len();
            if let Some(i) =
                (0..n).find(|&i| key(l.vertices[i], l.vertices[(i + 1) % n]) == key(a, b))
            {
                l.vertices.insert(i + 1, c);
            }
        }
    }

    /// The vertex at `p` on edge `e` (an end when within `snap`, else a new vertex splitting it).
    fn vertex_on_edge(&mut self, e: [usize; 2], p: DVec2, snap: f64) -> usize {
        for v in e {
            if self.positions[v].distance(p) <= snap {
                return v;
            }
        }
        self.positions.push(p);
        let c = self.positions.len() - 1;
        self.split_edge(e[0], e[1], c);
        c
    }

    /// Cuts the graph at `at`: the cut line crosses the nearest edge perpendicularly there and
    /// runs to the nearest other edge it meets (the far side of a strip, like the other rail of
    /// a road); those one or two points are the cut section. Each section vertex is split in
    /// two, one copy per side of the cut line, and the section edge is kept on both sides.
    // Long because: one geometric construction (the cut line, its ends, the duplicated section) whose steps share the intersections.
    pub fn cut(&mut self, at: DVec2, snap: f64) -> Result<CutSection, AuthorError> {
        if !at.is_finite() {
            return Err(AuthorError("a cut point must be finite".into()));
        }
        let (nearest, _) = self
            .edges
            .iter()
            .enumerate()
            .map(|(i, e)| {
                (
                    i,
                    segment_distance(at, self.positions[e[0]], self.positions[e[1]]).0,
                )
            })
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .ok_or_else(|| AuthorError("there is no edge to cut".into()))?;
        let e = self.edges[nearest];
        let (pa, pb) = (self.positions[e[0]], self.positions[e[1]]);
        let (_, t) = segment_distance(at, pa, pb);
        let q = pa + (pb - pa) * t;
        let along = (pb - pa).normalize_or_zero();
        if along == DVec2::ZERO {
            return Err(AuthorError(format!(
                "the edge nearest the cut at ({}, {}) has no length",
                at.x, at.y
            )));
        }
        let normal = along.perp();
        // The nearest other crossing of the cut line.
        let mut far: Option<(f64, [usize; 2], DVec2)> = None;
        for (i, f) in self.edges.iter().enumerate() {
            if i == nearest {
                continue;
            }
            let (a, b) = (self.positions[f[0]], self.positions[f[1]]);
            let d = b - a;
            let denom = normal.perp_dot(d);
            if denom.abs() < 1e-12 {
                continue;
            }
            let s = (a - q).perp_dot(d) / denom;
            let u = (a - q).perp_dot(normal) / denom;
            if s.abs() > snap
                && (-1e-9..=1.0 + 1e-9).contains(&u)
                && far.is_none_or(|(best, _, _)| s.abs() < best.abs())
            {
                far = Some((s, *f, q + normal * s));
            }
        }
        let mut section = vec![self.vertex_on_edge(e, q, snap)];
        if let Some((_, f, r)) = far {
            // The first split may have replaced the far edge's record; find it again.
            let f = if self.edges.contains(&f) {
                f
            } else {
                *self
                    .edges
                    .iter()
                    .filter(|x| x.contains(&f[0]) || x.contains(&f[1]))
                    .min_by(|x, y| {
                        let dx = segment_distance(r, self.positions[x[0]], self.positions[x[1]]).0;
                        let dy = segment_distance(r, self.positions[y[0]], self.positions[y[1]]).0;
                        dx.total_cmp(&dy)
                    })
                    .unwrap_or(&f)
            };
            let v = self.vertex_on_edge(f, r, snap);
            if v != section[0] {
                section.push(v);
            }
        }
        if section.len() == 2 && !self.edges.contains(&key(section[0], section[1])) {
            self.edges.push(key(section[0], section[1]));
            self.edge_source
                .push(self.edge_source[nearest.min(self.edge_source.len() - 1)]);
        }
        // Split every section vertex: edges leaving towards +along go to the new copy.
        let side = |p: DVec2| (p - q).dot(along);
        let mut copies = Vec::new();
        for &c in &section {
            self.positions.push(self.positions[c]);
            copies.push(self.positions.len() - 1);
        }
        let in_section = |v: usize| section.iter().position(|&s| s == v);
        let mut added = Vec::new();
        for i in 0..self.edges.len() {
            let [a, b] = self.edges[i];
            match (in_section(a), in_section(b)) {
                (Some(ia), Some(ib)) => {
                    added.push((key(copies[ia], copies[ib]), self.edge_source[i]))
                }
                (Some(ia), None) if side(self.positions[b]) > 0.0 => {
                    self.edges[i] = key(copies[ia], b)
                }
                (None, Some(ib)) if side(self.positions[a]) > 0.0 => {
                    self.edges[i] = key(a, copies[ib])
                }
                _ => {}
            }
        }
        for (e, s) in added {
            self.edges.push(e);
            self.edge_source.push(s);
        }
        // Loops describe the uncut drawing only.
        self.loops.clear();
        Ok(CutSection {
            at,
            negative: section,
            positive: copies,
        })
    }

    /// The regions after cutting: the connected pieces of the graph, with one contact per cut.
    /// An outline that crosses itself is an error ([`Graph::simple_outline`]).
    pub fn regions(&self, cuts: &[CutSection]) -> Result<Split, AuthorError> {
        let n = self.positions.len();
        let mut parent: Vec<usize> = (0..n).collect();
        fn find(p: &mut [usize], mut x: usize) -> usize {
            while p[x] != x {
                p[x] = p[p[x]];
                x = p[x];
            }
            x
        }
        for e in &self.edges {
            let (a, b) = (find(&mut parent, e[0]), find(&mut parent, e[1]));
            parent[a.max(b)] = a.min(b);
        }
        let mut by_root: BTreeMap<usize, usize> = BTreeMap::new();
        let mut region_of = vec![usize::MAX; n];
        let mut regions: Vec<Region> = Vec::new();
        let mut sources: Vec<Vec<usize>> = Vec::new();
        for (i, e) in self.edges.iter().enumerate() {
            let root = find(&mut parent, e[0]);
            let r = *by_root.entry(root).or_insert_with(|| {
                regions.push(Region {
                    vertices: Vec::new(),
                    edges: Vec::new(),
                    outline: None,
                    source: None,
                });
                sources.push(Vec::new());
                regions.len() - 1
            });
            regions[r].edges.push(*e);
            sources[r].push(self.edge_source[i]);
            for v in e {
                if region_of[*v] == usize::MAX {
                    region_of[*v] = r;
                    regions[r].vertices.push(*v);
                }
            }
        }
        for (r, region) in regions.iter_mut().enumerate() {
            region.outline = self.cycle(&region.vertices, &region.edges);
            region.source = most_common(&sources[r]);
            if let Some(o) = &region.outline {
                self.simple_outline(o, region.source)?;
            }
        }
        let mut contacts = Vec::new();
        for c in cuts {
            let (a, b) = (region_of[c.negative[0]], region_of[c.positive[0]]);
            if a == usize::MAX || b == usize::MAX {
                continue;
            }
            if a == b {
                return Err(AuthorError(format!(
                    "the cut at ({}, {}) does not separate the drawing into two regions; add another cut to split that part",
                    c.at.x, c.at.y
                )));
            }
            contacts.push(Contact {
                a,
                b,
                pairs: c
                    .negative
                    .iter()
                    .copied()
                    .zip(c.positive.iter().copied())
                    .collect(),
            });
        }
        Ok(Split {
            regions,
            contacts,
            notes: Vec::new(),
        })
    }

    /// With no cuts: every closed path is a region, and regions dock where they share vertices
    /// (two or more; a single shared corner docks only when it is in no other contact of the
    /// two regions). A closed path with no area (it runs out and back along a line) is left out
    /// like an open stroke, and one drawn again on top of another (an exporter's fill and
    /// stroke copies) is authored once, each with a note; one that touches or crosses itself is
    /// an error ([`Graph::simple_outline`]).
    // Long because: the regions, their duplicates and the contacts between them, over shared vertex tables.
    pub fn loop_regions(&self) -> Result<Split, AuthorError> {
        let mut edges_at: HashMap<usize, Vec<usize>> = HashMap::new();
        for (i, e) in self.edges.iter().enumerate() {
            for v in e {
                edges_at.entry(*v).or_default().push(i);
            }
        }
        let mut split = Split::default();
        let mut by_vertices: HashMap<Vec<usize>, usize> = HashMap::new();
        for l in &self.loops {
            let set: HashSet<usize> = l.vertices.iter().copied().collect();
            if set.len() < 3 {
                continue;
            }
            let mut outline = l.vertices.clone();
            if self.flat(&outline) {
                split.notes.push(format!(
                    "{} encloses no area (it runs along a line and back); it is left out like an open stroke",
                    self.stroke_name(l.source)
                ));
                continue;
            }
            self.simple_outline(&outline, Some(l.source))?;
            if signed_area(&self.positions, &outline) < 0.0 {
                outline.reverse();
            }
            let mut key = outline.clone();
            key.sort_unstable();
            if let Some(&r) = by_vertices.get(&key) {
                let first: &mut Region = &mut split.regions[r];
                if first
                    .outline
                    .as_deref()
                    .is_some_and(|o| same_cycle(o, &outline))
                {
                    split.notes.push(format!(
                        "{} is drawn again on top of {}; it is authored once",
                        self.stroke_name(l.source),
                        first
                            .source
                            .map_or_else(String::new, |s| self.stroke_name(s))
                    ));
                    // Keep the copy that has a fill, for the piece's colour.
                    let fill =
                        |s: Option<usize>| s.and_then(|s| self.sources.get(s)).and_then(|s| s.0);
                    if fill(first.source).is_none() && fill(Some(l.source)).is_some() {
                        first.source = Some(l.source);
                    }
                    continue;
                }
            }
            let mut edges: Vec<usize> = outline
                .iter()
                .flat_map(|v| edges_at.get(v).into_iter().flatten().copied())
                .filter(|&i| set.contains(&self.edges[i][0]) && set.contains(&self.edges[i][1]))
                .collect();
            edges.sort_unstable();
            edges.dedup();
            by_vertices.insert(key, split.regions.len());
            split.regions.push(Region {
                vertices: outline.clone(),
                edges: edges.into_iter().map(|i| self.edges[i]).collect(),
                outline: Some(outline),
                source: Some(l.source),
            });
        }
        if split.regions.is_empty() {
            return Err(AuthorError(
                "the drawing has no closed path; close the outlines, or give cut points (--cut x,y) to split open strokes".into(),
            ));
        }
        let regions = &split.regions;
        let mut shared: BTreeMap<(usize, usize), Vec<usize>> = BTreeMap::new();
        let mut owners: HashMap<usize, Vec<usize>> = HashMap::new();
        for (r, region) in regions.iter().enumerate() {
            for &v in &region.vertices {
                owners.entry(v).or_default().push(r);
            }
        }
        for (v, rs) in &owners {
            for (i, &a) in rs.iter().enumerate() {
                for &b in &rs[i + 1..] {
                    if a != b {
                        shared.entry((a.min(b), a.max(b))).or_default().push(*v);
                    }
                }
            }
        }
        let mut in_contact: HashSet<(usize, usize)> = HashSet::new();
        for ((a, b), vs) in &shared {
            if vs.len() >= 2 {
                for &v in vs {
                    in_contact.insert((*a, v));
                    in_contact.insert((*b, v));
                }
            }
        }
        for ((a, b), vs) in shared {
            let lone_corner = vs.len() == 1
                && !in_contact.contains(&(a, vs[0]))
                && !in_contact.contains(&(b, vs[0]));
            if vs.len() >= 2 || lone_corner {
                let mut vs = vs;
                vs.sort_unstable();
                split.contacts.push(Contact {
                    a,
                    b,
                    pairs: vs.iter().map(|&v| (v, v)).collect(),
                });
            }
        }
        Ok(split)
    }

    /// How a message names drawing polyline `k`: by its SVG id, else by its place in the
    /// drawing.
    pub fn stroke_name(&self, k: usize) -> String {
        match self.sources.get(k).and_then(|s| s.1.as_deref()) {
            Some(id) => format!("path `{id}`"),
            None => format!(
                "stroke {} of {} (a path without an id)",
                k + 1,
                self.sources.len()
            ),
        }
    }

    /// Whether every vertex of `cycle` lies within the snap tolerance of one line: a closed
    /// path that encloses nothing. (T-junctions split every edge a vertex lies on, so a flat
    /// cycle passes through a vertex twice; one that does not is not flat.)
    fn flat(&self, cycle: &[usize]) -> bool {
        if cycle.iter().collect::<HashSet<_>>().len() == cycle.len() {
            return false;
        }
        let p = |i: usize| self.positions[i];
        let far = |from: DVec2| {
            cycle
                .iter()
                .map(|&v| p(v))
                .max_by(|x, y| x.distance(from).total_cmp(&y.distance(from)))
                .unwrap_or(from)
        };
        let a = far(p(cycle[0]));
        let b = far(a);
        let span = a.distance(b);
        span == 0.0
            || cycle
                .iter()
                .all(|&v| (b - a).perp_dot(p(v) - a).abs() / span <= self.snap)
    }

    /// Refuses an outline that is not a simple polygon: one that passes through a point twice
    /// (it touches itself, as a figure eight drawn in one stroke does) or whose edges cross (a
    /// bowtie). The error names the path and the place, in metres with y up.
    ///
    /// Why refuse rather than repair: the outline becomes the piece's polygon and its edges the
    /// piece's structure, and a crossing outline has no one inside (SVG's even-odd and
    /// non-zero fill rules already disagree about it); splitting it at its crossings would
    /// guess shapes the author never drew and leave them to be discovered in the grammar. CAD
    /// sketchers refuse self-intersecting profiles the same way; naming the place makes the
    /// fix in the drawing quick (redraw it there, or draw the parts as separate closed paths).
    pub fn simple_outline(
        &self,
        cycle: &[usize],
        source: Option<usize>,
    ) -> Result<(), AuthorError> {
        let what = || match source {
            Some(k) => format!("the outline of {}", self.stroke_name(k)),
            None => "an outline".to_string(),
        };
        let mut seen = HashSet::new();
        if let Some(&v) = cycle.iter().find(|v| !seen.insert(**v)) {
            return Err(AuthorError(format!(
                "{} passes through {} twice: it touches or runs back along itself there; a piece outline must be a simple closed path, so redraw it there or draw its parts as separate closed paths",
                what(),
                metres(self.positions[v])
            )));
        }
        let ring: Vec<DVec2> = cycle.iter().map(|&v| self.positions[v]).collect();
        if let Some((_, _, at)) = self_crossing(&ring) {
            return Err(AuthorError(format!(
                "{} crosses itself at {}; a piece outline must be a simple closed path, so redraw it without the crossing or draw its parts as separate closed paths",
                what(),
                metres(at)
            )));
        }
        Ok(())
    }

    /// The vertices as a counter-clockwise cycle, when the edges form exactly one simple cycle.
    fn cycle(&self, vertices: &[usize], edges: &[[usize; 2]]) -> Option<Vec<usize>> {
        if vertices.len() < 3 || edges.len() != vertices.len() {
            return None;
        }
        let mut adj: HashMap<usize, Vec<usize>> = HashMap::new();
        for e in edges {
            adj.entry(e[0]).or_default().push(e[1]);
            adj.entry(e[1]).or_default().push(e[0]);
        }
        if adj.values().any(|a| a.len() != 2) {
            return None;
        }
        let mut cycle = vec![vertices[0]];
        let mut prev = vertices[0];
        let mut cur = adj[&vertices[0]][0];
        while cur != vertices[0] {
            cycle.push(cur);
            let next = if adj[&cur][0] == prev {
                adj[&cur][1]
            } else {
                adj[&cur][0]
            };
            prev = cur;
            cur = next;
            if cycle.len() > vertices.len() {
                return None;
            }
        }
        if cycle.len() != vertices.len() {
            return None;
        }
        if signed_area(&self.positions, &cycle) < 0.0 {
            cycle.reverse();
        }
        Some(cycle)
    }
}

/// Refuses a tolerance that is not a number of metres from [`MIN_TOLERANCE`] up.
pub fn check_tolerance(what: &str, v: f64) -> Result<(), AuthorError> {
    if v.is_finite() && v >= MIN_TOLERANCE {
        Ok(())
    } else {
        Err(AuthorError(format!(
            "the {what} must be a number of metres from {MIN_TOLERANCE} up (the grammar is written to the micrometre), found {v}"
        )))
    }
}

/// Whether `a` and `b` are the same cycle of vertices, whatever vertex each starts from.
fn same_cycle(a: &[usize], b: &[usize]) -> bool {
    a.len() == b.len()
        && b.iter()
            .position(|&v| Some(&v) == a.first())
            .is_some_and(|k| {
                a.iter()
                    .enumerate()
                    .all(|(i, &v)| b[(i + k) % b.len()] == v)
            })
}

/// A point for a message: `(x, y) m`, to the micrometre.
pub(crate) fn metres(p: DVec2) -> String {
    let r = |x: f64| {
        let r = (x * 1e6).round() / 1e6;
        if r == 0.0 { 0.0 } else { r }
    };
    let show = |x: f64| {
        if x.abs() < 1e9 {
            r(x).to_string()
        } else {
            format!("{x:e}")
        }
    };
    format!("({}, {}) m", show(p.x), show(p.y))
}

/// The signed area of a polygon of graph vertices (positive when counter-clockwise).
pub fn signed_area(positions: &[DVec2], cycle: &[usize]) -> f64 {
    crate::plane::polygon_area(cycle.iter().map(|&i| positions[i]))
}

fn most_common(xs: &[usize]) -> Option<usize> {
    let mut counts: BTreeMap<usize, usize> = BTreeMap::new();
    for &x in xs {
        *counts.entry(x).or_default() += 1;
    }
    counts
        .into_iter()
        .max_by_key(|&(x, c)| (c, std::cmp::Reverse(x)))
        .map(|(x, _)| x)
}
