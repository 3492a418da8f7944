//! Least-squares maps between corresponding point sets: the best rigid motion (2D Procrustes:
//! posing rigid proxy geometry, placing a junction over the instance it replaces, handles'
//! rest placement) and the best affine map (laying new chain elements into a deformed pose).
//! The one home of these fits, so the renderer, the rules and the assembly agree exactly.

use glam::{DMat2, DVec2};

/// A map `p -> linear * p + offset`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointMap {
    pub linear: DMat2,
    pub offset: DVec2,
}

impl PointMap {
    pub const IDENTITY: Self = Self {
        linear: DMat2::IDENTITY,
        offset: DVec2::ZERO,
    };

    pub fn apply(&self, p: DVec2) -> DVec2 {
        self.linear * p + self.offset
    }
}

/// A rotation and translation: `p -> rotation * (p - from_centre) + to_centre`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidMotion {
    /// The rotation as a unit complex number `(cos, sin)`.
    pub rotation: DVec2,
    pub from_centre: DVec2,
    pub to_centre: DVec2,
}

impl RigidMotion {
    pub const IDENTITY: Self = Self {
        rotation: DVec2::X,
        from_centre: DVec2::ZERO,
        to_centre: DVec2::ZERO,
    };

    pub fn apply(&self, p: DVec2) -> DVec2 {
        self.rotation.rotate(p - self.from_centre) + self.to_centre
    }

    /// Rotates a direction (no translation).
    pub fn apply_direction(&self, d: DVec2) -> DVec2 {
        self.rotation.rotate(d)
    }
}

/// The best rigid motion taking `from` onto `to` in the least-squares sense (2D Procrustes:
/// centre both, angle = atan2(sum of cross products, sum of dot products)), the same closed form
/// as the solver's shape distance. `None` when the slices differ in length, are empty, or hold
/// non-finite points. A single point, or points that give no rotation, give a pure translation.
pub fn rigid_motion(from: &[DVec2], to: &[DVec2]) -> Option<RigidMotion> {
    let (motion, _) = fitted(from, to)?;
    Some(motion)
}

/// The rotation of [`rigid_motion`] (a unit complex number `(cos, sin)`) when the points
/// determine one; `None` also when they give no rotation (fewer than two distinct points on a
/// side), where [`rigid_motion`] falls back to the identity.
pub fn rigid_rotation(from: &[DVec2], to: &[DVec2]) -> Option<DVec2> {
    let (motion, determined) = fitted(from, to)?;
    determined.then_some(motion.rotation)
}

/// The fit, and whether the points determined its rotation.
fn fitted(from: &[DVec2], to: &[DVec2]) -> Option<(RigidMotion, bool)> {
    if from.len() != to.len() || from.is_empty() || !from.iter().chain(to).all(|p| p.is_finite()) {
        return None;
    }
    let n = from.len() as f64;
    let from_centre = from.iter().sum::<DVec2>() / n;
    let to_centre = to.iter().sum::<DVec2>() / n;
    let (mut dot, mut cross) = (0.0, 0.0);
    for (a, b) in from.iter().zip(to) {
        let (a, b) = (*a - from_centre, *b - to_centre);
        dot += a.dot(b);
        cross += a.perp_dot(b);
    }
    let rotation = DVec2::new(dot, cross).try_normalize();
    Some((
        RigidMotion {
            rotation: rotation.unwrap_or(DVec2::X),
            from_centre,
            to_centre,
        },
        rotation.is_some(),
    ))
}

fn centroids(from: &[DVec2], to: &[DVec2]) -> (DVec2, DVec2) {
    let n = from.len().min(to.len()).max(1) as f64;
    let a = from.iter().copied().sum::<DVec2>() / n;
    let b = to.iter().copied().sum::<DVec2>() / n;
    (a, b)
}

/// Best rotation + translation taking `from[i]` to `to[i]` (2D Procrustes) as a [`PointMap`],
/// over the common prefix of the two slices. With fewer than two distinct points, or non-finite
/// input, the rotation is the identity.
pub fn rigid(from: &[DVec2], to: &[DVec2]) -> PointMap {
    let m = from.len().min(to.len());
    let Some(motion) = rigid_motion(&from[..m], &to[..m]) else {
        return PointMap::IDENTITY;
    };
    let (c, s) = (motion.rotation.x, motion.rotation.y);
    let linear = DMat2::from_cols(DVec2::new(c, s), DVec2::new(-s, c));
    PointMap {
        linear,
        offset: motion.to_centre - linear * motion.from_centre,
    }
}

/// Best affine map taking `from[i]` to `to[i]`; falls back to [`rigid`] when the source
/// points are (nearly) collinear, where an affine fit is not determined.
pub fn affine(from: &[DVec2], to: &[DVec2]) -> PointMap {
    let m = from.len().min(to.len());
    if m < 3 {
        return rigid(from, to);
    }
    let (cf, ct) = centroids(&from[..m], &to[..m]);
    // M = (sum q p^T) (sum p p^T)^-1 over centred pairs.
    let mut pp = DMat2::ZERO;
    let mut qp = DMat2::ZERO;
    let mut scale = 0.0;
    for (p, q) in from[..m].iter().zip(&to[..m]) {
        let (p, q) = (*p - cf, *q - ct);
        pp += DMat2::from_cols(p * p.x, p * p.y);
        qp += DMat2::from_cols(q * p.x, q * p.y);
        scale += p.length_squared();
    }
    let det = pp.determinant();
    // Relative test: det is of order scale^2 for well-spread points.
    if det.is_nan() || det.abs() <= 1e-9 * scale * scale {
        return rigid(from, to);
    }
    let linear = qp * pp.inverse();
    let map = PointMap {
        linear,
        offset: ct - linear * cf,
    };
    if map.linear.is_finite() && map.offset.is_finite() {
        map
    } else {
        rigid(from, to)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rigid_recovers_a_rotation_and_translation() {
        let from = [
            DVec2::new(0.0, 0.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(0.0, 1.0),
        ];
        let rot = DVec2::from_angle(0.7);
        let to: Vec<DVec2> = from
            .iter()
            .map(|p| rot.rotate(*p) + DVec2::new(3.0, -1.0))
            .collect();
        let m = rigid(&from, &to);
        for (p, q) in from.iter().zip(&to) {
            assert!(m.apply(*p).distance(*q) < 1e-12);
        }
    }

    #[test]
    fn affine_recovers_a_stretch_and_degenerates_to_rigid() {
        let from = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 0.5),
            DVec2::new(0.0, 0.5),
        ];
        let to: Vec<DVec2> = from
            .iter()
            .map(|p| DVec2::new(2.0 * p.x + 1.0, p.y))
            .collect();
        let m = affine(&from, &to);
        assert!(
            m.apply(DVec2::new(0.5, 0.25))
                .distance(DVec2::new(2.0, 0.25))
                < 1e-12
        );
        let line = [DVec2::ZERO, DVec2::X, DVec2::X * 2.0];
        let shifted: Vec<DVec2> = line.iter().map(|p| *p + DVec2::Y).collect();
        let m = affine(&line, &shifted);
        assert!(m.apply(DVec2::X).distance(DVec2::new(1.0, 1.0)) < 1e-12);
    }
}
