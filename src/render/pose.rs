//! Posing (paper 5.2, skinning): maps each instance's tessellated proxy geometry from its rest
//! frame into the world, rigidly for connectors and by linear blend skinning between the two
//! axis-site frames for linear pieces. The output is plain world-space triangles that tiny-skia,
//! SVG and egui all draw the same way.

use clay_dsl::compiled::{AssemblyData, Binding, CompiledGrammar, Rgba};
use glam::DVec2;

use super::tessellate::{Mesh, TessellationCache, shown_geometry};
pub use crate::fit::{RigidMotion, rigid_motion};

/// The frame of one axis site: its vertex centroid and its tangent (first to last site vertex),
/// at rest and now. Mapping through it keeps the tangential coordinate scaled by the site's
/// change of width, so the site's own vertices land exactly on their current positions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SiteFrame {
    pub rest_origin: DVec2,
    pub rest_tangent: DVec2,
    pub origin: DVec2,
    pub tangent: DVec2,
    /// Current site width over rest site width (1 for single-vertex sites).
    pub stretch: f64,
}

impl SiteFrame {
    pub fn apply(&self, p: DVec2) -> DVec2 {
        let d = p - self.rest_origin;
        let t = d.dot(self.rest_tangent);
        let n = d.dot(self.rest_tangent.perp());
        self.origin + self.tangent * (t * self.stretch) + self.tangent.perp() * n
    }
}

/// Linear blend skinning between the frames of a piece's two axis sites: a point's weight is
/// its projection on the rest axis, 0 at the `from` site and 1 at the `to` site, clamped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Skin {
    pub from: SiteFrame,
    pub to: SiteFrame,
}

impl Skin {
    /// Builds the skin from rest and current positions of the piece's vertices; `None` when the
    /// sites are empty, out of range, coincide, or positions are not finite.
    pub fn new(
        rest: &[DVec2],
        current: &[DVec2],
        from_site: &[usize],
        to_site: &[usize],
    ) -> Option<Self> {
        let centroid = |pos: &[DVec2], site: &[usize]| -> Option<DVec2> {
            let mut sum = DVec2::ZERO;
            for &v in site {
                sum += *pos.get(v)?;
            }
            (!site.is_empty()).then(|| sum / site.len() as f64)
        };
        let (r0, r1) = (centroid(rest, from_site)?, centroid(rest, to_site)?);
        let (c0, c1) = (centroid(current, from_site)?, centroid(current, to_site)?);
        let rest_axis = (r1 - r0).try_normalize()?;
        let axis = (c1 - c0).try_normalize()?;
        let frame = |site: &[usize], rest_origin: DVec2, origin: DVec2| -> SiteFrame {
            let (first, last) = (site[0], site[site.len() - 1]);
            let rest_span = rest[last] - rest[first];
            let span = current[last] - current[first];
            match (rest_span.try_normalize(), span.try_normalize()) {
                (Some(rest_tangent), Some(tangent)) => SiteFrame {
                    rest_origin,
                    rest_tangent,
                    origin,
                    tangent,
                    stretch: span.length() / rest_span.length(),
                },
                // A one-vertex site has no tangent of its own: the axis turns it instead.
                _ => SiteFrame {
                    rest_origin,
                    rest_tangent: rest_axis.perp(),
                    origin,
                    tangent: axis.perp(),
                    stretch: 1.0,
                },
            }
        };
        let skin = Self {
            from: frame(from_site, r0, c0),
            to: frame(to_site, r1, c1),
        };
        let finite = |f: &SiteFrame| {
            f.tangent.is_finite() && f.rest_tangent.is_finite() && f.stretch.is_finite()
        };
        (finite(&skin.from) && finite(&skin.to)).then_some(skin)
    }

    /// The blend weight of a rest-frame point: 0 at the `from` site, 1 at the `to` site.
    pub fn weight(&self, p: DVec2) -> f64 {
        let axis = self.to.rest_origin - self.from.rest_origin;
        ((p - self.from.rest_origin).dot(axis) / axis.length_squared()).clamp(0.0, 1.0)
    }

    pub fn apply(&self, p: DVec2) -> DVec2 {
        let w = self.weight(p);
        self.from.apply(p) * (1.0 - w) + self.to.apply(p) * w
    }
}

/// World-space triangles of one proxy of one instance: what every drawing back end consumes.
#[derive(Clone, Debug, PartialEq)]
pub struct WorldMesh {
    /// Positions in metres (x east, y north).
    pub positions: Vec<[f32; 2]>,
    /// Counter-clockwise in rest coordinates; skinning may flip a badly folded triangle.
    pub triangles: Vec<[u32; 3]>,
    /// Boundary edges for outlines.
    pub outline: Vec<[u32; 2]>,
    pub fill: Rgba,
    /// The instance (index into [`AssemblyData::instances`]) the mesh belongs to.
    pub instance: usize,
}

/// Poses one instance's geometry for its active rest state. Instances whose indices or
/// positions are broken give no meshes; triangles touching a non-finite vertex are dropped.
pub fn pose_instance(
    grammar: &CompiledGrammar,
    assembly: &AssemblyData,
    instance: usize,
    cache: &mut TessellationCache,
) -> Vec<WorldMesh> {
    let Some(inst) = assembly.instances.get(instance) else {
        return Vec::new();
    };
    let Some(current) = inst
        .vertices
        .iter()
        .map(|&v| assembly.positions.get(v).copied())
        .collect::<Option<Vec<DVec2>>>()
    else {
        return Vec::new();
    };
    pose_piece(grammar, inst.piece, inst.state, &current, cache)
        .into_iter()
        .map(|mut m| {
            m.instance = instance;
            m
        })
        .collect()
}

/// Poses a piece in rest state `state` whose vertices are now at `current` (one per piece
/// vertex). The sheet uses this with the state's own rest positions.
pub fn pose_piece(
    grammar: &CompiledGrammar,
    piece: usize,
    state: usize,
    current: &[DVec2],
    cache: &mut TessellationCache,
) -> Vec<WorldMesh> {
    let Some((_, frame)) = shown_geometry(grammar, piece, state) else {
        return Vec::new();
    };
    let p = &grammar.pieces[piece];
    let rest = &p.states[frame].positions;
    let rigid = rigid_motion(rest, current);
    let skin = p.axis.and_then(|[a, b]| {
        Skin::new(
            rest,
            current,
            &p.sites.get(a)?.vertices,
            &p.sites.get(b)?.vertices,
        )
    });
    let meshes = cache.meshes(grammar, piece, state);
    meshes
        .iter()
        .filter_map(|mesh| {
            let map = |q: DVec2| match (mesh.binding, skin, rigid) {
                (Binding::Skinned, Some(s), _) => Some(s.apply(q)),
                // A skinned proxy without a usable axis falls back to the rigid motion.
                (_, _, Some(r)) => Some(r.apply(q)),
                _ => None,
            };
            world_mesh(mesh, map)
        })
        .collect()
}

/// Poses every instance of the assembly, in instance order.
pub fn pose_assembly(
    grammar: &CompiledGrammar,
    assembly: &AssemblyData,
    cache: &mut TessellationCache,
) -> Vec<WorldMesh> {
    (0..assembly.instances.len())
        .flat_map(|i| pose_instance(grammar, assembly, i, cache))
        .collect()
}

/// The current outward direction of a site of an instance: the site's `out` (base-state
/// coordinates) turned by the instance's best rigid motion from its base state.
pub fn site_out(
    grammar: &CompiledGrammar,
    piece: usize,
    site: usize,
    current: &[DVec2],
) -> Option<DVec2> {
    let p = grammar.pieces.get(piece)?;
    let out = p.sites.get(site)?.out;
    let motion = rigid_motion(&p.states.first()?.positions, current)?;
    motion.apply_direction(out).try_normalize()
}

fn world_mesh(mesh: &Mesh, map: impl Fn(DVec2) -> Option<DVec2>) -> Option<WorldMesh> {
    let mapped: Vec<Option<[f32; 2]>> = mesh
        .vertices
        .iter()
        .map(|&q| {
            let w = map(q)?;
            let f = [w.x as f32, w.y as f32];
            (f[0].is_finite() && f[1].is_finite()).then_some(f)
        })
        .collect();
    let ok = |i: &u32| mapped[*i as usize].is_some();
    let triangles: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .copied()
        .filter(|t| t.iter().all(ok))
        .collect();
    if triangles.is_empty() {
        return None;
    }
    let outline = mesh
        .outline
        .iter()
        .copied()
        .filter(|e| e.iter().all(ok))
        .collect();
    // Unmapped vertices keep a finite placeholder; no kept triangle or edge refers to them.
    let positions = mapped
        .into_iter()
        .map(|p| p.unwrap_or([0.0, 0.0]))
        .collect();
    Some(WorldMesh {
        positions,
        triangles,
        outline,
        fill: mesh.fill,
        instance: 0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn procrustes_recovers_a_rotation() {
        let rest = [DVec2::ZERO, DVec2::X, DVec2::new(1.0, 2.0)];
        let turn = DVec2::from_angle(0.7);
        let now: Vec<DVec2> = rest
            .iter()
            .map(|p| turn.rotate(*p) + DVec2::new(3.0, -1.0))
            .collect();
        let m = rigid_motion(&rest, &now).unwrap();
        for (a, b) in rest.iter().zip(&now) {
            assert!(m.apply(*a).distance(*b) < 1e-12);
        }
    }

    #[test]
    fn skin_ends_follow_site_vertices() {
        // A brick: west site [nw, sw], east site [se, ne]; stretch the east end by 0.5.
        let rest = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 0.5),
            DVec2::new(0.0, 0.5),
        ];
        let now = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.5, 0.1),
            DVec2::new(1.5, 0.6),
            DVec2::new(0.0, 0.5),
        ];
        let skin = Skin::new(&rest, &now, &[3, 0], &[1, 2]).unwrap();
        for (a, b) in rest.iter().zip(&now) {
            assert!(
                skin.apply(*a).distance(*b) < 1e-12,
                "{a} -> {} not {b}",
                skin.apply(*a)
            );
        }
    }
}
