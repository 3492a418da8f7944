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
        return Alignment {
            rotation: DVec2::X,
            distance: 0.0,
        };
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
    let len = (dot * dot + cross * cross).sqrt();
    let rotation = if len > 1e-300 && len.is_finite() {
        DVec2::new(dot / len, cross / len)
    } else {
        DVec2::X
    };
    let distance = (pp + qq - 2.0 * len).max(0.0);
    Alignment {
        rotation,
        distance: if distance.is_finite() {
            distance
        } else {
            f64::MAX
        },
    }
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

/// For every vertex, the parts containing it (compressed rows; built once per generation).
#[derive(Clone, Debug, Default)]
pub struct VertexParts {
    start: Vec<usize>,
    parts: Vec<usize>,
}

impl VertexParts {
    pub fn build(parts: &[Part], vertex_count: usize) -> Self {
        let mut count = vec![0usize; vertex_count + 1];
        for part in parts {
            for &v in &part.vertices {
                count[v + 1] += 1;
            }
        }
        for i in 0..vertex_count {
            count[i + 1] += count[i];
        }
        let mut fill = count.clone();
        let mut list = vec![0; count[vertex_count]];
        for (pi, part) in parts.iter().enumerate() {
            for &v in &part.vertices {
                list[fill[v]] = pi;
                fill[v] += 1;
            }
        }
        Self {
            start: count,
            parts: list,
        }
    }

    pub fn of(&self, v: usize) -> &[usize] {
        &self.parts[self.start[v]..self.start[v + 1]]
    }
}

/// Sum of the rotations of the parts containing `v` that lie within the cone `cos_cone` of
/// `own`; [`edge_rotation`] is the normalised sum of this for both ends of an edge.
pub fn vertex_rotation_sum(
    vertex_parts: &VertexParts,
    rotations: &[DVec2],
    v: usize,
    own: DVec2,
    cos_cone: f64,
) -> DVec2 {
    let mut s = DVec2::ZERO;
    for &j in vertex_parts.of(v) {
        let r = rotations[j];
        if r.dot(own) >= cos_cone {
            s += r;
        }
    }
    s
}

/// Normalises a sum of rotations, falling back to `own` when it (nearly) vanishes.
pub fn normalised_or(s: DVec2, own: DVec2) -> DVec2 {
    let len = s.length();
    if len > 1e-9 && len.is_finite() {
        s / len
    } else {
        own
    }
}

/// `R_xy` for an edge of part `own_part`: the average of the rotations of the parts containing
/// `x` or `y`, as a normalised sum of unit complex numbers (never an average of angles).
///
/// Only parts whose rotation lies within the cone `cos_cone` of the part's own rotation take
/// part: every part's rest states live in its own piece frame, so two parts meeting at a
/// corner (a wall turning 90 degrees at a tower) have rotations 90 degrees apart even at rest,
/// and averaging them would leave a rest assembly with non-zero energy. Parts containing both
/// ends count twice. Falls back to the part's own rotation when the average vanishes.
pub fn edge_rotation(
    vertex_parts: &VertexParts,
    rotations: &[DVec2],
    x: usize,
    y: usize,
    own_part: usize,
    cos_cone: f64,
) -> DVec2 {
    let own = rotations[own_part];
    if cos_cone >= 1.0 {
        return own;
    }
    let s = vertex_rotation_sum(vertex_parts, rotations, x, own, cos_cone)
        + vertex_rotation_sum(vertex_parts, rotations, y, own, cos_cone);
    normalised_or(s, own)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn align_recovers_a_rotation_and_zero_distance() {
        let rest = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(0.0, 2.0),
        ];
        let rot = DVec2::from_angle(0.7);
        let pos: Vec<DVec2> = rest
            .iter()
            .map(|&p| rot.rotate(p) + DVec2::new(3.0, -1.0))
            .collect();
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

    fn two_parts(rotations: &[DVec2]) -> (Vec<Part>, VertexParts) {
        let part = |v: Vec<usize>| Part {
            kind: clay_dsl::compiled::PartKind::Piece { instance: 0 },
            vertices: v,
            edges: vec![[0, 1]],
            states: vec![],
            active: 0,
        };
        let parts = vec![part(vec![0, 1]), part(vec![1, 2])];
        let vp = VertexParts::build(&parts, 3);
        assert_eq!(rotations.len(), 2);
        (parts, vp)
    }

    #[test]
    fn edge_rotation_averages_nearby_rotations_as_unit_complex_numbers() {
        let rotations = [DVec2::from_angle(0.1), DVec2::from_angle(0.3)];
        let (_, vp) = two_parts(&rotations);
        let r = edge_rotation(&vp, &rotations, 0, 1, 0, 0.5);
        // part 0 counts twice (it holds both ends), part 1 once
        let expected = (2.0 * rotations[0] + rotations[1]).normalize();
        assert!((r - expected).length() < 1e-12);
    }

    #[test]
    fn rotations_outside_the_cone_are_left_out() {
        let rotations = [DVec2::X, DVec2::Y];
        let (_, vp) = two_parts(&rotations);
        assert_eq!(edge_rotation(&vp, &rotations, 0, 1, 0, 0.9), DVec2::X);
        // with the cone wide open, opposite rotations may cancel: fall back to our own
        let opposite = [DVec2::X, -DVec2::X];
        assert_eq!(edge_rotation(&vp, &opposite, 1, 1, 0, -1.0), DVec2::X);
    }
}
