//! Plane geometry, in one place: nearest points on segments, signed areas (counter-clockwise
//! positive, the true area, never twice it), centroids and containment. Points and vectors
//! are both `glam::DVec2`; the functions say which they take. Where a tolerance matters it
//! is an argument, never a hidden constant.

use glam::DVec2;

/// The point of the segment `a-b` nearest `p`, and its parameter `t` in `[0, 1]` (`a + (b - a)
/// t`). A degenerate segment (`a == b`) gives `a` and `t = 0`.
///
/// ```
/// use clay::nearest_on_segment;
/// use glam::DVec2;
/// let (q, t) = nearest_on_segment(DVec2::new(1.0, 5.0), DVec2::ZERO, DVec2::new(4.0, 0.0));
/// assert_eq!((q, t), (DVec2::new(1.0, 0.0), 0.25));
/// ```
pub fn nearest_on_segment(p: DVec2, a: DVec2, b: DVec2) -> (DVec2, f64) {
    let d = b - a;
    let len2 = d.length_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(d) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + d * t, t)
}

/// Distance from `p` to the segment `a-b`.
pub fn segment_distance(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    p.distance(nearest_on_segment(p, a, b).0)
}

/// Signed area of the polygon whose corners are `ring` in order (closed implicitly; positive
/// when counter-clockwise).
pub fn polygon_area(ring: impl IntoIterator<Item = DVec2>) -> f64 {
    let mut ring = ring.into_iter();
    let Some(first) = ring.next() else {
        return 0.0;
    };
    let mut twice = 0.0;
    let mut last = first;
    for p in ring {
        twice += last.perp_dot(p);
        last = p;
    }
    twice += last.perp_dot(first);
    twice / 2.0
}

/// Signed area of the triangle `a, b, c` (positive when counter-clockwise).
pub fn triangle_area(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a) / 2.0
}

/// The barycentric weights of `p` in the triangle `a, b, c` (they sum to 1, and all lie in
/// `0..=1` exactly when `p` is inside or on the boundary), or `None` for a triangle without
/// area.
pub fn barycentric(a: DVec2, b: DVec2, c: DVec2, p: DVec2) -> Option<[f64; 3]> {
    let area = (b - a).perp_dot(c - a);
    if area == 0.0 {
        return None;
    }
    Some([
        (b - p).perp_dot(c - p) / area,
        (p - a).perp_dot(c - a) / area,
        (b - a).perp_dot(p - a) / area,
    ])
}

/// Whether `p` is inside the triangle `a, b, c` or on its boundary, whatever its winding.
pub fn triangle_contains(a: DVec2, b: DVec2, c: DVec2, p: DVec2) -> bool {
    let d1 = (b - a).perp_dot(p - a);
    let d2 = (c - b).perp_dot(p - b);
    let d3 = (a - c).perp_dot(p - c);
    let neg = d1 < 0.0 || d2 < 0.0 || d3 < 0.0;
    let pos = d1 > 0.0 || d2 > 0.0 || d3 > 0.0;
    !(neg && pos)
}

/// Whether `p` is inside `rings` by the even-odd rule (inside the outer ring and outside every
/// hole; rings may wind either way): a horizontal ray from `p` crosses the rings' edges an odd
/// number of times, each edge counted half-open in y so a ray through a vertex counts once.
/// The containment rule of every ring test (tessellation keeps the triangles it puts inside);
/// a triangle with its boundary is [`triangle_contains`].
pub fn rings_contain(rings: &[Vec<DVec2>], p: DVec2) -> bool {
    let mut inside = false;
    for ring in rings {
        let n = ring.len();
        for i in 0..n {
            let (a, b) = (ring[i], ring[(i + 1) % n]);
            if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
                inside = !inside;
            }
        }
    }
    inside
}

/// The mean of the points (the centroid of a vertex set, not of an area); `None` for none.
pub fn centroid(points: impl IntoIterator<Item = DVec2>) -> Option<DVec2> {
    let (sum, n) = points
        .into_iter()
        .fold((DVec2::ZERO, 0usize), |(s, n), p| (s + p, n + 1));
    (n > 0).then(|| sum / n as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn beyond_the_ends_the_nearest_point_is_an_end() {
        let (a, b) = (DVec2::new(1.0, 1.0), DVec2::new(3.0, 1.0));
        assert_eq!(nearest_on_segment(DVec2::new(-5.0, 2.0), a, b), (a, 0.0));
        assert_eq!(nearest_on_segment(DVec2::new(9.0, 0.0), a, b), (b, 1.0));
        assert_eq!(nearest_on_segment(DVec2::new(2.0, 7.0), a, a), (a, 0.0));
    }

    #[test]
    fn areas_are_true_areas_with_the_winding_as_sign() {
        let square = [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y];
        assert_eq!(polygon_area(square), 1.0);
        assert_eq!(polygon_area(square.into_iter().rev()), -1.0);
        assert_eq!(triangle_area(DVec2::ZERO, DVec2::X, DVec2::Y), 0.5);
        assert_eq!(polygon_area([]), 0.0);
    }

    #[test]
    fn containment_includes_the_boundary_and_ignores_winding() {
        let (a, b, c) = (DVec2::ZERO, DVec2::new(2.0, 0.0), DVec2::new(0.0, 2.0));
        assert!(triangle_contains(a, b, c, DVec2::new(0.5, 0.5)));
        assert!(triangle_contains(a, c, b, DVec2::new(0.5, 0.5)));
        assert!(triangle_contains(a, b, c, DVec2::new(1.0, 0.0)));
        assert!(!triangle_contains(a, b, c, DVec2::new(1.5, 1.5)));
        assert_eq!(centroid([a, b, c]), Some(DVec2::new(2.0 / 3.0, 2.0 / 3.0)));
        assert_eq!(centroid([]), None);
    }
}
