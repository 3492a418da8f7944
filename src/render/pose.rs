//! Posing (paper 5.2, skinning): maps each instance's tessellated proxy geometry from its rest
//! frame into the world, rigidly for connectors and by linear blend skinning between the two
//! axis-site frames for linear pieces. The output is plain world-space triangles that tiny-skia,
//! SVG and egui all draw the same way.

use std::sync::Arc;

use clay_dsl::compiled::{AssemblyData, Binding, CompiledGrammar, Extrude, Rgba};
use glam::DVec2;

use super::tessellate::{Mesh, Solid, TessellationCache, shown_geometry};
use crate::fit::rigid_motion;

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
    /// sites are empty, out of range, coincide, or positions are not finite. Only the tests
    /// build a skin by hand (posing builds it from the rest data once).
    #[cfg(any(test, feature = "testing"))]
    pub fn new(
        rest: &[DVec2],
        current: &[DVec2],
        from_site: &[usize],
        to_site: &[usize],
    ) -> Option<Self> {
        RestSkin::new(rest, from_site, to_site)?.pose(current)
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

/// The centroid of a site's vertices; `None` when the site is empty or out of range.
fn centroid(positions: &[DVec2], site: &[usize]) -> Option<DVec2> {
    let points = site
        .iter()
        .map(|&v| positions.get(v).copied())
        .collect::<Option<Vec<DVec2>>>()?;
    crate::plane::centroid(points)
}

/// One axis site at rest: its vertices, centroid, unit tangent (first to last vertex; `None`
/// for a one-vertex site) and width.
#[derive(Clone, Copy, Debug)]
struct RestSite<'g> {
    vertices: &'g [usize],
    origin: DVec2,
    tangent: Option<DVec2>,
    width: f64,
}

impl<'g> RestSite<'g> {
    /// `vertices` must be in range of `rest` (their centroid was found).
    fn new(rest: &[DVec2], vertices: &'g [usize], origin: DVec2) -> Self {
        let span = rest[vertices[vertices.len() - 1]] - rest[vertices[0]];
        Self {
            vertices,
            origin,
            tangent: span.try_normalize(),
            width: span.length(),
        }
    }

    fn frame(&self, current: &[DVec2], origin: DVec2, rest_axis: DVec2, axis: DVec2) -> SiteFrame {
        let span = current[self.vertices[self.vertices.len() - 1]] - current[self.vertices[0]];
        match (self.tangent, span.try_normalize()) {
            (Some(rest_tangent), Some(tangent)) => SiteFrame {
                rest_origin: self.origin,
                rest_tangent,
                origin,
                tangent,
                stretch: span.length() / self.width,
            },
            // A one-vertex site has no tangent of its own: the axis turns it instead.
            _ => SiteFrame {
                rest_origin: self.origin,
                rest_tangent: rest_axis.perp(),
                origin,
                tangent: axis.perp(),
                stretch: 1.0,
            },
        }
    }
}

/// The half of a [`Skin`] that depends only on the rest state, so posing many instances of a
/// piece computes it once (it is half of the skin's square roots and divisions).
#[derive(Clone, Copy, Debug)]
struct RestSkin<'g> {
    from: RestSite<'g>,
    to: RestSite<'g>,
    axis: DVec2,
}

impl<'g> RestSkin<'g> {
    fn new(rest: &[DVec2], from_site: &'g [usize], to_site: &'g [usize]) -> Option<Self> {
        let (r0, r1) = (centroid(rest, from_site)?, centroid(rest, to_site)?);
        Some(Self {
            axis: (r1 - r0).try_normalize()?,
            from: RestSite::new(rest, from_site, r0),
            to: RestSite::new(rest, to_site, r1),
        })
    }

    /// The skin for the piece's vertices now at `current`.
    fn pose(&self, current: &[DVec2]) -> Option<Skin> {
        let c0 = centroid(current, self.from.vertices)?;
        let c1 = centroid(current, self.to.vertices)?;
        let axis = (c1 - c0).try_normalize()?;
        let skin = Skin {
            from: self.from.frame(current, c0, self.axis, axis),
            to: self.to.frame(current, c1, self.axis, axis),
        };
        let finite = |f: &SiteFrame| {
            f.tangent.is_finite() && f.rest_tangent.is_finite() && f.stretch.is_finite()
        };
        (finite(&skin.from) && finite(&skin.to)).then_some(skin)
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
    /// The proxy's heights for the 3D export (`None`: flat geometry).
    pub extrude: Option<Extrude>,
    /// The 3D surface of a mesh asset over `positions` (heights unchanged by posing).
    pub solid: Option<Arc<Solid>>,
    /// The instance (index into [`AssemblyData::instances`]) the mesh belongs to.
    pub instance: usize,
}

/// Poses one instance's geometry for its active rest state. Instances whose indices or
/// positions are broken give no meshes; triangles touching a non-finite vertex are dropped.
/// The tests' reference (posing goes through [`pose_assembly_into`]).
#[cfg(any(test, feature = "testing"))]
pub fn pose_instance(
    grammar: &CompiledGrammar,
    assembly: &AssemblyData,
    instance: usize,
    cache: &mut TessellationCache,
) -> Vec<WorldMesh> {
    let mut out = Vec::new();
    let Some(inst) = assembly.instances.get(instance) else {
        return out;
    };
    let mut current = Vec::new();
    if !gather(&assembly.positions, &inst.vertices, &mut current) {
        return out;
    }
    if let Some(shown) = Shown::new(grammar, inst.piece, inst.state, cache) {
        let used = shown.pose_into(&current, instance, &mut out, 0);
        out.truncate(used);
    }
    out
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
    let mut out = Vec::new();
    if let Some(shown) = Shown::new(grammar, piece, state, cache) {
        let used = shown.pose_into(current, 0, &mut out, 0);
        out.truncate(used);
    }
    out
}

/// Poses every instance of the assembly, in instance order.
pub fn pose_assembly(
    grammar: &CompiledGrammar,
    assembly: &AssemblyData,
    cache: &mut TessellationCache,
) -> Vec<WorldMesh> {
    let mut out = Vec::with_capacity(assembly.instances.len());
    pose_assembly_into(grammar, assembly, cache, &mut out);
    out
}

/// `pose_assembly` into `out`, reusing its meshes' buffers: what the editor calls on every
/// solver frame, where a fresh `Vec` of fresh meshes would cost most of the posing time in the
/// allocator. Afterwards `out` holds exactly what `pose_assembly` (the tests') returns.
pub fn pose_assembly_into(
    grammar: &CompiledGrammar,
    assembly: &AssemblyData,
    cache: &mut TessellationCache,
    out: &mut Vec<WorldMesh>,
) {
    // What does not depend on current positions is found once per (piece, state) and call,
    // not once per instance: slot `first_state[piece] + state`, filled on first use.
    let mut first_state = Vec::with_capacity(grammar.pieces.len());
    let mut states = 0;
    for p in &grammar.pieces {
        first_state.push(states);
        states += p.states.len();
    }
    let mut shown: Vec<Option<Option<Shown>>> = vec![None; states];

    let mut current = Vec::new();
    let mut used = 0;
    for (i, inst) in assembly.instances.iter().enumerate() {
        let Some(piece) = grammar.pieces.get(inst.piece) else {
            continue;
        };
        if inst.state >= piece.states.len()
            || !gather(&assembly.positions, &inst.vertices, &mut current)
        {
            continue;
        }
        let slot = &mut shown[first_state[inst.piece] + inst.state];
        let slot = slot.get_or_insert_with(|| Shown::new(grammar, inst.piece, inst.state, cache));
        if let Some(s) = slot {
            used = s.pose_into(&current, i, out, used);
        }
    }
    out.truncate(used);
}

/// Copies the current positions of an instance's vertices into `current`; false when an index
/// is out of range (the instance is then not drawn).
fn gather(positions: &[DVec2], vertices: &[usize], current: &mut Vec<DVec2>) -> bool {
    current.clear();
    for &v in vertices {
        match positions.get(v) {
            Some(&p) => current.push(p),
            None => return false,
        }
    }
    true
}

/// What posing needs of a piece in a rest state that does not depend on where its vertices are
/// now: the tessellated proxies, the rest positions they are authored against, and the rest
/// half of the skin (only when a proxy is skinned).
#[derive(Clone)]
struct Shown<'g> {
    meshes: Arc<[Mesh]>,
    rest: &'g [DVec2],
    skin: Option<RestSkin<'g>>,
    all_skinned: bool,
}

impl<'g> Shown<'g> {
    /// `None` when the piece or state does not exist.
    fn new(
        grammar: &'g CompiledGrammar,
        piece: usize,
        state: usize,
        cache: &mut TessellationCache,
    ) -> Option<Self> {
        let (_, frame) = shown_geometry(grammar, piece, state)?;
        let p = &grammar.pieces[piece];
        let rest = &p.states[frame].positions;
        let meshes = cache.meshes(grammar, piece, state);
        let skinned = |m: &Mesh| m.binding == Binding::Skinned;
        let skin = if meshes.iter().any(skinned) {
            p.axis.and_then(|[a, b]| {
                RestSkin::new(rest, &p.sites.get(a)?.vertices, &p.sites.get(b)?.vertices)
            })
        } else {
            None
        };
        let all_skinned = meshes.iter().all(skinned);
        Some(Self {
            meshes,
            rest,
            skin,
            all_skinned,
        })
    }

    /// Writes the meshes posed for vertices at `current` into `out[used..]`, overwriting (and
    /// reusing the buffers of) meshes already there; returns the new count of meshes in use.
    /// Meshes left with no triangle are not kept.
    fn pose_into(
        &self,
        current: &[DVec2],
        instance: usize,
        out: &mut Vec<WorldMesh>,
        mut used: usize,
    ) -> usize {
        if self.meshes.is_empty() {
            return used;
        }
        let skin = self.skin.as_ref().and_then(|s| s.pose(current));
        // The rigid motion serves rigid proxies, and skinned ones when the skin is unusable.
        let rigid = if skin.is_none() || !self.all_skinned {
            rigid_motion(self.rest, current)
        } else {
            None
        };
        for mesh in self.meshes.iter() {
            let kept = match (mesh.binding, &skin, &rigid) {
                (Binding::Skinned, Some(s), _) => write_mesh(mesh, |q| s.apply(q), out, used),
                // A skinned proxy without a usable axis falls back to the rigid motion.
                (_, _, Some(r)) => write_mesh(mesh, |q| r.apply(q), out, used),
                // No vertex can be placed, so no triangle survives.
                _ => false,
            };
            if kept {
                out[used].instance = instance;
                used += 1;
            }
        }
        used
    }
}

/// Writes `mesh` mapped through `map` into `out[at]` (pushed when `out` is that short); false
/// when no triangle has all three vertices finite, in which case `out[at]` is scratch.
fn write_mesh(
    mesh: &Mesh,
    map: impl Fn(DVec2) -> DVec2,
    out: &mut Vec<WorldMesh>,
    at: usize,
) -> bool {
    if mesh.triangles.is_empty() && mesh.solid.is_none() {
        return false;
    }
    if at == out.len() {
        out.push(WorldMesh {
            positions: Vec::with_capacity(mesh.vertices.len()),
            triangles: Vec::with_capacity(mesh.triangles.len()),
            outline: Vec::with_capacity(mesh.outline.len()),
            fill: mesh.fill,
            extrude: mesh.extrude,
            solid: mesh.solid.clone(),
            instance: 0,
        });
    }
    let w = &mut out[at];
    w.fill = mesh.fill;
    w.extrude = mesh.extrude;
    w.solid.clone_from(&mesh.solid);
    w.positions.clear();
    w.triangles.clear();
    w.outline.clear();
    let finite = |f: &[f32; 2]| f[0].is_finite() && f[1].is_finite();
    let mut all_finite = true;
    w.positions.extend(mesh.vertices.iter().map(|&q| {
        let p = map(q);
        let f = [p.x as f32, p.y as f32];
        if finite(&f) {
            f
        } else {
            all_finite = false;
            // A finite placeholder; no kept triangle or edge refers to it.
            [0.0, 0.0]
        }
    }));
    if all_finite {
        // The common case: every triangle and edge survives, so copy instead of filtering.
        // Element-wise: these lists are a few entries long, too short for a `memmove` call to pay.
        for &t in &mesh.triangles {
            w.triangles.push(t);
        }
        for &e in &mesh.outline {
            w.outline.push(e);
        }
        return true;
    }
    // A placeholder cannot be told from a real origin, so ask the map again (it is pure). A
    // mesh asset's surface would need every vertex: its footprint is all that is left of it.
    w.solid = None;
    // A placeholder cannot be told from a real origin, so ask the map again (it is pure).
    let ok = |i: u32| {
        finite(&{
            let p = map(mesh.vertices[i as usize]);
            [p.x as f32, p.y as f32]
        })
    };
    w.triangles
        .extend(mesh.triangles.iter().filter(|t| t.iter().all(|&i| ok(i))));
    w.outline
        .extend(mesh.outline.iter().filter(|e| e.iter().all(|&i| ok(i))));
    !w.triangles.is_empty()
}

/// The current outward direction of a site of an instance in rest state `state`: the site's
/// `out` (base-state coordinates) carried into the rest state by the site's own local frame,
/// then turned by the instance's best rigid motion from that rest state. A site of two or more
/// vertices turns with its first-to-last span, so the east end of a road bent a quarter turn
/// (`state left bend 90`) points north, not halfway; a one-vertex site turns with the piece.
/// An unknown state counts as the base state.
///
/// This is the direction drawn (arrows on the sheet and on the model), steady while a part
/// deforms; the merge rule reads [`crate::site_out`], the fit of the site's own vertices,
/// which follows a site through a part's deformation.
pub fn drawn_site_out(
    grammar: &CompiledGrammar,
    piece: usize,
    state: usize,
    site: usize,
    current: &[DVec2],
) -> Option<DVec2> {
    let p = grammar.pieces.get(piece)?;
    let s = p.sites.get(site)?;
    let base = &p.states.first()?.positions;
    let rest = p.states.get(state).map_or(base, |st| &st.positions);
    let mut out = s.out;
    if let (Some(&a), Some(&b)) = (s.vertices.first(), s.vertices.last())
        && state != 0
        && a != b
    {
        let span = |pos: &[DVec2]| Some(pos.get(b)? - pos.get(a)?).and_then(DVec2::try_normalize);
        if let (Some(from), Some(to)) = (span(base), span(rest)) {
            // The turn taking the base span onto the rest span, as a unit complex number.
            out = DVec2::new(to.dot(from), from.perp_dot(to)).rotate(out);
        }
    }
    let motion = rigid_motion(rest, current)?;
    motion.apply_direction(out).try_normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn site_out_arrows_turn_with_the_bent_ends() {
        // In `left` the east end faces north and the west end still faces west; in `right` the
        // east end faces south. The arrows follow each site's own frame, not the piece's average
        // turn (which is 45 degrees).
        let dir = env!("CARGO_MANIFEST_DIR");
        // (The drawn arrow is render's own; moved here from tests/derived_states.rs when the
        // render module became private.)
        let src = std::fs::read_to_string(format!("{dir}/grammars/bend.clay")).unwrap();
        let g = clay_dsl::compile(&src, "bend.clay", &clay_dsl::CompileOptions::default())
            .unwrap()
            .grammar;
        let road = &g.pieces[0];
        let site = |name: &str| road.sites.iter().position(|s| s.name == name).unwrap();
        let state = |name: &str| road.states.iter().position(|s| s.name == name).unwrap();
        for (st, s, expected) in [
            ("left", "east", glam::DVec2::Y),
            ("left", "west", glam::DVec2::NEG_X),
            ("right", "east", glam::DVec2::NEG_Y),
            ("base", "east", glam::DVec2::X),
        ] {
            let rest = &road.states[state(st)].positions;
            let out = drawn_site_out(&g, 0, state(st), site(s), rest).unwrap();
            assert!(out.distance(expected) < 1e-9, "{st}.{s}: {out}");
        }
    }

    /// The straightforward posing the fast path replaced, kept as the reference it must match
    /// exactly: per vertex an `Option`, per mesh a filtered triangle and edge list.
    mod reference {
        use super::super::*;

        pub fn pose_assembly(
            grammar: &CompiledGrammar,
            assembly: &AssemblyData,
            cache: &mut TessellationCache,
        ) -> Vec<WorldMesh> {
            (0..assembly.instances.len())
                .flat_map(|i| pose_instance(grammar, assembly, i, cache))
                .collect()
        }

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
                skin_new(
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
                        (_, _, Some(r)) => Some(r.apply(q)),
                        _ => None,
                    };
                    world_mesh(mesh, map)
                })
                .collect()
        }

        /// Builds the skin from rest and current positions of the piece's vertices; `None` when the
        /// sites are empty, out of range, coincide, or positions are not finite.
        pub fn skin_new(
            rest: &[DVec2],
            current: &[DVec2],
            from_site: &[usize],
            to_site: &[usize],
        ) -> Option<Skin> {
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
            let skin = Skin {
                from: frame(from_site, r0, c0),
                to: frame(to_site, r1, c1),
            };
            let finite = |f: &SiteFrame| {
                f.tangent.is_finite() && f.rest_tangent.is_finite() && f.stretch.is_finite()
            };
            (finite(&skin.from) && finite(&skin.to)).then_some(skin)
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
            let positions = mapped
                .into_iter()
                .map(|p| p.unwrap_or([0.0, 0.0]))
                .collect();
            Some(WorldMesh {
                positions,
                triangles,
                outline,
                fill: mesh.fill,
                extrude: mesh.extrude,
                solid: mesh.solid.clone(),
                instance: 0,
            })
        }
    }

    fn grammar(name: &str) -> CompiledGrammar {
        let path = format!("{}/grammars/{name}", env!("CARGO_MANIFEST_DIR"));
        let source = std::fs::read_to_string(&path).unwrap();
        match clay_dsl::compile(&source, &path, &clay_dsl::CompileOptions::default()) {
            Ok(c) => c.grammar,
            Err(d) => panic!("{}", clay_dsl::render(&d, &source, &path, false)),
        }
    }

    /// Moves every vertex by a different small amount and swings the east half of the model
    /// round, so walls stretch, bend and turn and every rigid motion is a real rotation.
    fn sculpted(assembly: &AssemblyData) -> AssemblyData {
        let mut a = assembly.clone();
        for (i, p) in a.positions.iter_mut().enumerate() {
            let k = i as f64;
            *p += DVec2::new(0.05 * (k * 0.37).sin(), 0.05 * (k * 0.91).cos());
            if p.x > 0.0 {
                *p = DVec2::from_angle(0.3).rotate(*p) * 1.2;
            }
        }
        a
    }

    /// Compares the fast posing with the reference: the fresh `Vec`, the per-instance and
    /// per-piece entry points, and `pose_assembly_into` over a `Vec` already holding other
    /// meshes (more than needed, so reuse and truncation are both exercised).
    fn assert_matches_reference(g: &CompiledGrammar, a: &AssemblyData, stale: &[WorldMesh]) {
        let mut cache = TessellationCache::new();
        let expected = reference::pose_assembly(g, a, &mut cache);
        assert!(!expected.is_empty());
        assert_eq!(pose_assembly(g, a, &mut cache), expected);
        let mut out = stale.to_vec();
        out.extend_from_slice(stale);
        pose_assembly_into(g, a, &mut TessellationCache::new(), &mut out);
        assert_eq!(out, expected);
        for i in 0..a.instances.len() + 1 {
            assert_eq!(
                pose_instance(g, a, i, &mut cache),
                reference::pose_instance(g, a, i, &mut cache)
            );
        }
        for (pi, piece) in g.pieces.iter().enumerate() {
            for (si, state) in piece.states.iter().enumerate() {
                let moved: Vec<DVec2> = state.positions.iter().map(|p| *p * 1.1).collect();
                assert_eq!(
                    pose_piece(g, pi, si, &moved, &mut cache),
                    reference::pose_piece(g, pi, si, &moved, &mut cache)
                );
            }
        }
    }

    #[test]
    fn fast_posing_matches_the_reference_on_a_sculpted_castle() {
        let g = grammar("castle.clay");
        let stale = pose_assembly(&g, &g.assembly, &mut TessellationCache::new());
        let a = sculpted(&g.assembly);
        assert_ne!(pose_assembly(&g, &a, &mut TessellationCache::new()), stale);
        assert_matches_reference(&g, &a, &stale);
        // Streets switch rest states, so several (piece, state) geometries are shown.
        let streets = grammar("streets.clay");
        assert_matches_reference(&streets, &sculpted(&streets.assembly), &stale);
    }

    #[test]
    fn skin_from_its_rest_half_matches_the_reference() {
        let rest = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 0.5),
            DVec2::new(0.0, 0.5),
            DVec2::new(0.5, 0.25),
        ];
        let now = [
            DVec2::new(0.1, -0.2),
            DVec2::new(1.5, 0.1),
            DVec2::new(1.4, 0.7),
            DVec2::new(0.0, 0.5),
            DVec2::new(0.7, 0.3),
        ];
        let sites: [(&[usize], &[usize]); 6] = [
            (&[3, 0], &[1, 2]),
            // One-vertex sites turn with the axis.
            (&[4], &[1, 2]),
            (&[3, 0], &[4]),
            // Coinciding sites, an empty site and an out-of-range vertex give no skin.
            (&[3, 0], &[0, 3]),
            (&[], &[1, 2]),
            (&[3, 9], &[1, 2]),
        ];
        for (from, to) in sites {
            assert_eq!(
                Skin::new(&rest, &now, from, to),
                reference::skin_new(&rest, &now, from, to),
                "{from:?} {to:?}"
            );
        }
        let flat = [DVec2::new(f64::NAN, 0.0); 5];
        assert_eq!(Skin::new(&rest, &flat, &[3, 0], &[1, 2]), None);
    }

    #[test]
    fn fast_posing_matches_the_reference_with_broken_vertices() {
        let g = grammar("castle.clay");
        let mut a = sculpted(&g.assembly);
        // Non-finite and f32-overflowing positions drop only the triangles that touch them;
        // an out-of-range vertex index hides its instance.
        let last = a.instances.len() - 1;
        a.positions[a.instances[0].vertices[0]] = DVec2::new(f64::NAN, 0.0);
        a.positions[a.instances[1].vertices[1]] = DVec2::new(1e39, 0.0);
        a.instances[last].vertices[0] = a.positions.len();
        let stale = pose_assembly(&g, &g.assembly, &mut TessellationCache::new());
        assert_matches_reference(&g, &a, &stale);
    }

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
