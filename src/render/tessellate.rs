//! Tessellation of proxy geometry (paper 5.2) into plain triangle meshes in the piece's
//! geometry-frame coordinates, computed once per piece and rest state.
//!
//! Polygons (concave, with holes) go through spade's constrained Delaunay triangulation: every
//! ring is inserted as constraint edges and the triangles inside by the even-odd rule
//! (`plane::rings_contain`) are kept.
//! Which triangles are inside is found in one walk over the triangulation from its outside, the
//! parity flipping across every edge that an odd number of ring segments cover: O(n) after the
//! O(n log n) triangulation, for 200,000-point rings too. Only when a self-crossing ring had a
//! constraint left out does each triangle's centroid get the even-odd ray test (O(n) each). Thick polylines become a strip of quads with miter joins (bevel joins
//! past the miter limit). Degenerate shapes are skipped, never a panic: a picture with one
//! missing shape beats a crashed editor.

use std::collections::HashMap;
use std::sync::Arc;

use clay_dsl::compiled::{Binding, CompiledGrammar, Extrude, Proxy, ProxyShape, Rgba};
use glam::DVec2;
use spade::handles::FixedUndirectedEdgeHandle;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

/// Rings whose shoelace area is below this (square metres) have no inside worth drawing.
const MIN_RING_AREA: f64 = 1e-12;
/// Miter joins longer than this many half-widths become bevels (SVG's default limit of 4).
const MITER_LIMIT: f64 = 4.0;

/// One tessellated proxy: triangles in the coordinates of the rest state the geometry was
/// authored against ([`clay_dsl::compiled::RestState::geometry_frame`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    pub vertices: Vec<DVec2>,
    /// Vertex indices, counter-clockwise.
    pub triangles: Vec<[u32; 3]>,
    /// Boundary edges of the shape (edges used by exactly one triangle), for outlines.
    pub outline: Vec<[u32; 2]>,
    pub fill: Rgba,
    pub binding: Binding,
    /// The proxy's heights for the 3D export, when it has them.
    pub extrude: Option<Extrude>,
    /// The 3D triangles of a mesh asset over these vertices (`None` for polygons and polylines).
    pub solid: Option<Arc<Solid>>,
}

/// The 3D surface of a mesh asset (`mesh "tower.glb"`): a height per vertex of its [`Mesh`] and
/// its triangles, counter-clockwise seen from outside. Posing moves the vertices' floor-plan
/// coordinates and shares this unchanged (paper 6: the height stays).
#[derive(Clone, Debug, PartialEq)]
pub struct Solid {
    pub heights: Vec<f64>,
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// The sum of the triangles' areas.
    pub fn area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| triangle_area(self.corners(*t)))
            .sum()
    }

    fn corners(&self, t: [u32; 3]) -> [DVec2; 3] {
        t.map(|i| self.vertices[i as usize])
    }
}

/// Tessellates one proxy; `None` when its shape is degenerate (too few distinct points, zero
/// area, non-finite coordinates or width).
pub fn tessellate_proxy(proxy: &Proxy) -> Option<Mesh> {
    let mut solid = None;
    let (vertices, triangles) = match &proxy.shape {
        ProxyShape::Polygon { outer, holes } => tessellate_polygon(outer, holes)?,
        ProxyShape::Polyline { points, width } => tessellate_polyline(points, *width)?,
        ProxyShape::Mesh {
            points,
            heights,
            triangles,
        } => {
            let (footprint, s) = footprint(points, heights, triangles)?;
            solid = Some(Arc::new(s));
            (points.clone(), footprint)
        }
    };
    let outline = boundary_edges(&triangles);
    Some(Mesh {
        vertices,
        triangles,
        outline,
        fill: proxy.fill,
        binding: proxy.binding,
        extrude: proxy.extrude,
        solid,
    })
}

/// A mesh asset's footprint, what the 2D pictures draw of it: its triangles seen from above,
/// counter-clockwise, those standing on edge left out; and its 3D surface. `None` when an index
/// is out of range, a number is not finite or the asset has no triangle.
fn footprint(
    points: &[DVec2],
    heights: &[f64],
    triangles: &[[u32; 3]],
) -> Option<(Vec<[u32; 3]>, Solid)> {
    let n = points.len();
    let sound = heights.len() == n
        && points.iter().all(|p| p.is_finite())
        && heights.iter().all(|h| h.is_finite())
        && triangles.iter().flatten().all(|&i| (i as usize) < n);
    if !sound || triangles.is_empty() {
        return None;
    }
    let seen = triangles
        .iter()
        .filter(|&&t| triangle_area(t.map(|i| points[i as usize])) > 0.0)
        .map(|&t| ccw(points, t))
        .collect();
    let solid = Solid {
        heights: heights.to_vec(),
        triangles: triangles.to_vec(),
    };
    Some((seen, solid))
}

/// Triangulates a polygon with holes; triangles are counter-clockwise. Holes that are
/// degenerate are ignored; a degenerate outer ring gives `None`. Self-intersecting rings do not
/// panic: a constraint that would cross another is left out and the even-odd test decides.
pub fn tessellate_polygon(
    outer: &[DVec2],
    holes: &[Vec<DVec2>],
) -> Option<(Vec<DVec2>, Vec<[u32; 3]>)> {
    let outer = clean_ring(outer)?;
    let rings: Vec<Vec<DVec2>> = std::iter::once(outer)
        .chain(holes.iter().filter_map(|h| clean_ring(h)))
        .collect();

    let (cdt, cover) = constrained(&rings)?;
    let inside = match cover {
        Some(cover) => inside_by_walk(&cdt, &cover),
        None => cdt
            .inner_faces()
            .map(|face| {
                let [a, b, c] = face.positions().map(|p| DVec2::new(p.x, p.y));
                crate::plane::rings_contain(&rings, (a + b + c) / 3.0)
            })
            .collect(),
    };

    // The mesh index of each triangulation vertex, once it is used (u32::MAX before).
    let mut index_of = vec![u32::MAX; cdt.num_vertices()];
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for (face, inside) in cdt.inner_faces().zip(inside) {
        if !inside {
            continue;
        }
        let corners = face.vertices().map(|v| {
            let p = v.position();
            (v.fix().index(), DVec2::new(p.x, p.y))
        });
        let pts = corners.map(|(_, p)| p);
        let area = signed_area(pts);
        if area.abs() <= f64::EPSILON * scale_of(pts) {
            continue;
        }
        let mut tri = corners.map(|(handle, p)| {
            if index_of[handle] == u32::MAX {
                index_of[handle] = vertices.len() as u32;
                vertices.push(p);
            }
            index_of[handle]
        });
        if area < 0.0 {
            tri.swap(1, 2);
        }
        triangles.push(tri);
    }
    (!triangles.is_empty()).then_some((vertices, triangles))
}

type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;

/// The constrained triangulation of the rings, and how many ring segments cover each of its
/// undirected edges (indexed by edge), or `None` for the cover when a constraint that crosses
/// another had to be left out. `None` when spade cannot represent a coordinate.
fn constrained(rings: &[Vec<DVec2>]) -> Option<(Cdt, Option<Vec<u32>>)> {
    let mut cdt = Cdt::new();
    // Every point first, then every constraint: a point inserted later could split a constraint
    // edge already counted.
    let mut handles = Vec::with_capacity(rings.len());
    for ring in rings {
        let mut ring_handles = Vec::with_capacity(ring.len());
        for p in ring {
            // Coordinates spade cannot represent (e.g. 1e-300) make the whole shape unusable.
            ring_handles.push(cdt.insert(Point2::new(p.x, p.y)).ok()?);
        }
        handles.push(ring_handles);
    }
    let mut covered: Vec<FixedUndirectedEdgeHandle> = Vec::new();
    let mut complete = true;
    for ring in &handles {
        for i in 0..ring.len() {
            let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
            if a == b {
                continue;
            }
            // try_add_constraint leaves crossing constraints out instead of panicking; it gives
            // every edge the segment now consists of (also edges that were constraints before).
            let edges = cdt.try_add_constraint(a, b);
            complete &= !edges.is_empty();
            covered.extend(edges.iter().map(|e| e.as_undirected()));
        }
    }
    if !complete {
        return Some((cdt, None));
    }
    // Constraint edges are never flipped, so the handles taken above still name them.
    let mut cover = vec![0u32; cdt.num_undirected_edges()];
    for e in covered {
        cover[e.index()] += 1;
    }
    Some((cdt, Some(cover)))
}

/// Which inner faces (in `inner_faces` order) are inside by the even-odd rule: a walk from the
/// outer face across the triangulation's edges, the parity flipping across an edge covered by
/// an odd number of ring segments. Every path from outside crosses the rings that often.
fn inside_by_walk(cdt: &Cdt, cover: &[u32]) -> Vec<bool> {
    let odd = |e: spade::handles::DirectedEdgeHandle<_, _, _, _>| {
        cover[e.as_undirected().fix().index()] % 2 == 1
    };
    // Parity per face index; the faces next to the outer face (which is outside) start the walk.
    let mut parity: Vec<Option<bool>> = vec![None; cdt.num_all_faces()];
    let mut stack = Vec::new();
    for face in cdt.inner_faces() {
        for e in face.adjacent_edges() {
            if e.rev().face().is_outer() && parity[face.fix().index()].is_none() {
                parity[face.fix().index()] = Some(odd(e));
                stack.push(face.fix());
            }
        }
    }
    while let Some(face) = stack.pop() {
        let here = parity[face.index()].unwrap_or(false);
        for e in cdt.face(face).adjacent_edges() {
            let Some(next) = e.rev().face().as_inner() else {
                continue;
            };
            if parity[next.fix().index()].is_none() {
                parity[next.fix().index()] = Some(here != odd(e));
                stack.push(next.fix());
            }
        }
    }
    cdt.inner_faces()
        .map(|f| parity[f.fix().index()].unwrap_or(false))
        .collect()
}

/// A thick open polyline as a strip of quads, counter-clockwise triangles. Consecutive duplicate
/// points are dropped; fewer than two distinct points or a non-positive width gives `None`.
pub fn tessellate_polyline(points: &[DVec2], width: f64) -> Option<(Vec<DVec2>, Vec<[u32; 3]>)> {
    if !(width.is_finite() && width > 0.0) {
        return None;
    }
    let mut pts: Vec<DVec2> = Vec::with_capacity(points.len());
    for &p in points {
        if p.is_finite() && pts.last().is_none_or(|q: &DVec2| q.distance(p) > 1e-12) {
            pts.push(p);
        }
    }
    if pts.len() < 2 {
        return None;
    }
    let h = width / 2.0;
    let normals: Vec<DVec2> = pts
        .windows(2)
        .map(|w| (w[1] - w[0]).normalize().perp())
        .collect();

    let mut vertices: Vec<DVec2> = Vec::new();
    let mut triangles = Vec::new();
    let push = |p: DVec2, vertices: &mut Vec<DVec2>| {
        vertices.push(p);
        (vertices.len() - 1) as u32
    };
    // The left/right offset vertices where the current segment starts.
    let mut left = push(pts[0] + normals[0] * h, &mut vertices);
    let mut right = push(pts[0] - normals[0] * h, &mut vertices);
    for s in 0..normals.len() {
        let n = normals[s];
        let end = pts[s + 1];
        let next = normals.get(s + 1).copied();
        // A miter join shares its two offset points between both segments: no overlap, no gap.
        let miter = next.and_then(|m| {
            let bisector = (n + m).normalize_or_zero();
            let cos_half = bisector.dot(n);
            (cos_half > 1.0 / MITER_LIMIT).then(|| bisector * (h / cos_half))
        });
        let (end_left, end_right) = match miter {
            Some(offset) => (
                push(end + offset, &mut vertices),
                push(end - offset, &mut vertices),
            ),
            None => (
                push(end + n * h, &mut vertices),
                push(end - n * h, &mut vertices),
            ),
        };
        let corners = [left, right, end_right, end_left];
        triangles.push(ccw(&vertices, [corners[0], corners[1], corners[2]]));
        triangles.push(ccw(&vertices, [corners[0], corners[2], corners[3]]));
        match (next, miter) {
            (Some(m), None) => {
                // Bevel: both segments keep their own ends; a triangle closes the outer wedge.
                let centre = push(end, &mut vertices);
                let next_left = push(end + m * h, &mut vertices);
                let next_right = push(end - m * h, &mut vertices);
                let turn_left = n.perp_dot(m) > 0.0;
                let wedge = if turn_left {
                    [centre, end_right, next_right]
                } else {
                    [centre, end_left, next_left]
                };
                triangles.push(ccw(&vertices, wedge));
                left = next_left;
                right = next_right;
            }
            _ => {
                left = end_left;
                right = end_right;
            }
        }
    }
    let triangles: Vec<[u32; 3]> = triangles
        .into_iter()
        .filter(|t| signed_area(t.map(|i| vertices[i as usize])).abs() > f64::EPSILON)
        .collect();
    (!triangles.is_empty()).then_some((vertices, triangles))
}

/// Tessellated geometry of every (piece, rest state) asked for so far. Tessellation is the only
/// costly step of drawing; posing reuses these meshes every frame. Make a new cache (or call
/// [`TessellationCache::clear`]) when the grammar changes.
#[derive(Clone, Debug, Default)]
pub struct TessellationCache {
    meshes: HashMap<(usize, usize), Arc<[Mesh]>>,
}

impl TessellationCache {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn clear(&mut self) {
        self.meshes.clear();
    }

    /// The meshes shown while `piece` is in rest state `state` (the state's own geometry, or the
    /// geometry of its geometry frame when it has none). Unknown indices give no meshes.
    pub fn meshes(&mut self, grammar: &CompiledGrammar, piece: usize, state: usize) -> Arc<[Mesh]> {
        self.meshes
            .entry((piece, state))
            .or_insert_with(|| {
                shown_geometry(grammar, piece, state)
                    .map(|(proxies, _)| proxies.iter().filter_map(tessellate_proxy).collect())
                    .unwrap_or_else(|| Arc::from(Vec::new()))
            })
            .clone()
    }
}

/// The proxies shown for a piece in a rest state, and the index of the state whose positions
/// they are authored against.
pub fn shown_geometry(
    grammar: &CompiledGrammar,
    piece: usize,
    state: usize,
) -> Option<(&[Proxy], usize)> {
    let states = &grammar.pieces.get(piece)?.states;
    let rest = states.get(state)?;
    let frame = if rest.geometry_frame < states.len() {
        rest.geometry_frame
    } else {
        state
    };
    if rest.geometry.is_empty() && frame != state {
        return Some((&states[frame].geometry, frame));
    }
    Some((&rest.geometry, frame))
}

fn triangle_area(p: [DVec2; 3]) -> f64 {
    signed_area(p).abs()
}

fn signed_area(p: [DVec2; 3]) -> f64 {
    crate::plane::triangle_area(p[0], p[1], p[2])
}

fn scale_of(p: [DVec2; 3]) -> f64 {
    p.iter().map(|q| q.length_squared()).fold(1.0, f64::max)
}

fn ccw(vertices: &[DVec2], t: [u32; 3]) -> [u32; 3] {
    if signed_area(t.map(|i| vertices[i as usize])) < 0.0 {
        [t[0], t[2], t[1]]
    } else {
        t
    }
}

/// Drops non-finite points and consecutive duplicates (including a repeated first point);
/// `None` when fewer than three points or no area remain.
fn clean_ring(ring: &[DVec2]) -> Option<Vec<DVec2>> {
    let mut out: Vec<DVec2> = Vec::with_capacity(ring.len());
    for &p in ring {
        if p.is_finite() && out.last() != Some(&p) {
            out.push(p);
        }
    }
    while out.len() > 1 && out.first() == out.last() {
        out.pop();
    }
    (out.len() >= 3 && crate::plane::polygon_area(out.iter().copied()).abs() > MIN_RING_AREA)
        .then_some(out)
}

/// Edges that belong to exactly one triangle, oriented as in that triangle, in the order the
/// triangles give them. Sorting the undirected edges counts them in O(n log n).
fn boundary_edges(triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let undirected = |t: &[u32; 3], k: usize| {
        let (a, b) = (t[k], t[(k + 1) % 3]);
        [a.min(b), a.max(b)]
    };
    let mut sorted: Vec<[u32; 2]> = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| undirected(t, k)))
        .collect();
    sorted.sort_unstable();
    let once = |e: [u32; 2]| {
        let first = sorted.partition_point(|x| *x < e);
        sorted.get(first + 1) != Some(&e)
    };
    let mut out = Vec::new();
    for t in triangles {
        for k in 0..3 {
            if once(undirected(t, k)) {
                out.push([t[k], t[(k + 1) % 3]]);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_becomes_two_triangles_of_unit_area() {
        let sq = [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y];
        let (v, t) = tessellate_polygon(&sq, &[]).unwrap();
        assert_eq!(t.len(), 2);
        let area: f64 = t
            .iter()
            .map(|t| signed_area(t.map(|i| v[i as usize])))
            .sum();
        assert!((area - 1.0).abs() < 1e-12, "area {area}");
    }

    #[test]
    fn degenerate_rings_are_skipped() {
        let line = [DVec2::ZERO, DVec2::X, DVec2::X * 2.0];
        assert!(tessellate_polygon(&line, &[]).is_none());
        let dup = [DVec2::ZERO, DVec2::ZERO, DVec2::ZERO];
        assert!(tessellate_polygon(&dup, &[]).is_none());
        let nan = [DVec2::ZERO, DVec2::X, DVec2::new(f64::NAN, 1.0)];
        assert!(tessellate_polygon(&nan, &[]).is_none());
        assert!(tessellate_polyline(&[DVec2::ZERO, DVec2::ZERO], 1.0).is_none());
        assert!(tessellate_polyline(&[DVec2::ZERO, DVec2::X], 0.0).is_none());
    }

    /// The walk keeps exactly the triangles whose centroid the even-odd ray test puts inside, on
    /// small integer rings full of duplicates, collinear runs, shared edges and touching corners.
    #[test]
    fn the_walk_agrees_with_the_even_odd_test() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = |n: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % n) as f64
        };
        let (mut walked, mut compared) = (0, 0);
        for _ in 0..12_000 {
            let mut ring = |len: u64, scale: f64| -> Vec<DVec2> {
                let n = 3 + next(len) as usize;
                (0..n)
                    .map(|_| DVec2::new(next(7) - 3.0, next(7) - 3.0) * scale)
                    .collect()
            };
            let rings: Vec<Vec<DVec2>> = [ring(6, 1.0), ring(4, 0.5)]
                .iter()
                .filter_map(|r| clean_ring(r))
                .collect();
            let Some((cdt, Some(cover))) = constrained(&rings) else {
                continue;
            };
            walked += 1;
            for (face, inside) in cdt.inner_faces().zip(inside_by_walk(&cdt, &cover)) {
                let pts = face.positions().map(|p| DVec2::new(p.x, p.y));
                if signed_area(pts).abs() > 1e-9 {
                    let centroid = (pts[0] + pts[1] + pts[2]) / 3.0;
                    assert_eq!(
                        inside,
                        crate::plane::rings_contain(&rings, centroid),
                        "{rings:?}"
                    );
                    compared += 1;
                }
            }
        }
        assert!(walked > 1500 && compared > 8000, "{walked} {compared}");
    }

    #[test]
    fn straight_polyline_covers_length_times_width() {
        let (v, t) =
            tessellate_polyline(&[DVec2::ZERO, DVec2::X * 2.0, DVec2::X * 3.0], 0.5).unwrap();
        let area: f64 = t
            .iter()
            .map(|t| signed_area(t.map(|i| v[i as usize])))
            .sum();
        assert!((area - 1.5).abs() < 1e-9, "area {area}");
    }
}
