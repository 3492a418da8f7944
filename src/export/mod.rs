//! The sculpted model as 3D meshes, for engines and DCC tools (`clayc export`, the editor's
//! Export). Paper 6: "the computed deformation only affects two out of three coordinates (the
//! floor-plan, leaving the height unchanged)": every proxy of every instance is posed exactly
//! as the renderer poses it (`render::pose`), then extruded between its base and top heights.
//! Flat proxy geometry gets a small default thickness so nothing is invisible, each later proxy
//! of a piece a little higher than the one before (as it is drawn on top in 2D). A mesh asset
//! (`mesh "tower.glb"`) is written as its own triangles, every vertex at its posed floor-plan
//! point and the height it has in the asset.
//!
//! Data flows one way: assembly -> [`scene`] ([`Scene`]: one [`Node`] per instance, one
//! [`Primitive`] per fill colour) -> [`gltf`] (`.glb`, `.gltf`) or [`obj`] (`.obj` + `.mtl`).
//!
//! Coordinates: metres, y up (glTF's convention): the floor plan's x (east) is x and its y
//! (north) is -z, so a map seen from above keeps its orientation; heights are y.
//!
//! Architecture Invariant: the floor-plan coordinates of every exported vertex are the
//! renderer's (`pose_assembly`), so a picture and an export of the same assembly agree.

pub mod gltf;
pub mod iso;
pub mod obj;

use std::collections::HashMap;

use clay_dsl::compiled::{AssemblyData, CompiledGrammar, Instance, Rgba};
use glam::DVec3;

use crate::render::{Solid, TessellationCache, WorldMesh, pose_assembly};

/// How flat geometry is given volume.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExportOptions {
    /// Height of flat proxy geometry, in metres.
    pub thickness: f64,
    /// How much higher each later proxy of a piece is than the one before, in metres (so that
    /// lane markings lie on their road as they are drawn on it, without z-fighting).
    pub layer: f64,
}

impl Default for ExportOptions {
    fn default() -> Self {
        Self {
            thickness: 0.05,
            layer: 0.002,
        }
    }
}

/// Triangles of one colour of one instance, flat-shaded (every face has its own vertices).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Primitive {
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// Metres, y up.
    pub positions: Vec<[f32; 3]>,
    /// Unit face normals, one per position.
    pub normals: Vec<[f32; 3]>,
    /// Counter-clockwise seen from the side the normal points to.
    pub indices: Vec<u32>,
}

/// One instance.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    /// The instance's name in the assembly (`wall[3]`).
    pub name: String,
    pub piece: String,
    /// The active rest state.
    pub state: String,
    pub id: u64,
    pub primitives: Vec<Primitive>,
}

/// The exported model.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scene {
    pub nodes: Vec<Node>,
    /// One per fill colour, in order of first use.
    pub materials: Vec<Rgba>,
}

impl Scene {
    pub fn triangle_count(&self) -> usize {
        self.nodes
            .iter()
            .flat_map(|n| &n.primitives)
            .map(|p| p.indices.len() / 3)
            .sum()
    }

    /// The floor-plan bounding box (x east, y north) of every exported vertex.
    pub fn floor_bounds(&self) -> Option<([f64; 2], [f64; 2])> {
        let mut it = self
            .nodes
            .iter()
            .flat_map(|n| &n.primitives)
            .flat_map(|p| &p.positions)
            .map(|p| [p[0] as f64, -(p[2] as f64)]);
        let first = it.next()?;
        Some(it.fold((first, first), |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1])],
                [hi[0].max(p[0]), hi[1].max(p[1])],
            )
        }))
    }
}

/// The assembly as 3D meshes.
pub fn scene(grammar: &CompiledGrammar, assembly: &AssemblyData, options: &ExportOptions) -> Scene {
    let mut cache = TessellationCache::default();
    let meshes = pose_assembly(grammar, assembly, &mut cache);
    let mut scene = Scene::default();
    let mut material_of: HashMap<[u8; 4], usize> = HashMap::new();
    let mut nodes: Vec<Option<Node>> = vec![None; assembly.instances.len()];
    // The meshes come in instance order, each instance's proxies in order: the k-th mesh of an
    // instance is its k-th layer.
    let mut layer = 0usize;
    let mut last = usize::MAX;
    for mesh in &meshes {
        if mesh.instance != last {
            layer = 0;
            last = mesh.instance;
        }
        let Some(inst) = assembly.instances.get(mesh.instance) else {
            continue;
        };
        let node = nodes[mesh.instance].get_or_insert_with(|| node_of(grammar, inst));
        let material = *material_of.entry(mesh.fill.0).or_insert_with(|| {
            scene.materials.push(mesh.fill);
            scene.materials.len() - 1
        });
        let at = match node.primitives.iter().position(|p| p.material == material) {
            Some(i) => i,
            None => {
                node.primitives.push(Primitive {
                    material,
                    ..Primitive::default()
                });
                node.primitives.len() - 1
            }
        };
        let (base, top) = match mesh.extrude {
            Some(e) => (e.base, e.base + e.height),
            None => (0.0, options.thickness + options.layer * layer as f64),
        };
        match &mesh.solid {
            Some(solid) => surface(mesh, solid, &mut node.primitives[at]),
            None => extrude(mesh, base, top, &mut node.primitives[at]),
        }
        layer += 1;
    }
    // Every instance is a node, also one without geometry (an empty node keeps the names
    // and the count the assembly's).
    scene.nodes = nodes
        .into_iter()
        .zip(&assembly.instances)
        .map(|(n, inst)| n.unwrap_or_else(|| node_of(grammar, inst)))
        .collect();
    scene
}

fn node_of(grammar: &CompiledGrammar, inst: &Instance) -> Node {
    let piece = grammar.pieces.get(inst.piece);
    Node {
        name: inst.name.clone(),
        piece: piece.map_or(String::new(), |p| p.name.clone()),
        state: piece
            .and_then(|p| p.states.get(inst.state))
            .map_or(String::new(), |s| s.name.clone()),
        id: inst.id,
        primitives: Vec::new(),
    }
}

/// The 3D point of floor-plan point `p` at height `h`.
fn lift(p: [f32; 2], h: f64) -> DVec3 {
    DVec3::new(p[0] as f64, h, -(p[1] as f64))
}

impl Primitive {
    /// Adds a triangle facing `normal` (its winding is chosen to match).
    fn triangle(&mut self, mut c: [DVec3; 3], normal: DVec3) {
        let n = (c[1] - c[0]).cross(c[2] - c[0]);
        // A degenerate (or NaN) triangle has no face to show: never write it.
        let area = n.length_squared();
        if area.is_nan() || area <= 0.0 || !c.iter().all(|p| p.is_finite()) {
            return;
        }
        if n.dot(normal) < 0.0 {
            c.swap(1, 2);
        }
        let base = self.positions.len() as u32;
        let nf = normal.normalize().as_vec3().to_array();
        for p in c {
            self.positions.push(p.as_vec3().to_array());
            self.normals.push(nf);
        }
        self.indices.extend([base, base + 1, base + 2]);
    }
}

/// The prism of a posed proxy between heights `base` and `top`: top face up, bottom face down,
/// and a wall on every boundary edge, facing out. Each face's winding is chosen from its
/// normal, so a triangle that skinning folded over still faces the right way.
fn extrude(mesh: &WorldMesh, base: f64, top: f64, out: &mut Primitive) {
    let p = &mesh.positions;
    let at = |i: u32| p.get(i as usize).copied();
    let up = DVec3::Y;
    for t in &mesh.triangles {
        let (Some(a), Some(b), Some(c)) = (at(t[0]), at(t[1]), at(t[2])) else {
            continue;
        };
        out.triangle([lift(a, top), lift(b, top), lift(c, top)], up);
        out.triangle([lift(a, base), lift(b, base), lift(c, base)], -up);
    }
    // The outline's edges are directed as in the counter-clockwise rest triangles: the inside
    // is on their left (the tessellation's boundary edges, in its order, so the bytes of an
    // export are the same every time).
    let walls = mesh.outline.iter().map(|e| (e[0], e[1]));
    for (i, j) in walls {
        let (Some(a), Some(b)) = (at(i), at(j)) else {
            continue;
        };
        // The inside is on the left of a -> b, so outward is its right: (dy, -dx) in the plan.
        let (dx, dy) = ((b[0] - a[0]) as f64, (b[1] - a[1]) as f64);
        let normal = DVec3::new(dy, 0.0, dx);
        let (a0, b0, a1, b1) = (lift(a, base), lift(b, base), lift(a, top), lift(b, top));
        out.triangle([a0, b0, b1], normal);
        out.triangle([a0, b1, a1], normal);
    }
}

/// A mesh asset's own triangles, each vertex at its posed floor-plan point and its rest height.
fn surface(mesh: &WorldMesh, solid: &Solid, out: &mut Primitive) {
    let corner = |i: u32| {
        let p = mesh.positions.get(i as usize)?;
        Some(lift(*p, *solid.heights.get(i as usize)?))
    };
    for t in &solid.triangles {
        let (Some(a), Some(b), Some(c)) = (corner(t[0]), corner(t[1]), corner(t[2])) else {
            continue;
        };
        out.triangle([a, b, c], (b - a).cross(c - a));
    }
}

/// The linear value of an sRGB channel (glTF's colour factors are linear).
pub fn srgb_to_linear(c: u8) -> f32 {
    let c = c as f32 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}
