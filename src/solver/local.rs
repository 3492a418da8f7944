//! The local step (paper 4.1-4.3): for each part and each of its rest states, the optimal 2D
//! rotation onto the current pose and the shape distance, the choice of the active rest state
//! with hysteresis, and the per-edge rotations `R_xy` averaged over the parts touching an edge.

use clay_dsl::compiled::Part;
use glam::DVec2;

/// Optimal rigid alignment of a rest state onto a current pose (2D Procrustes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Alignment {
    /// The rotation taking the centred rest state onto the centred pose, as `(cos, sin)`.
    pub rotation: DVec2,
    /// Sum of squared vertex distances after the alignment (never negative).
    pub distance: f64,
}

/// Aligns `rest` (one position per vertex) to the current positions of `vertices`.
/// Degenerate poses (all coincident) give the identity rotation, never NaN.
pub fn align(rest: &[DVec2], vertices: &[usize], positions: &[DVec2]) -> Alignment {
    let m = vertices.len().min(rest.len());
    if m == 0 {
        return Alignment { rotation: DVec2::X, distance: 0.0 };
    }
    let inv = 1.0 / m as f64;
    let rest_centre = rest[..m].iter().copied().sum::<DVec2>() * inv;
    let pose_centre = vertices[..m].iter().map(|&v| positions[v]).sum::<DVec2>() * inv;
    // sum of dot products and of cross products of centred rest (p) and pose (q) vectors:
    // the best rotation angle is atan2(cross, dot), and the residual after it is
    // |p|^2 + |q|^2 - 2 * |(dot, cross)|.
    let (mut dot, mut cross, mut pp, mut qq) = (0.0, 0.0, 0.0, 0.0);
    for k in 0..m {
        let p = rest[k] - rest_centre;
        let q = positions[vertices[k]] - pose_centre;
        dot += p.dot(q);
        cross += p.perp_dot(q);
        pp += p.length_squared();
        qq += q.length_squared();
    }
    let len = dot.hypot(cross);
    let rotation = if len > 1e-300 && len.is_finite() { DVec2::new(dot / len, cross / len) } else { DVec2::X };
    let distance = (pp + qq - 2.0 * len).max(0.0);
    Alignment { rotation, distance: if distance.is_finite() { distance } else { f64::MAX } }
}

/// Picks the active state of `part` for the current positions: the nearest rest state, but
/// only when it is closer than `(1 - hysteresis)` times the active one (paper 4.3). Returns
/// the (possibly new) active state and the rotation of that state onto the pose.
pub fn choose_state(part: &Part, positions: &[DVec2], hysteresis: f64) -> (usize, DVec2) {
    let active = part.active.min(part.states.len().saturating_sub(1));
    let Some(current) = part.states.get(active) else {
        return (0, DVec2::X);
    };
    let here = align(&current.positions, &part.vertices, positions);
    if part.states.len() < 2 {
        return (active, here.rotation);
    }
    let mut best = (active, here);
    for (j, state) in part.states.iter().enumerate() {
        if j == active {
            continue;
        }
        let a = align(&state.positions, &part.vertices, positions);
        if a.distance < best.1.distance {
            best = (j, a);
        }
    }
    if best.0 != active && best.1.distance < (1.0 - hysteresis) * here.distance {
        (best.0, best.1.rotation)
    } else {
        (active, here.rotation)
    }
}

/// Rotation of the active state of `part` onto the pose, states fixed.
pub fn part_rotation(part: &Part, positions: &[DVec2]) -> DVec2 {
    match part.states.get(part.active) {
        Some(s) => align(&s.positions, &part.vertices, positions).rotation,
        None => DVec2::X,
    }
}

/// Sums the rotations of the parts containing each vertex into `sums` (resized to
/// `vertex_count`), for [`edge_rotation`].
pub fn vertex_rotation_sums(parts: &[Part], rotations: &[DVec2], vertex_count: usize, sums: &mut Vec<DVec2>) {
    sums.clear();
    sums.resize(vertex_count, DVec2::ZERO);
    for (part, &r) in parts.iter().zip(rotations) {
        for &v in &part.vertices {
            sums[v] += r;
        }
    }
}

/// `R_xy`: the average of the rotations of the parts containing `x` or `y`, as a normalised
/// sum of unit complex numbers (never an average of angles). Parts containing both count
/// twice, which keeps this O(1) per edge. Falls back to the part's own rotation when the
/// rotations cancel out.
pub fn edge_rotation(sums: &[DVec2], x: usize, y: usize, own: DVec2) -> DVec2 {
    let s = sums[x] + sums[y];
    let len = s.length();
    if len > 1e-9 && len.is_finite() { s / len } else { own }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn align_recovers_a_rotation_and_zero_distance() {
        let rest = [DVec2::new(0.0, 0.0), DVec2::new(1.0, 0.0), DVec2::new(0.0, 2.0)];
        let rot = DVec2::from_angle(0.7);
        let pos: Vec<DVec2> = rest.iter().map(|&p| rot.rotate(p) + DVec2::new(3.0, -1.0)).collect();
        let a = align(&rest, &[0, 1, 2], &pos);
        assert!((a.rotation - rot).length() < 1e-12);
        assert!(a.distance < 1e-12);
    }

    #[test]
    fn coincident_vertices_give_identity_not_nan() {
        let rest = [DVec2::ZERO; 3];
        let pos = [DVec2::new(1.0, 1.0); 3];
        let a = align(&rest, &[0, 1, 2], &pos);
        assert_eq!(a.rotation, DVec2::X);
        assert!(a.distance.is_finite());
    }

    #[test]
    fn opposite_rotations_fall_back_to_own() {
        let sums = [DVec2::X, -DVec2::X];
        assert_eq!(edge_rotation(&sums, 0, 1, DVec2::Y), DVec2::Y);
    }
}
