//! Closed solids from a piece's tessellated proxies, planned once per piece and rest state in
//! rest coordinates and built for every instance from its posed vertices.
//!
//! A proxy with heights becomes a prism: its cap triangles on top and at the bottom, and a wall
//! on every boundary edge. The proxies of a piece that share a fill colour and both heights
//! form one solid: their cap vertices are welded by position, so two touching polygons become
//! one outline (no wall between them, no edge used by four faces). A cap that is not a clean
//! triangulation after welding (a vertex in the middle of another triangle's edge, as at a
//! polyline's bevel join, or triangles that overlap) is replaced by the union of its triangles:
//! spade's constrained triangulation of every triangle edge, split where edges cross, keeping
//! the faces inside some triangle. Every prism is then closed and every edge is used by exactly
//! two of its faces, in opposite directions (the faces wind consistently), with two exceptions
//! that are the shape's own: an outline that touches itself at a point gives four walls on the
//! vertical edge there, and a triangle that skinning folded over stays folded.
//!
//! A mesh asset (`mesh "tower.glb"`) is not a prism: its own triangles are written as they are.

use std::collections::{HashMap, HashSet};

use clay_dsl::compiled::{Extrude, Rgba};
use glam::DVec2;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

use super::model::ExportOptions;
use crate::plane::{barycentric, triangle_area};
use crate::render::Mesh;

/// A vertex of a cap: a weighted sum of tessellation vertices, `(mesh, vertex, weight)`; all
/// but the first weight are 0 except for points where the union split crossing edges.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Blend(pub [(u32, u32, f64); 3]);

impl Blend {
    fn one(mesh: usize, vertex: usize) -> Self {
        Self([(mesh as u32, vertex as u32, 1.0), (0, 0, 0.0), (0, 0, 0.0)])
    }
}

/// One closed prism: the cap's vertices and counter-clockwise triangles (rest winding, seen from
/// above) and its boundary edges, each with the inside on its left.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Prism {
    pub fill: Rgba,
    pub base: f64,
    pub top: f64,
    pub vertices: Vec<Blend>,
    pub triangles: Vec<[u32; 3]>,
    pub walls: Vec<[u32; 2]>,
}

/// What one piece state exports.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Shape {
    Prism(Prism),
    /// The mesh asset that is tessellation mesh `k`.
    Surface(usize),
}

/// The heights of tessellation mesh `k` of a piece state: its own `extrude`, or for flat
/// geometry the k-th layer, `k * layer` to `thickness + k * layer`: a later proxy lies on an
/// earlier one as it is drawn on top of it, neither its top nor its bottom in the other's plane.
pub(super) fn heights(extrude: Option<Extrude>, k: usize, options: &ExportOptions) -> (f64, f64) {
    match extrude {
        Some(e) => (e.base, e.base + e.height),
        None => {
            let lift = options.layer * k as f64;
            (lift, options.thickness + lift)
        }
    }
}

/// The solids of a piece state whose tessellated proxies are `meshes`, in the order of their
/// first proxy.
pub(super) fn plan(meshes: &[Mesh], options: &ExportOptions) -> Vec<Shape> {
    enum Pending {
        Group(Rgba, f64, f64, Vec<usize>),
        Surface(usize),
    }
    let mut pending = Vec::new();
    let mut group_of: HashMap<([u8; 4], u64, u64), usize> = HashMap::new();
    for (k, mesh) in meshes.iter().enumerate() {
        if mesh.solid.is_some() {
            pending.push(Pending::Surface(k));
            continue;
        }
        let (base, top) = heights(mesh.extrude, k, options);
        let key = (mesh.fill.0, base.to_bits(), top.to_bits());
        match group_of.get(&key) {
            Some(&g) => {
                if let Pending::Group(.., members) = &mut pending[g] {
                    members.push(k);
                }
            }
            None => {
                group_of.insert(key, pending.len());
                pending.push(Pending::Group(mesh.fill, base, top, vec![k]));
            }
        }
    }
    pending
        .into_iter()
        .map(|p| match p {
            Pending::Surface(k) => Shape::Surface(k),
            Pending::Group(fill, base, top, members) => {
                Shape::Prism(prism(meshes, &members, fill, base, top))
            }
        })
        .collect()
}

/// The prism of proxies `members` (same fill and heights): welded, and their union when the
/// welded cap is not a clean triangulation.
fn prism(meshes: &[Mesh], members: &[usize], fill: Rgba, base: f64, top: f64) -> Prism {
    let mut index: HashMap<[u64; 2], u32> = HashMap::new();
    let mut points: Vec<DVec2> = Vec::new();
    let mut blends: Vec<Blend> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    for &k in members {
        let mesh = &meshes[k];
        let ids: Vec<u32> = mesh
            .vertices
            .iter()
            .enumerate()
            .map(|(i, p)| {
                // `+ 0.0` makes -0 and 0 one key.
                *index
                    .entry([(p.x + 0.0).to_bits(), (p.y + 0.0).to_bits()])
                    .or_insert_with(|| {
                        points.push(*p);
                        blends.push(Blend::one(k, i));
                        (points.len() - 1) as u32
                    })
            })
            .collect();
        for t in &mesh.triangles {
            let Some(w) = t
                .iter()
                .map(|&i| ids.get(i as usize).copied())
                .collect::<Option<Vec<u32>>>()
            else {
                continue;
            };
            if w[0] != w[1] && w[1] != w[2] && w[0] != w[2] {
                triangles.push([w[0], w[1], w[2]]);
            }
        }
    }
    if !clean(&points, &triangles) {
        // A panic inside the triangulation must not take the export down: the welded cap is
        // still a good picture, only not a clean solid.
        let merged = quietly(|| union(&points, &triangles));
        if let Some(Some((weights, merged))) = merged {
            let blends_now = weights
                .iter()
                .map(|w| {
                    let mut terms = [(0, 0, 0.0); 3];
                    for (slot, &(v, f)) in terms.iter_mut().zip(w) {
                        let b = blends[v as usize].0[0];
                        *slot = (b.0, b.1, f);
                    }
                    Blend(terms)
                })
                .collect();
            blends = blends_now;
            triangles = merged;
        }
    }
    // Only vertices a triangle uses are written.
    let mut used = vec![u32::MAX; blends.len()];
    let mut vertices = Vec::new();
    for t in &mut triangles {
        for v in t.iter_mut() {
            if used[*v as usize] == u32::MAX {
                used[*v as usize] = vertices.len() as u32;
                vertices.push(blends[*v as usize]);
            }
            *v = used[*v as usize];
        }
    }
    let walls = boundary(&triangles);
    Prism {
        fill,
        base,
        top,
        vertices,
        triangles,
        walls,
    }
}

/// The directed edges used by one triangle whose reverse no triangle uses, in triangle order:
/// the outline, inside on the left.
fn boundary(triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let edges: HashSet<[u32; 2]> = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| [t[k], t[(k + 1) % 3]]))
        .collect();
    triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| [t[k], t[(k + 1) % 3]]))
        .filter(|e| !edges.contains(&[e[1], e[0]]))
        .collect()
}

/// Whether welded triangles form a clean triangulation of their region: every triangle
/// counter-clockwise with area, no directed edge used twice, and no vertex inside an outline
/// edge (a T-junction, where the walls on both sides would not meet).
fn clean(points: &[DVec2], triangles: &[[u32; 3]]) -> bool {
    let p = |i: u32| points[i as usize];
    if triangles
        .iter()
        .any(|t| triangle_area(p(t[0]), p(t[1]), p(t[2])) <= 0.0)
    {
        return false;
    }
    let mut edges = HashSet::with_capacity(triangles.len() * 3);
    for t in triangles {
        for k in 0..3 {
            if !edges.insert([t[k], t[(k + 1) % 3]]) {
                return false;
            }
        }
    }
    // Vertices by x, to find those within an edge's x range.
    let mut by_x: Vec<u32> = triangles.iter().flatten().copied().collect();
    by_x.sort_unstable_by(|&a, &b| p(a).x.total_cmp(&p(b).x).then(a.cmp(&b)));
    by_x.dedup();
    for e in boundary(triangles) {
        let (a, b) = (p(e[0]), p(e[1]));
        let (lo, hi) = (a.x.min(b.x), a.x.max(b.x));
        let tol = 1e-9 * a.abs().max(b.abs()).max_element().max(1.0);
        let first = by_x.partition_point(|&v| p(v).x < lo - tol);
        for &v in by_x[first..].iter().take_while(|&&v| p(v).x <= hi + tol) {
            if v == e[0] || v == e[1] {
                continue;
            }
            let q = p(v);
            let d = b - a;
            let along = (q - a).dot(d);
            if along > 0.0
                && along < d.length_squared()
                && (2.0 * triangle_area(a, b, q)).abs() <= tol * d.length()
            {
                return false;
            }
        }
    }
    true
}

/// The union of triangles over `points`, triangulated again: each output vertex as weights
/// over `points` (one point with weight 1, or a point where two edges cross as barycentric
/// weights in a triangle it lies in) and counter-clockwise triangles over the output vertices.
/// `None` when spade cannot represent a coordinate or nothing is inside.
type Weights = Vec<(u32, f64)>;

fn union(points: &[DVec2], triangles: &[[u32; 3]]) -> Option<(Vec<Weights>, Vec<[u32; 3]>)> {
    let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> = Default::default();
    let mut handles = Vec::with_capacity(points.len());
    for p in points {
        handles.push(cdt.insert(Point2::new(p.x, p.y)).ok()?);
    }
    let mut edges: Vec<[u32; 2]> = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| [t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])]))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    for [a, b] in edges {
        let (ha, hb) = (handles[a as usize], handles[b as usize]);
        if ha != hb {
            cdt.add_constraint_and_split(ha, hb, |p| p);
        }
    }
    let grid = Grid::new(points, triangles);
    // The source of each triangulation vertex: an input point, or weights found on first use.
    let mut source: Vec<Option<Weights>> = vec![None; cdt.num_vertices()];
    for (i, h) in handles.iter().enumerate() {
        source[h.index()] = Some(vec![(i as u32, 1.0)]);
    }
    let mut index_of = vec![u32::MAX; cdt.num_vertices()];
    let mut out_weights = Vec::new();
    let mut out_points: Vec<DVec2> = Vec::new();
    let mut out = Vec::new();
    for face in cdt.inner_faces() {
        let corners = face.vertices();
        let pos = corners.map(|v| DVec2::new(v.position().x, v.position().y));
        let area = 2.0 * triangle_area(pos[0], pos[1], pos[2]);
        if area.abs() <= f64::EPSILON * pos.iter().map(|q| q.length_squared()).fold(1.0, f64::max) {
            continue;
        }
        let centre = (pos[0] + pos[1] + pos[2]) / 3.0;
        if grid.containing(points, triangles, centre).is_none() {
            continue;
        }
        let mut tri = [0u32; 3];
        for (slot, (v, q)) in tri.iter_mut().zip(corners.iter().zip(pos)) {
            let h = v.fix().index();
            if index_of[h] == u32::MAX {
                let w = match &source[h] {
                    Some(w) => w.clone(),
                    None => grid.weights(points, triangles, q),
                };
                source[h] = Some(w.clone());
                index_of[h] = out_weights.len() as u32;
                out_weights.push(w);
                out_points.push(q);
            }
            *slot = index_of[h];
        }
        if area < 0.0 {
            tri.swap(1, 2);
        }
        out.push(tri);
    }
    let out = weld_close(&out_points, out);
    (!out.is_empty()).then_some((out_weights, out))
}

/// Triangles with every vertex that lies within rounding of an earlier one replaced by it, and
/// the triangles that leaves without area dropped. A point where two edges cross is computed in
/// floating point, and can land a hair beside a vertex of the input instead of on it: the
/// sliver between them would leave a slit in the outline, two walls back to back.
fn weld_close(points: &[DVec2], triangles: Vec<[u32; 3]>) -> Vec<[u32; 3]> {
    let tol = |p: DVec2| 1e-9 * p.abs().max_element().max(1.0);
    let mut by_x: Vec<u32> = (0..points.len() as u32).collect();
    by_x.sort_unstable_by(|&a, &b| points[a as usize].x.total_cmp(&points[b as usize].x));
    let mut to: Vec<u32> = (0..points.len() as u32).collect();
    for (k, &a) in by_x.iter().enumerate() {
        let p = points[a as usize];
        for &b in by_x[k + 1..]
            .iter()
            .take_while(|&&b| points[b as usize].x - p.x <= tol(p))
        {
            if points[b as usize].distance(p) <= tol(p) {
                let (keep, drop) = (to[a as usize].min(to[b as usize]), a.max(b));
                to[drop as usize] = keep;
            }
        }
    }
    // Follow chains of replacements to their end.
    for i in 0..to.len() {
        let mut j = to[i];
        while to[j as usize] != j {
            j = to[j as usize];
        }
        to[i] = j;
    }
    triangles
        .into_iter()
        .map(|t| t.map(|v| to[v as usize]))
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
        .collect()
}

/// Triangles bucketed by their bounding boxes on a uniform grid, for point location.
struct Grid {
    lo: DVec2,
    cell: DVec2,
    n: [usize; 2],
    cells: Vec<Vec<u32>>,
}

impl Grid {
    fn new(points: &[DVec2], triangles: &[[u32; 3]]) -> Self {
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for p in triangles.iter().flatten().map(|&i| points[i as usize]) {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        let side = (triangles.len() as f64).sqrt().ceil().clamp(1.0, 256.0) as usize;
        let n = [side, side];
        let cell = ((hi - lo) / side as f64).max(DVec2::splat(1e-12));
        let mut grid = Self {
            lo,
            cell,
            n,
            cells: vec![Vec::new(); side * side],
        };
        for (k, t) in triangles.iter().enumerate() {
            let ps = t.map(|i| points[i as usize]);
            let (a, b) = (
                grid.at(ps[0].min(ps[1]).min(ps[2])),
                grid.at(ps[0].max(ps[1]).max(ps[2])),
            );
            for y in a[1]..=b[1] {
                for x in a[0]..=b[0] {
                    grid.cells[y * n[0] + x].push(k as u32);
                }
            }
        }
        grid
    }

    fn at(&self, p: DVec2) -> [usize; 2] {
        let c = ((p - self.lo) / self.cell).floor();
        let clamp = |v: f64, n: usize| (v.max(0.0) as usize).min(n - 1);
        [clamp(c.x, self.n[0]), clamp(c.y, self.n[1])]
    }

    /// The barycentric weights of `p` in the triangle that holds it best (its smallest weight
    /// largest), and that triangle's index.
    fn best(
        &self,
        points: &[DVec2],
        triangles: &[[u32; 3]],
        p: DVec2,
    ) -> Option<(usize, [f64; 3])> {
        let [x, y] = self.at(p);
        let mut best: Option<(usize, [f64; 3])> = None;
        for &k in &self.cells[y * self.n[0] + x] {
            let t = triangles[k as usize];
            let [a, b, c] = t.map(|i| points[i as usize]);
            let Some(w) = barycentric(a, b, c, p) else {
                continue;
            };
            let worst = w[0].min(w[1]).min(w[2]);
            if best.is_none_or(|(_, bw)| worst > bw[0].min(bw[1]).min(bw[2])) {
                best = Some((k as usize, w));
            }
        }
        best
    }

    /// The triangle `p` lies in (on its edges included, within rounding).
    fn containing(&self, points: &[DVec2], triangles: &[[u32; 3]], p: DVec2) -> Option<usize> {
        self.best(points, triangles, p)
            .filter(|(_, w)| w.iter().all(|&x| x >= -1e-9))
            .map(|(k, _)| k)
    }

    /// `p` as weights over the corners of the triangle that holds it best.
    fn weights(&self, points: &[DVec2], triangles: &[[u32; 3]], p: DVec2) -> Weights {
        match self.best(points, triangles, p) {
            Some((k, w)) => {
                let w = w.map(|x| x.clamp(0.0, 1.0));
                let sum: f64 = w.iter().sum();
                triangles[k]
                    .iter()
                    .zip(w)
                    .map(|(&i, x)| (i, if sum > 0.0 { x / sum } else { 1.0 / 3.0 }))
                    .collect()
            }
            // Not in any triangle (rounding at the very edge): the nearest point.
            None => {
                let nearest = (0..points.len())
                    .min_by(|&a, &b| {
                        points[a]
                            .distance_squared(p)
                            .total_cmp(&points[b].distance_squared(p))
                    })
                    .unwrap_or(0);
                vec![(nearest as u32, 1.0)]
            }
        }
    }
}

/// Runs `f`; a panic inside it becomes `None`, without the panic hook's message and backtrace
/// (issue 47: a panic caught in the triangulation printed a backtrace above an export that then
/// succeeded, exit 0). Only panics on this thread while `f` runs are silenced; every other
/// goes to the hook that was installed before (the editor's crash recovery, say).
fn quietly<T>(f: impl FnOnce() -> T) -> Option<T> {
    use std::cell::Cell;
    thread_local!(static QUIET: Cell<bool> = const { Cell::new(false) });
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| {
        let before = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.with(Cell::get) {
                before(info);
            }
        }));
    });
    let was = QUIET.with(|q| q.replace(true));
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
    QUIET.with(|q| q.set(was));
    result.ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::{tessellate_polygon, tessellate_polyline};
    use clay_dsl::compiled::Binding;

    fn mesh(vertices: Vec<DVec2>, triangles: Vec<[u32; 3]>) -> Mesh {
        Mesh {
            vertices,
            triangles,
            outline: Vec::new(),
            fill: Rgba([1, 2, 3, 255]),
            binding: Binding::Rigid,
            extrude: Some(clay_dsl::compiled::Extrude {
                height: 1.0,
                base: 0.0,
            }),
            solid: None,
        }
    }

    fn square(x: f64, y: f64, side: f64) -> Mesh {
        let ring = [
            DVec2::new(x, y),
            DVec2::new(x + side, y),
            DVec2::new(x + side, y + side),
            DVec2::new(x, y + side),
        ];
        let (v, t) = tessellate_polygon(&ring, &[]).unwrap();
        mesh(v, t)
    }

    fn area(p: &Prism, at: impl Fn(&Blend) -> DVec2) -> f64 {
        p.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| at(&p.vertices[i as usize]));
                triangle_area(a, b, c)
            })
            .sum()
    }

    fn only_prism(shapes: Vec<Shape>) -> Prism {
        match shapes.as_slice() {
            [Shape::Prism(p)] => p.clone(),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn two_touching_squares_of_one_colour_are_one_outline() {
        let meshes = [square(0.0, 0.0, 1.0), square(1.0, 0.0, 1.0)];
        let p = only_prism(plan(&meshes, &ExportOptions::default()));
        // Six outline edges (the shared edge is inside), no edge twice.
        assert_eq!(p.walls.len(), 6, "{:?}", p.walls);
        assert_eq!(p.vertices.len(), 6);
    }

    #[test]
    fn a_t_junction_is_merged_into_one_triangulation() {
        // A 2 x 1 rectangle and a 1 x 0.5 one touching half of its right edge.
        let big = {
            let ring = [
                DVec2::new(0.0, 0.0),
                DVec2::new(2.0, 0.0),
                DVec2::new(2.0, 1.0),
                DVec2::new(0.0, 1.0),
            ];
            let (v, t) = tessellate_polygon(&ring, &[]).unwrap();
            mesh(v, t)
        };
        let small = {
            let ring = [
                DVec2::new(2.0, 0.0),
                DVec2::new(3.0, 0.0),
                DVec2::new(3.0, 0.5),
                DVec2::new(2.0, 0.5),
            ];
            let (v, t) = tessellate_polygon(&ring, &[]).unwrap();
            mesh(v, t)
        };
        let meshes = [big, small];
        let p = only_prism(plan(&meshes, &ExportOptions::default()));
        let at = |b: &Blend| {
            b.0.iter()
                .map(|&(m, v, w)| meshes[m as usize].vertices[v as usize] * w)
                .sum::<DVec2>()
        };
        assert!((area(&p, at) - 2.5).abs() < 1e-12);
        // Every directed edge once, every undirected one twice counting walls.
        let mut uses: HashMap<[u32; 2], i32> = HashMap::new();
        for t in &p.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *uses.entry([a.min(b), a.max(b)]).or_default() += 1;
            }
        }
        for w in &p.walls {
            *uses.entry([w[0].min(w[1]), w[0].max(w[1])]).or_default() += 1;
        }
        assert!(uses.values().all(|&n| n == 2), "{uses:?}");
        // The L outline: seven corners, (2, 0) among them.
        assert_eq!(p.walls.len(), 7, "{:?}", p.walls);
    }

    #[test]
    fn a_bevel_joined_polyline_becomes_its_union() {
        // A turn sharper than the miter limit: the segments overlap inside the turn and the
        // bevel's centre lies on both segments' ends.
        let points = [
            DVec2::new(0.0, 0.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(0.2, 0.3),
        ];
        let (v, t) = tessellate_polyline(&points, 0.2).unwrap();
        let m = mesh(v, t);
        assert!(
            !clean(&m.vertices, &m.triangles),
            "the strip itself overlaps"
        );
        let meshes = [m];
        let p = only_prism(plan(&meshes, &ExportOptions::default()));
        let at = |b: &Blend| {
            b.0.iter()
                .map(|&(m, v, w)| meshes[m as usize].vertices[v as usize] * w)
                .sum::<DVec2>()
        };
        let points: Vec<DVec2> = p.vertices.iter().map(at).collect();
        assert!(clean(&points, &p.triangles));
        // The union is smaller than the overlapping triangles together.
        let sum: f64 = meshes[0]
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| meshes[0].vertices[i as usize]);
                triangle_area(a, b, c)
            })
            .sum();
        assert!(area(&p, at) < sum - 1e-6);
    }

    #[test]
    fn flat_layers_do_not_share_a_plane() {
        let mut a = square(0.0, 0.0, 1.0);
        a.extrude = None;
        let mut b = square(0.25, 0.25, 0.5);
        b.extrude = None;
        let o = ExportOptions::default();
        assert_eq!(heights(a.extrude, 0, &o), (0.0, o.thickness));
        let (base, top) = heights(b.extrude, 1, &o);
        assert!(base > 0.0 && top > o.thickness && base < o.thickness);
        assert_eq!(plan(&[a, b], &o).len(), 2);
    }

    #[test]
    fn quietly_makes_a_panic_inside_none_and_keeps_the_value_otherwise() {
        assert_eq!(quietly(|| 3), Some(3));
        assert_eq!(quietly(|| -> u8 { panic!("a triangulation fails") }), None);
        // silenced only while it runs: a panic after it is still a panic
        assert!(std::panic::catch_unwind(|| panic!("after")).is_err());
    }
}
