//! The nearest point of a line segment to a point: picking connections and strokes in the
//! editor and splitting strokes at T-junctions when authoring.

use glam::DVec2;

/// The point of the segment `a-b` nearest `p`, and its parameter `t` in `[0, 1]` (`a + (b - a)
/// t`). A degenerate segment (`a == b`) gives `a` and `t = 0`.
///
/// ```
/// use clay::segment::nearest_on_segment;
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
}
