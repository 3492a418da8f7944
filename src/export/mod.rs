//! The sculpted model as 3D meshes, for engines and DCC tools (`clayc export`, the editor's
//! Export). Paper 6: "the computed deformation only affects two out of three coordinates (the
//! floor-plan, leaving the height unchanged)": every proxy of every instance is posed exactly
//! as the renderer poses it (`render::pose`), then extruded between its base and top heights
//! into a closed solid (`solid.rs`). Flat proxy geometry gets a small default thickness so
//! nothing is invisible, each later proxy of a piece a little higher than the one before (as it
//! is drawn on top in 2D). A mesh asset (`mesh "tower.glb"`) is written as its own triangles,
//! every vertex at its posed floor-plan point and the height it has in the asset.
//!
//! Data flows one way: assembly -> [`scene`] ([`Scene`]: a root named after the model, one
//! [`Node`] per instance at its pivot, one [`SharedMesh`] per distinct geometry, one
//! [`Primitive`] per fill colour) -> [`gltf`] (`.glb`, `.gltf`), [`obj`] (`.obj` + `.mtl`) or [`usd`] (`.usda`, Z up).
//!
//! Coordinates: metres, y up (glTF's convention): the floor plan's x (east) is x and its y
//! (north) is -z, so a map seen from above keeps its orientation; heights are y. A node stands
//! at its instance's pivot, the centroid of its vertices on the ground (y = 0), turned about y
//! by the instance's best-fit rotation from its rest state (the rigid motion the renderer poses
//! rigid proxies with); its geometry is in that local frame, so a rigid instance's mesh is its
//! rest geometry and identical instances share one mesh.
//!
//! Architecture Invariant: the floor-plan coordinates of every exported vertex, placed by its
//! node, are the renderer's (`pose_assembly`) to within f32 rounding (and the sharing tolerance,
//! [`SHARE_TOLERANCE`]), so a picture and an export of the same assembly agree.

mod file;
pub mod gltf;
pub mod iso;
mod model;
mod names;
pub mod obj;
mod solid;
pub mod usd;

use std::collections::HashMap;

use clay_dsl::compiled::{AssemblyData, CompiledGrammar, Instance, Rgba};
use glam::{DVec2, DVec3};

use crate::fit::rigid_motion;
use crate::render::tessellate::shown_geometry;
use crate::render::{Mesh, Solid, TessellationCache, WorldMesh, pose_assembly};
use solid::{Blend, Prism, Shape};

pub use file::{ExportFileError, ExportFormat, encode_export, mtl_path, write_export};
pub use model::{ChainPlace, ExportOptions, Node, Primitive, Scene, SharedMesh, material_name};
pub use names::chain_places;
// Names only the tests use, re-exported as `clay::testing::X`.
#[cfg(any(test, feature = "testing"))]
pub use {file::MAX_THICKNESS, model::srgb_to_linear, names::MAX_NAME_BYTES};

/// How far apart (metres, per coordinate) two instances' local geometry may be and still share
/// one mesh, at the origin; it grows with the distance from the origin as f32's precision
/// shrinks (by [`SHARE_TOLERANCE_PER_METRE`] per metre), since posed positions are f32.
pub const SHARE_TOLERANCE: f64 = 1e-5;
/// See [`SHARE_TOLERANCE`]: two f32 roundings at a coordinate of 1 m.
pub const SHARE_TOLERANCE_PER_METRE: f64 = 2.4e-7;

/// The assembly as 3D meshes.
pub fn scene(grammar: &CompiledGrammar, assembly: &AssemblyData, options: &ExportOptions) -> Scene {
    let mut cache = TessellationCache::default();
    let posed = pose_assembly(grammar, assembly, &mut cache);
    let chains = names::chain_places(assembly);
    let mut scene = Scene::default();
    let mut material_of: HashMap<[u8; 4], usize> = HashMap::new();
    let mut plans: HashMap<(usize, usize), Vec<Shape>> = HashMap::new();
    // The meshes already made for each (piece, state), to share.
    let mut shared: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
    let mut next = 0;
    for (i, inst) in assembly.instances.iter().enumerate() {
        // The posed meshes come in instance order.
        let start = next;
        while next < posed.len() && posed[next].instance == i {
            next += 1;
        }
        let worlds = &posed[start..next];
        let frame = frame_of(grammar, assembly, inst);
        let key = (inst.piece, inst.state);
        let tess = cache.meshes(grammar, inst.piece, inst.state);
        let plan = plans
            .entry(key)
            .or_insert_with(|| solid::plan(&tess, options));
        let mut material = |fill: Rgba| {
            *material_of.entry(fill.0).or_insert_with(|| {
                scene.materials.push(fill);
                scene.materials.len() - 1
            })
        };
        let primitives = build(plan, &tess, worlds, &frame, options, &mut material);
        let mut node = node_of(grammar, inst, &frame, chains[i].clone());
        if !primitives.is_empty() {
            let tol = share_tolerance(&frame, &primitives);
            let candidates = shared.entry(key).or_default();
            // The first shape of a piece state (usually its rest shape) and the latest ones:
            // a bounded search however many deformed copies there are.
            let found = candidates
                .first()
                .into_iter()
                .chain(candidates.iter().skip(1).rev().take(15))
                .copied()
                .find(|&m| {
                    same(
                        &scene.nodes[scene.meshes[m].node].primitives,
                        &primitives,
                        tol,
                    )
                });
            match found {
                Some(m) => {
                    node.primitives = scene.nodes[scene.meshes[m].node].primitives.clone();
                    scene.meshes[m].users += 1;
                    node.mesh = Some(m);
                }
                None => {
                    node.primitives = primitives;
                    node.mesh = Some(scene.meshes.len());
                    candidates.push(scene.meshes.len());
                    scene.meshes.push(SharedMesh {
                        name: String::new(),
                        node: scene.nodes.len(),
                        users: 1,
                    });
                }
            }
        }
        scene.nodes.push(node);
    }
    names::name_scene(&mut scene, grammar);
    scene
}

/// Where an instance's node stands and how it is turned: the best rigid motion from the rest
/// state its geometry is authored against onto its vertices now (the renderer's for rigid
/// proxies). An instance whose vertices are not all known and finite stands at the centroid of
/// those that are, unturned.
struct Frame {
    pivot: DVec2,
    turn: DVec2,
}

impl Frame {
    /// A posed floor-plan point in the node's frame.
    fn local(&self, p: [f32; 2]) -> DVec2 {
        let d = DVec2::new(p[0] as f64, p[1] as f64) - self.pivot;
        DVec2::new(self.turn.x, -self.turn.y).rotate(d)
    }
}

fn frame_of(grammar: &CompiledGrammar, assembly: &AssemblyData, inst: &Instance) -> Frame {
    let current: Vec<DVec2> = inst
        .vertices
        .iter()
        .filter_map(|&v| assembly.positions.get(v).copied())
        .collect();
    let rest = shown_geometry(grammar, inst.piece, inst.state)
        .and_then(|(_, frame)| grammar.pieces.get(inst.piece)?.states.get(frame))
        .map(|s| &s.positions);
    if let Some(rest) = rest
        && current.len() == inst.vertices.len()
        && let Some(motion) = rigid_motion(rest, &current)
    {
        return Frame {
            pivot: motion.to_centre,
            turn: motion.rotation,
        };
    }
    let finite: Vec<DVec2> = current.into_iter().filter(|p| p.is_finite()).collect();
    Frame {
        pivot: if finite.is_empty() {
            DVec2::ZERO
        } else {
            finite.iter().sum::<DVec2>() / finite.len() as f64
        },
        turn: DVec2::X,
    }
}

fn node_of(
    grammar: &CompiledGrammar,
    inst: &Instance,
    frame: &Frame,
    chain: Option<ChainPlace>,
) -> Node {
    let piece = grammar.pieces.get(inst.piece);
    Node {
        name: String::new(),
        instance: inst.name.clone(),
        piece: piece.map_or(String::new(), |p| p.name.clone()),
        state: piece
            .and_then(|p| p.states.get(inst.state))
            .map_or(String::new(), |s| s.name.clone()),
        id: inst.id,
        chain,
        pivot: frame.pivot,
        turn: frame.turn,
        mesh: None,
        primitives: Vec::new(),
    }
}

/// The primitive of `material` in `out`, added when missing.
fn primitive(out: &mut Vec<Primitive>, material: usize) -> &mut Primitive {
    let at = match out.iter().position(|p| p.material == material) {
        Some(i) => i,
        None => {
            out.push(Primitive {
                material,
                ..Primitive::default()
            });
            out.len() - 1
        }
    };
    &mut out[at]
}

/// One instance's primitives in its frame: the piece state's solids over the posed vertices,
/// or, when posing left something out (a vertex that is not finite), each posed mesh extruded
/// on its own.
fn build(
    plan: &[Shape],
    tess: &[Mesh],
    worlds: &[WorldMesh],
    frame: &Frame,
    options: &ExportOptions,
    material: &mut impl FnMut(Rgba) -> usize,
) -> Vec<Primitive> {
    let mut out = Vec::new();
    let whole = worlds.len() == tess.len()
        && worlds.iter().zip(tess).all(|(w, m)| {
            w.positions.len() == m.vertices.len()
                && w.triangles.len() == m.triangles.len()
                && w.solid.is_some() == m.solid.is_some()
        });
    let local: Vec<Vec<DVec2>> = worlds
        .iter()
        .map(|w| w.positions.iter().map(|&p| frame.local(p)).collect())
        .collect();
    if whole {
        for shape in plan {
            match shape {
                Shape::Prism(p) => {
                    let at = |b: &Blend| {
                        b.0.iter()
                            .filter(|t| t.2 != 0.0)
                            .map(|&(m, v, w)| local[m as usize][v as usize] * w)
                            .sum::<DVec2>()
                    };
                    prism(p, at, primitive(&mut out, material(p.fill)));
                }
                Shape::Surface(k) => {
                    if let Some(solid) = &worlds[*k].solid {
                        let prim = primitive(&mut out, material(worlds[*k].fill));
                        surface(&local[*k], solid, prim);
                    }
                }
            }
        }
    } else {
        for (k, (w, local)) in worlds.iter().zip(&local).enumerate() {
            let prim = primitive(&mut out, material(w.fill));
            match &w.solid {
                Some(solid) => surface(local, solid, prim),
                None => {
                    let (base, top) = solid::heights(w.extrude, k, options);
                    extrude(w, local, base, top, prim);
                }
            }
        }
    }
    out.retain(|p| !p.indices.is_empty());
    out
}

/// The tolerance two instances' local geometry is compared with to share a mesh.
fn share_tolerance(frame: &Frame, primitives: &[Primitive]) -> f32 {
    let reach = primitives
        .iter()
        .flat_map(|p| &p.positions)
        .flatten()
        .fold(0f32, |m, &c| m.max(c.abs())) as f64;
    let extent = frame.pivot.abs().max_element() + reach;
    (SHARE_TOLERANCE + SHARE_TOLERANCE_PER_METRE * extent) as f32
}

/// Whether two instances' primitives are the same mesh: the same materials and triangles,
/// every position within `tol` and every normal nearly the same.
fn same(a: &[Primitive], b: &[Primitive], tol: f32) -> bool {
    let near = |x: &[[f32; 3]], y: &[[f32; 3]], tol: f32| {
        x.len() == y.len()
            && x.iter()
                .zip(y)
                .all(|(p, q)| (0..3).all(|k| (p[k] - q[k]).abs() <= tol))
    };
    a.len() == b.len()
        && a.iter().zip(b).all(|(p, q)| {
            p.material == q.material
                && p.indices == q.indices
                && near(&p.positions, &q.positions, tol)
                && near(&p.normals, &q.normals, 1e-4)
        })
}

/// The 3D point of floor-plan point `p` at height `h`, as written.
fn lift(p: DVec2, h: f64) -> [f32; 3] {
    [p.x as f32, h as f32, -p.y as f32]
}

fn to_f64(p: [f32; 3]) -> DVec3 {
    DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
}

/// The unit normal of a triangle as written (counter-clockwise around it); `None` when it has
/// no area or a corner is not finite.
fn face_normal(c: [[f32; 3]; 3]) -> Option<DVec3> {
    let [a, b, c] = c.map(to_f64);
    let n = (b - a).cross(c - a);
    let len = n.length();
    (len.is_finite() && len > 0.0 && a.is_finite() && b.is_finite() && c.is_finite())
        .then(|| n / len)
}

/// Planar texture coordinates in metres of point `p` on a face with unit normal `n`.
fn uv(p: [f32; 3], n: DVec3) -> [f32; 2] {
    if n.y.abs() >= n.x.hypot(n.z) {
        [p[0], p[2]]
    } else {
        // Along the face: the horizontal direction to the right seen from outside.
        let right = DVec2::new(n.z, -n.x).normalize();
        [
            (p[0] as f64 * right.x + p[2] as f64 * right.y) as f32,
            -p[1],
        ]
    }
}

impl Primitive {
    fn vertex(&mut self, p: [f32; 3], n: DVec3) -> u32 {
        self.positions.push(p);
        self.normals.push(n.as_vec3().to_array());
        self.uvs.push(uv(p, n));
        (self.positions.len() - 1) as u32
    }

    /// A triangle of its own vertices in the given winding, facing its geometric normal.
    fn face(&mut self, c: [[f32; 3]; 3]) {
        if let Some(n) = face_normal(c) {
            let i = c.map(|p| self.vertex(p, n));
            self.indices.extend(i);
        }
    }

    /// A triangle of its own vertices facing `normal` (its winding is chosen to match).
    fn triangle(&mut self, mut c: [[f32; 3]; 3], normal: DVec3) {
        let Some(n) = face_normal(c) else {
            return;
        };
        if n.dot(normal) < 0.0 {
            c.swap(1, 2);
        }
        self.face(c);
    }
}

/// A prism over its cap vertices now at `at` (the node's frame): the cap on top and below, a
/// wall on every outline edge. The winding is the rest state's, so the faces of the solid wind
/// consistently; each face's normal is its geometric one (a triangle that skinning folded over
/// faces down on top, as the fold is).
fn prism(p: &Prism, at: impl Fn(&Blend) -> DVec2, out: &mut Primitive) {
    let q: Vec<DVec2> = p.vertices.iter().map(at).collect();
    for (h, up) in [(p.top, 1.0), (p.base, -1.0)] {
        // The cap's vertices, shared by its triangles that face the cap's way.
        let mut shared = vec![u32::MAX; q.len()];
        let normal = DVec3::new(0.0, up, 0.0);
        for t in &p.triangles {
            let t = if up > 0.0 { *t } else { [t[0], t[2], t[1]] };
            let c = t.map(|v| lift(q[v as usize], h));
            match face_normal(c) {
                Some(n) if n.y * up > 0.0 => {
                    for (&v, p) in t.iter().zip(c) {
                        let s = &mut shared[v as usize];
                        if *s == u32::MAX {
                            *s = out.vertex(p, normal);
                        }
                        out.indices.push(*s);
                    }
                }
                Some(_) => out.face(c),
                None => {}
            }
        }
    }
    for &[i, j] in &p.walls {
        let (qi, qj) = (q[i as usize], q[j as usize]);
        let c = [
            lift(qi, p.base),
            lift(qj, p.base),
            lift(qj, p.top),
            lift(qi, p.top),
        ];
        // Outward: the edge's right in the plan, from the positions as written.
        let e = to_f64(c[1]) - to_f64(c[0]);
        let n = DVec3::new(-e.z, 0.0, e.x);
        let len = n.length();
        if !(len.is_finite() && len > 0.0 && p.top > p.base) {
            continue;
        }
        let k = c.map(|v| out.vertex(v, n / len));
        out.indices.extend([k[0], k[1], k[2], k[0], k[2], k[3]]);
    }
}

/// A mesh asset's own triangles, each vertex at its posed point (`local`, the node's frame) and
/// its rest height.
fn surface(local: &[DVec2], solid: &Solid, out: &mut Primitive) {
    let corner = |i: u32| {
        Some(lift(
            *local.get(i as usize)?,
            *solid.heights.get(i as usize)?,
        ))
    };
    for t in &solid.triangles {
        let (Some(a), Some(b), Some(c)) = (corner(t[0]), corner(t[1]), corner(t[2])) else {
            continue;
        };
        out.face([a, b, c]);
    }
}

/// The prism of one posed mesh on its own, between heights `base` and `top`, for an instance
/// whose posing left something out: top face up, bottom face down, and a wall on every
/// boundary edge that is left, facing out.
fn extrude(mesh: &WorldMesh, local: &[DVec2], base: f64, top: f64, out: &mut Primitive) {
    let at = |i: u32| local.get(i as usize).copied();
    for t in &mesh.triangles {
        let (Some(a), Some(b), Some(c)) = (at(t[0]), at(t[1]), at(t[2])) else {
            continue;
        };
        out.triangle([lift(a, top), lift(b, top), lift(c, top)], DVec3::Y);
        out.triangle([lift(a, base), lift(b, base), lift(c, base)], -DVec3::Y);
    }
    for e in &mesh.outline {
        let (Some(a), Some(b)) = (at(e[0]), at(e[1])) else {
            continue;
        };
        // The inside is on the left of a -> b, so outward is its right: (dy, -dx) in the plan.
        let d = b - a;
        let normal = DVec3::new(d.y, 0.0, d.x);
        let (a0, b0, a1, b1) = (lift(a, base), lift(b, base), lift(a, top), lift(b, top));
        out.triangle([a0, b0, b1], normal);
        out.triangle([a0, b1, a1], normal);
    }
}
