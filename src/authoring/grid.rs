//! Uniform grids over a drawing, so that the questions authoring asks of every segment (which
//! vertices lie on it, which other segment of an outline crosses it) cost about the segment's
//! length in cells rather than the size of the drawing: a drawing of ten thousand points asked
//! pairwise is a hundred million questions, and a path that crosses itself everywhere made
//! authoring take seconds (issue 37).
//!
//! The cell size follows the points' spread: about one point per cell on average, so a cell
//! holds a few points and a segment passes about its length over the mean spacing of cells.

use std::collections::HashMap;

use glam::DVec2;

/// A cell index.
pub(crate) type Cell = (i64, i64);

/// Cell size for `count` items spread over `points`: about one per cell, never below `least`
/// (a tolerance the queries reach out by) and never so small that the longest side spans more
/// than `count` cells.
pub(crate) fn cell_size(points: impl IntoIterator<Item = DVec2>, count: usize, least: f64) -> f64 {
    let (lo, hi) = points.into_iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    );
    let size = (hi - lo).max(DVec2::ZERO);
    if !size.is_finite() {
        return least.max(1.0);
    }
    let n = count.max(1) as f64;
    let side = size.max_element();
    let h = (size.x * size.y / n).sqrt().max(side / n);
    if h.is_finite() && h > 0.0 {
        h.max(least)
    } else {
        least.max(1e-9)
    }
}

fn index(v: f64, h: f64) -> i64 {
    // Coordinates are bounded (the graph refuses points beyond its limit), so this is finite.
    (v / h).floor() as i64
}

/// Calls `visit` for every cell of size `h` that meets the segment `a-b` widened by `r` on
/// every side (a superset of the points within `r` of it). Cells are visited column by column,
/// each once.
pub(crate) fn cover(a: DVec2, b: DVec2, r: f64, h: f64, mut visit: impl FnMut(Cell)) {
    // A hair of slack so that a point on a cell's border is found from both sides.
    let r = r + 1e-9 * (1.0 + a.abs().max(b.abs()).max_element());
    let (lo, hi) = (a.min(b), a.max(b));
    let d = b - a;
    for cx in index(lo.x - r, h)..=index(hi.x + r, h) {
        // The part of the segment whose x lies within this column, widened by r.
        let (x0, x1) = (cx as f64 * h - r, (cx + 1) as f64 * h + r);
        let (t0, t1) = if d.x == 0.0 {
            (0.0, 1.0)
        } else {
            let (u, v) = ((x0 - a.x) / d.x, (x1 - a.x) / d.x);
            (u.min(v).max(0.0), u.max(v).min(1.0))
        };
        if t0 > t1 {
            continue;
        }
        let (y0, y1) = (a.y + d.y * t0, a.y + d.y * t1);
        for cy in index(y0.min(y1) - r, h)..=index(y0.max(y1) + r, h) {
            visit((cx, cy));
        }
    }
}

/// The points of a drawing bucketed by cell, for "which points lie near this segment".
pub(crate) struct PointGrid {
    h: f64,
    reach: f64,
    cells: HashMap<Cell, Vec<usize>>,
}

impl PointGrid {
    /// Buckets `points`; queries will ask for points within `reach` of a segment.
    pub(crate) fn new(points: &[DVec2], reach: f64) -> Self {
        let h = cell_size(points.iter().copied(), points.len(), 2.0 * reach);
        let mut cells: HashMap<Cell, Vec<usize>> = HashMap::new();
        for (i, p) in points.iter().enumerate() {
            cells
                .entry((index(p.x, h), index(p.y, h)))
                .or_default()
                .push(i);
        }
        Self { h, reach, cells }
    }

    /// Every point that may lie within the reach of the segment `a-b` (a superset, each once,
    /// in no particular order).
    pub(crate) fn near_segment(&self, a: DVec2, b: DVec2, out: &mut Vec<usize>) {
        out.clear();
        cover(a, b, self.reach, self.h, |c| {
            if let Some(list) = self.cells.get(&c) {
                out.extend_from_slice(list);
            }
        });
    }
}

/// `o` relative to the directed line `a-b`: positive on its left.
fn orient(a: DVec2, b: DVec2, o: DVec2) -> f64 {
    (b - a).perp_dot(o - a)
}

/// Where the segments `a-b` and `c-d` cross properly (each passes strictly from one side of the
/// other to the other), if they do.
pub(crate) fn proper_crossing(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> Option<DVec2> {
    let (o1, o2) = (orient(a, b, c), orient(a, b, d));
    let (o3, o4) = (orient(c, d, a), orient(c, d, b));
    let opposite = |x: f64, y: f64| (x > 0.0 && y < 0.0) || (x < 0.0 && y > 0.0);
    (opposite(o1, o2) && opposite(o3, o4)).then(|| {
        let t = o3 / (o3 - o4);
        a + (b - a) * t
    })
}

/// The first place (in a fixed order) where the closed polygon `ring` crosses itself: two of
/// its edges that share no corner crossing properly. Edge `i` runs from `ring[i]` to
/// `ring[i + 1]` (the last back to the first). The corners must be distinct; touching (a corner
/// on another edge) is the caller's to find.
pub(crate) fn self_crossing(ring: &[DVec2]) -> Option<(usize, usize, DVec2)> {
    let n = ring.len();
    if n < 4 {
        return None;
    }
    let edge = |i: usize| (ring[i], ring[(i + 1) % n]);
    let h = cell_size(ring.iter().copied(), n, 0.0);
    let mut entries: Vec<(Cell, usize)> = Vec::new();
    for i in 0..n {
        let (a, b) = edge(i);
        cover(a, b, 0.0, h, |c| entries.push((c, i)));
    }
    entries.sort_unstable();
    let adjacent = |i: usize, j: usize| i.abs_diff(j) == 1 || i.abs_diff(j) == n - 1;
    for group in entries.chunk_by(|x, y| x.0 == y.0) {
        for (k, &(_, i)) in group.iter().enumerate() {
            let (a, b) = edge(i);
            for &(_, j) in &group[k + 1..] {
                if adjacent(i, j) {
                    continue;
                }
                let (c, d) = edge(j);
                if let Some(p) = proper_crossing(a, b, c, d) {
                    return Some((i.min(j), i.max(j), p));
                }
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bowtie_crosses_itself_and_a_square_does_not() {
        let p = |x: f64, y: f64| DVec2::new(x, y);
        let bowtie = [p(0.0, 0.0), p(1.0, 1.0), p(1.0, 0.0), p(0.0, 1.0)];
        let (i, j, at) = self_crossing(&bowtie).unwrap();
        assert_eq!((i, j), (0, 2));
        assert!(at.distance(p(0.5, 0.5)) < 1e-12);
        let square = [p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)];
        assert_eq!(self_crossing(&square), None);
    }

    #[test]
    fn a_circle_of_many_points_is_simple_and_its_star_is_not() {
        let n = 5000;
        let at = |k: usize| DVec2::from_angle(std::f64::consts::TAU * k as f64 / n as f64);
        let circle: Vec<DVec2> = (0..n).map(at).collect();
        assert_eq!(self_crossing(&circle), None);
        let star: Vec<DVec2> = (0..n).map(|k| at(k * (n / 2 - 1) % n)).collect();
        assert!(self_crossing(&star).is_some());
    }

    #[test]
    fn the_point_grid_finds_every_point_near_a_long_segment() {
        let points: Vec<DVec2> = (0..400)
            .map(|k| DVec2::new((k % 20) as f64, (k / 20) as f64))
            .collect();
        let grid = PointGrid::new(&points, 0.01);
        let mut out = Vec::new();
        let (a, b) = (DVec2::new(-0.5, -0.5), DVec2::new(19.5, 19.5));
        grid.near_segment(a, b, &mut out);
        for (i, p) in points.iter().enumerate() {
            if crate::plane::segment_distance(*p, a, b) <= 0.01 {
                assert!(out.contains(&i), "{p} missed");
            }
        }
    }
}
