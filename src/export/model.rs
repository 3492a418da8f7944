//! The exported model as data, and the options it is built with: a [`Scene`] (the root), one [`Node`] per instance at its
//! pivot, one [`SharedMesh`] per distinct geometry, one [`Primitive`] per fill colour. Built
//! by [`scene`](super::scene), named by `names.rs`, written by the glTF and OBJ writers.

use clay_dsl::compiled::Rgba;
use glam::{DVec2, DVec3};

/// How flat geometry is given volume.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExportOptions {
    /// Height of flat proxy geometry, in metres.
    pub thickness: f64,
    /// How much higher each later proxy of a piece is than the one before, its bottom and its
    /// top, in metres (so that lane markings lie on their road as they are drawn on it, without
    /// a face in the plane of the road's).
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

/// Triangles of one colour of one instance, flat-shaded (a vertex per face corner, shared by
/// the triangles of one planar face), in the node's frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Primitive {
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// Metres, y up, in the node's frame.
    pub positions: Vec<[f32; 3]>,
    /// Unit face normals, one per position.
    pub normals: Vec<[f32; 3]>,
    /// Planar texture coordinates in metres, one per position (glTF's convention: v grows
    /// downwards in the picture): a face that looks up or down is mapped from above, `(x, z)`,
    /// any other face along itself, u to the right seen from outside and v down its height.
    pub uvs: Vec<[f32; 2]>,
    /// Counter-clockwise seen from the side the normal points to.
    pub indices: Vec<u32>,
}

/// An instance's place in its stretch chain.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ChainPlace {
    /// The chain's model name (`wall_n`), unique among the chains.
    pub name: String,
    /// The element's index in chain order, 0 at the chain's `from` end.
    pub index: usize,
}

/// One instance.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    /// Unique in the scene (the root's name included) and unchanged by importers' sanitising:
    /// letters, digits and `_` (`wall_n_4`, `t_ne`, `gate_0`; docs/export.md).
    pub name: String,
    /// The instance's name in the assembly (`wall[3]`, `wall#17`).
    pub instance: String,
    pub piece: String,
    /// The active rest state.
    pub state: String,
    pub id: u64,
    /// The stretch chain the instance is an element of, if any.
    pub chain: Option<ChainPlace>,
    /// The floor-plan point (x east, y north) the node stands at: the centroid of the
    /// instance's vertices.
    pub pivot: DVec2,
    /// The node's turn about the vertical, counter-clockwise seen from above, as a unit complex
    /// number `(cos, sin)`.
    pub turn: DVec2,
    /// Index into [`Scene::meshes`]; `None` for an instance without geometry.
    pub mesh: Option<usize>,
    /// The mesh's primitives in the node's frame (every node of a shared mesh holds the same).
    pub primitives: Vec<Primitive>,
}

impl Node {
    /// The glTF translation: the pivot on the ground, y up.
    pub fn translation(&self) -> [f64; 3] {
        [self.pivot.x, 0.0, -self.pivot.y]
    }

    /// The glTF rotation, a unit quaternion `[x, y, z, w]` about y.
    pub fn rotation(&self) -> [f64; 4] {
        let half = self.turn.y.atan2(self.turn.x) / 2.0;
        [0.0, half.sin(), 0.0, half.cos()]
    }

    /// A point of the node's frame in the scene.
    pub fn to_world(&self, p: [f32; 3]) -> DVec3 {
        let q = self.pivot + self.turn.rotate(DVec2::new(p[0] as f64, -(p[2] as f64)));
        DVec3::new(q.x, p[1] as f64, -q.y)
    }

    /// A direction of the node's frame in the scene.
    pub fn direction_to_world(&self, d: [f32; 3]) -> DVec3 {
        let q = self.turn.rotate(DVec2::new(d[0] as f64, -(d[2] as f64)));
        DVec3::new(q.x, d[1] as f64, -q.y)
    }
}

/// The name of the material of fill colour `c` in every output (glTF, OBJ, USD, the Blender
/// add-on): `fill_` and its sRGB bytes in hex, `fill_9a958cff`. One colour, one material, so
/// the name is unique in a scene and the same in every file of the same grammar; letters,
/// digits and `_`, so OBJ and USD take it as it is.
pub fn material_name(c: Rgba) -> String {
    let [r, g, b, a] = c.0;
    format!("fill_{r:02x}{g:02x}{b:02x}{a:02x}")
}

/// One mesh of the file, written once and placed by every node that refers to it.
#[derive(Clone, Debug, PartialEq)]
pub struct SharedMesh {
    /// `piece__state`, then `piece__state__2` for another shape of the same piece and state.
    pub name: String,
    /// The first node that uses it; its [`Node::primitives`] are the mesh.
    pub node: usize,
    /// How many nodes use it.
    pub users: usize,
}

/// The exported model.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scene {
    /// The root node's name: the grammar's file name without its extension (`castle`).
    pub name: String,
    /// One per instance, in the assembly's order: the root's children.
    pub nodes: Vec<Node>,
    pub meshes: Vec<SharedMesh>,
    /// One per fill colour, in order of first use.
    pub materials: Vec<Rgba>,
}

impl Scene {
    /// Triangles drawn: every node's, a shared mesh counted once per node.
    pub fn triangle_count(&self) -> usize {
        self.nodes
            .iter()
            .flat_map(|n| &n.primitives)
            .map(|p| p.indices.len() / 3)
            .sum()
    }

    /// Triangles written to a glTF file: every mesh's once.
    pub fn mesh_triangle_count(&self) -> usize {
        self.meshes
            .iter()
            .flat_map(|m| &self.nodes[m.node].primitives)
            .map(|p| p.indices.len() / 3)
            .sum()
    }

    /// The floor-plan bounding box (x east, y north) of every exported vertex, placed by its
    /// node.
    pub fn floor_bounds(&self) -> Option<([f64; 2], [f64; 2])> {
        let mut it = self.nodes.iter().flat_map(|n| {
            n.primitives
                .iter()
                .flat_map(|p| &p.positions)
                .map(|&p| n.to_world(p))
                .map(|w| [w.x, -w.z])
        });
        let first = it.next()?;
        Some(it.fold((first, first), |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1])],
                [hi[0].max(p[0]), hi[1].max(p[1])],
            )
        }))
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
