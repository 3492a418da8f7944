//! The boundary contours of a posed triangle mesh, so that a canvas can fill a large mesh as a
//! few closed paths instead of one subpath per triangle. A rasteriser walks every edge of its
//! path across every scanline it spans; the interior edges of a big tessellation (long chords
//! of a 200,000-point ring) cost far more than the boundary, though they cancel out.

use glam::DVec2;

/// Whether a pixel-space point is finite (NaN or infinity never reaches a picture).
pub(crate) fn finite(p: &[f32; 2]) -> bool {
    p[0].is_finite() && p[1].is_finite()
}

/// Meshes with fewer triangles are filled triangle by triangle: cheap at that size, and the
/// pictures in `docs/pictures/` stay exactly as they are.
pub const CONTOUR_MIN_TRIANGLES: usize = 256;

/// The closed contours whose nonzero fill covers the union of the triangles, or `None` when
/// there is none to be had cheaply: a corner missing or not finite, or triangles turning both
/// ways (a fold, where the union is not what the boundary winds around).
///
/// A sliver whose area is within the rounding error of its `f32` corners has no orientation to
/// speak of (near-collinear points of a fine ring give many) and does not count as turning
/// either way: whatever it covers is far below a pixel.
///
/// The contours are the sum of the triangles' boundaries: each directed edge counted by how
/// many triangles run along it one way minus the other. With all triangles turning the same
/// way, the winding number this chain gives a point is the number of triangles over it.
pub fn contours(points: &[[f32; 2]], triangles: &[[u32; 3]]) -> Option<Vec<Vec<[f32; 2]>>> {
    let (mut ccw, mut cw) = (false, false);
    // Every directed edge as (lower index, higher index, +1 low to high or -1 high to low).
    let mut edges: Vec<(u32, u32, i64)> = Vec::with_capacity(triangles.len() * 3);
    for t in triangles {
        let mut c = [DVec2::ZERO; 3];
        for (k, &i) in t.iter().enumerate() {
            let p = points.get(i as usize).filter(|p| finite(p))?;
            c[k] = DVec2::new(f64::from(p[0]), f64::from(p[1]));
        }
        // Twice the area (exact in f64 for f32 corners, but for the last rounding), against
        // the error that rounding the corners to f32 can make of it.
        let area = (c[1] - c[0]).perp_dot(c[2] - c[0]);
        let magnitude = c.iter().map(|p| p.abs().max_element()).fold(1.0, f64::max);
        let longest = (0..3)
            .map(|k| c[k].distance(c[(k + 1) % 3]))
            .fold(0.0, f64::max);
        let noise = 8.0 * f64::from(f32::EPSILON) * magnitude * longest;
        ccw |= area > noise;
        cw |= area < -noise;
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a != b {
                edges.push((a.min(b), a.max(b), if a < b { 1 } else { -1 }));
            }
        }
    }
    if ccw && cw {
        return None;
    }
    Some(walk(points, &boundary(edges)))
}

/// The boundary chain: the directed edges whose net count is not zero, each as often as its
/// count says, sorted by their start.
fn boundary(mut edges: Vec<(u32, u32, i64)>) -> Vec<(u32, u32)> {
    edges.sort_unstable_by_key(|&(lo, hi, _)| (lo, hi));
    let mut chain = Vec::new();
    for run in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        let (lo, hi) = (run[0].0, run[0].1);
        let net: i64 = run.iter().map(|e| e.2).sum();
        let edge = if net > 0 { (lo, hi) } else { (hi, lo) };
        chain.extend(std::iter::repeat_n(edge, net.unsigned_abs() as usize));
    }
    chain.sort_unstable();
    chain
}

/// Splits a chain (sorted by start; as many edges into every vertex as out of it) into closed
/// contours of points.
fn walk(points: &[[f32; 2]], chain: &[(u32, u32)]) -> Vec<Vec<[f32; 2]>> {
    // The next unused out-going edge of each vertex, and where its edges end.
    let mut next = vec![0usize; points.len()];
    let mut end = vec![0usize; points.len()];
    let mut i = 0;
    while i < chain.len() {
        let v = chain[i].0;
        let j = i + chain[i..].partition_point(|e| e.0 == v);
        (next[v as usize], end[v as usize]) = (i, j);
        i = j;
    }
    let mut take = |v: u32| {
        let v = v as usize;
        (next[v] < end[v]).then(|| {
            next[v] += 1;
            chain[next[v] - 1].1
        })
    };
    let mut result = Vec::new();
    for &(start, _) in chain {
        // Every vertex has as many edges in as out, so a walk from `start` can only stop there.
        while let Some(mut at) = take(start) {
            let mut contour = vec![points[start as usize]];
            while at != start {
                contour.push(points[at as usize]);
                match take(at) {
                    Some(to) => at = to,
                    None => break,
                }
            }
            result.push(contour);
        }
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Twice the signed area the contours enclose.
    fn area(contours: &[Vec<[f32; 2]>]) -> f32 {
        contours
            .iter()
            .map(|c| {
                (0..c.len())
                    .map(|i| {
                        let (p, q) = (c[i], c[(i + 1) % c.len()]);
                        p[0] * q[1] - q[0] * p[1]
                    })
                    .sum::<f32>()
            })
            .sum()
    }

    #[test]
    fn a_square_with_a_hole_has_two_contours_of_the_right_area() {
        // A 3 x 3 square around a 1 x 1 hole, eight counter-clockwise triangles.
        let p = [
            [0.0, 0.0],
            [3.0, 0.0],
            [3.0, 3.0],
            [0.0, 3.0],
            [1.0, 1.0],
            [2.0, 1.0],
            [2.0, 2.0],
            [1.0, 2.0],
        ];
        let t = [
            [0, 1, 5],
            [0, 5, 4],
            [1, 2, 6],
            [1, 6, 5],
            [2, 3, 7],
            [2, 7, 6],
            [3, 0, 4],
            [3, 4, 7],
        ];
        let c = contours(&p, &t).unwrap();
        assert_eq!(c.len(), 2);
        assert_eq!(area(&c), 2.0 * 8.0);
        // Mirrored (all clockwise) the contours just turn the other way.
        let flipped: Vec<[u32; 3]> = t.iter().map(|t| [t[0], t[2], t[1]]).collect();
        assert_eq!(area(&contours(&p, &flipped).unwrap()), -2.0 * 8.0);
    }

    #[test]
    fn folds_and_broken_corners_give_none() {
        let p = [
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, 1.0],
            [0.0, 1.0],
            [f32::NAN, 0.0],
        ];
        assert!(contours(&p, &[[0, 1, 2], [0, 3, 2]]).is_none());
        assert!(contours(&p, &[[0, 1, 4]]).is_none());
        assert!(contours(&p, &[[0, 1, 9]]).is_none());
        assert_eq!(contours(&p, &[[0, 1, 2], [0, 2, 3]]).unwrap().len(), 1);
    }

    #[test]
    fn a_sliver_that_rounding_flipped_is_tolerated() {
        // A 100 px square as two triangles, and a clockwise sliver on its bottom edge whose
        // apex is one f32 step off the edge (what rounding near-collinear points can give).
        let up = f32::from_bits(1);
        let p = [
            [0.0, 0.0],
            [100.0, 0.0],
            [100.0, 100.0],
            [0.0, 100.0],
            [50.0, up],
        ];
        let c = contours(&p, &[[0, 1, 2], [0, 2, 3], [0, 4, 1]]).unwrap();
        assert!((area(&c) - 2e4).abs() < 1e-3, "{}", area(&c));
        // One a tenth of a pixel high is a real fold.
        let p = [
            [0.0, 0.0],
            [100.0, 0.0],
            [100.0, 100.0],
            [0.0, 100.0],
            [50.0, 0.1],
        ];
        assert!(contours(&p, &[[0, 1, 2], [0, 2, 3], [0, 4, 1]]).is_none());
    }
}
