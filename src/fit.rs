//! Least-squares maps between corresponding point sets: the best rigid motion (2D Procrustes:
//! posing rigid proxy geometry, placing a junction over the instance it replaces, handles'
//! rest placement, a pin carried to a recompiled grammar) and a rest state's alignment with its
//! shape distance (the solver's local step), both from one closed form, and the best affine
//! map (laying new chain elements into a deformed pose). The one home of these fits, so the
//! solver, the renderer, the rules and the assembly agree exactly.

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
    let s = CentredSums::of(from.len(), |k| from[k], |k| to[k]);
    let rotation = DVec2::new(s.dot, s.cross).try_normalize();
    Some((
        RigidMotion {
            rotation: rotation.unwrap_or(DVec2::X),
            from_centre: s.from_centre,
            to_centre: s.to_centre,
        },
        rotation.is_some(),
    ))
}

/// The sums 2D Procrustes needs over `m` pairs `(p(k), q(k))` centred on their centroids:
/// of dot and cross products (the best rotation angle is `atan2(cross, dot)`) and of squared
/// norms (the residual after it is `pp + qq - 2 |(dot, cross)|`). The one place both fits
/// ([`fitted`], [`align`]) compute them.
struct CentredSums {
    from_centre: DVec2,
    to_centre: DVec2,
    dot: f64,
    cross: f64,
    pp: f64,
    qq: f64,
}

impl CentredSums {
    #[inline]
    fn of(m: usize, p: impl Fn(usize) -> DVec2, q: impl Fn(usize) -> DVec2) -> Self {
        let inv = 1.0 / m as f64;
        let from_centre = (0..m).map(&p).sum::<DVec2>() * inv;
        let to_centre = (0..m).map(&q).sum::<DVec2>() * inv;
        let (mut dot, mut cross, mut pp, mut qq) = (0.0, 0.0, 0.0, 0.0);
        for k in 0..m {
            let a = p(k) - from_centre;
            let b = q(k) - to_centre;
            dot += a.dot(b);
            cross += a.perp_dot(b);
            pp += a.length_squared();
            qq += b.length_squared();
        }
        Self {
            from_centre,
            to_centre,
            dot,
            cross,
            pp,
            qq,
        }
    }
}

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
    let s = CentredSums::of(m, |k| rest[k], |k| positions[vertices[k]]);
    finish(s.dot, s.cross, s.pp, s.qq)
}

/// Aligns the points `rest` to the points `pose`, pairwise (the shorter list's length); as
/// [`align`], for points that are not the model's vertices.
pub fn align_points(rest: &[DVec2], pose: &[DVec2]) -> Alignment {
    let m = rest.len().min(pose.len());
    if m == 0 {
        return Alignment {
            rotation: DVec2::X,
            distance: 0.0,
        };
    }
    let s = CentredSums::of(m, |k| rest[k], |k| pose[k]);
    finish(s.dot, s.cross, s.pp, s.qq)
}

/// The alignment from the sums of dot and cross products of the centred rest (p) and pose (q)
/// vectors and their squared norms; shared by [`align`] and the solver's rest cache so both give the
/// same result bit for bit.
pub(crate) fn finish(dot: f64, cross: f64, pp: f64, qq: f64) -> Alignment {
    let len = (dot * dot + cross * cross).sqrt();
    Alignment {
        rotation: rotation_of(dot, cross, len),
        distance: distance_of(pp, qq, len),
    }
}

#[inline]
pub(crate) fn rotation_of(dot: f64, cross: f64, len: f64) -> DVec2 {
    // divided before the test, as in `normalised_or`
    let unit = DVec2::new(dot, cross) / len;
    if len > 1e-300 && len.is_finite() {
        unit
    } else {
        DVec2::X
    }
}

pub(crate) fn distance_of(pp: f64, qq: f64, len: f64) -> f64 {
    let distance = (pp + qq - 2.0 * len).max(0.0);
    if distance.is_finite() {
        distance
    } else {
        f64::MAX
    }
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

/// The targets of a pin carried to another compilation of the grammar (a parameter changed):
/// `at`, the targets of an instance whose rest positions (piece-local) are `from`, moved
/// rigidly onto `to`, the rest positions of the instance it is carried to (same vertices in
/// the same order): the rigid motion that takes `from` to `at`, applied to `to`. So a pinned
/// post stays where the user put it, at its new width. `None` when the counts differ.
pub fn carried_targets(from: &[DVec2], at: &[DVec2], to: &[DVec2]) -> Option<Vec<DVec2>> {
    if from.len() != at.len() || from.len() != to.len() {
        return None;
    }
    let motion = rigid_motion(from, at)?;
    Some(to.iter().map(|&p| motion.apply(p)).collect())
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

    #[test]
    fn a_carried_pin_moves_the_new_shape_as_the_old_was_moved() {
        // A 1 m post pinned turned a quarter and 5 m east; carried to a 2 m post.
        let from = [
            DVec2::ZERO,
            DVec2::X,
            DVec2::new(1.0, 0.5),
            DVec2::new(0.0, 0.5),
        ];
        let turn = |p: DVec2| DVec2::new(5.0 - p.y, p.x);
        let at: Vec<DVec2> = from.iter().map(|&p| turn(p)).collect();
        let to = [
            DVec2::ZERO,
            DVec2::new(2.0, 0.0),
            DVec2::new(2.0, 0.5),
            DVec2::new(0.0, 0.5),
        ];
        let carried = carried_targets(&from, &at, &to).unwrap();
        // The piece's own frame moves as the old post's did: its corner at the origin goes
        // where the old one's went, and the post turns the same.
        assert!((carried[0] - at[0]).length() < 1e-12, "{:?}", carried[0]);
        let along = carried[1] - carried[0];
        assert!((along - DVec2::new(0.0, 2.0)).length() < 1e-12, "{along}");
        assert_eq!(carried_targets(&from, &at, &to[..3]), None);
    }
}
