//! A [`Scene`] as glTF 2.0: the document through the `gltf` crate's JSON types, the binary
//! data in one buffer, written as `.glb` (one binary container) or `.gltf` (JSON with the
//! buffer embedded as a base64 data URI, so the file stands alone).
//!
//! One root node named after the model, whose children are the instances' nodes, each at its
//! pivot and turned as its instance (translation and rotation), named uniquely in a form
//! importers keep, with its assembly name, piece, rest state, id and place in its stretch chain
//! as extras. Nodes of identical instances share one mesh; a mesh has one primitive per
//! material, with positions, normals and planar UVs in metres (`TEXCOORD_0`). One material per
//! fill colour (its sRGB colour as a linear base colour factor; blended when not opaque).

use std::borrow::Cow;
use std::collections::BTreeMap;

use base64::Engine as _;
use gltf::json::{self, validation::Checked::Valid, validation::USize64};

use super::model::{Scene, material_name, srgb_to_linear};

/// The binary data and the accessors into it, as they are appended.
struct Buffers {
    bytes: Vec<u8>,
    root: json::Root,
}

impl Buffers {
    fn view(
        &mut self,
        data: &[u8],
        target: json::buffer::Target,
    ) -> json::Index<json::buffer::View> {
        // Every accessor here holds 4-byte components: keep views 4-byte aligned.
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        let offset = self.bytes.len();
        self.bytes.extend_from_slice(data);
        self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64::from(data.len()),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: Some(Valid(target)),
            extensions: None,
            extras: Default::default(),
        })
    }

    fn vec2(&mut self, values: &[[f32; 2]]) -> json::Index<json::Accessor> {
        let data: Vec<u8> = values
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let view = self.view(&data, json::buffer::Target::ArrayBuffer);
        self.accessor(
            view,
            values.len(),
            json::accessor::ComponentType::F32,
            json::accessor::Type::Vec2,
            None,
            None,
        )
    }

    fn vec3(&mut self, values: &[[f32; 3]], bounds: bool) -> json::Index<json::Accessor> {
        let data: Vec<u8> = values
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let view = self.view(&data, json::buffer::Target::ArrayBuffer);
        let (min, max) = if bounds {
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for v in values {
                for k in 0..3 {
                    lo[k] = lo[k].min(v[k]);
                    hi[k] = hi[k].max(v[k]);
                }
            }
            (
                Some(json::Value::from(lo.to_vec())),
                Some(json::Value::from(hi.to_vec())),
            )
        } else {
            (None, None)
        };
        self.accessor(
            view,
            values.len(),
            json::accessor::ComponentType::F32,
            json::accessor::Type::Vec3,
            min,
            max,
        )
    }

    fn indices(&mut self, values: &[u32]) -> json::Index<json::Accessor> {
        let data: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&data, json::buffer::Target::ElementArrayBuffer);
        self.accessor(
            view,
            values.len(),
            json::accessor::ComponentType::U32,
            json::accessor::Type::Scalar,
            None,
            None,
        )
    }

    fn accessor(
        &mut self,
        view: json::Index<json::buffer::View>,
        count: usize,
        component: json::accessor::ComponentType,
        kind: json::accessor::Type,
        min: Option<json::Value>,
        max: Option<json::Value>,
    ) -> json::Index<json::Accessor> {
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(count),
            component_type: Valid(json::accessor::GenericComponentType(component)),
            extensions: None,
            extras: Default::default(),
            type_: Valid(kind),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
        })
    }
}

fn extras(value: serde_json::Value) -> json::Extras {
    serde_json::value::to_raw_value(&value).ok()
}

/// The glTF document of the scene and its binary buffer (without a buffer URI yet).
fn document(scene: &Scene) -> (json::Root, Vec<u8>) {
    let mut b = Buffers {
        bytes: Vec::new(),
        root: json::Root {
            asset: json::Asset {
                generator: Some(format!("clayc {}", env!("CARGO_PKG_VERSION"))),
                ..Default::default()
            },
            ..Default::default()
        },
    };
    push_materials(&mut b, scene);
    let meshes = push_meshes(&mut b, scene);
    let children = push_nodes(&mut b, scene, &meshes);
    let root = b.root.push(json::Node {
        name: Some(scene.name.clone()),
        children: (!children.is_empty()).then_some(children),
        ..Default::default()
    });
    let scene_index = b.root.push(json::Scene {
        extensions: None,
        extras: Default::default(),
        name: Some(scene.name.clone()),
        nodes: vec![root],
    });
    b.root.scene = Some(scene_index);
    while !b.bytes.len().is_multiple_of(4) {
        b.bytes.push(0);
    }
    (b.root, b.bytes)
}

/// A material per fill colour: its linear base colour, blended when not opaque.
fn push_materials(b: &mut Buffers, scene: &Scene) {
    for c in &scene.materials {
        let [r, g, bl, a] = c.0;
        b.root.push(json::Material {
            name: Some(material_name(*c)),
            alpha_mode: Valid(if a == 255 {
                json::material::AlphaMode::Opaque
            } else {
                json::material::AlphaMode::Blend
            }),
            pbr_metallic_roughness: json::material::PbrMetallicRoughness {
                base_color_factor: json::material::PbrBaseColorFactor([
                    srgb_to_linear(r),
                    srgb_to_linear(g),
                    srgb_to_linear(bl),
                    a as f32 / 255.0,
                ]),
                metallic_factor: json::material::StrengthFactor(0.0),
                roughness_factor: json::material::StrengthFactor(0.9),
                ..Default::default()
            },
            ..Default::default()
        });
    }
}

/// The scene's meshes, their accessors written into the buffer; `None` for a mesh without
/// triangles (or whose node is missing).
fn push_meshes(b: &mut Buffers, scene: &Scene) -> Vec<Option<json::Index<json::Mesh>>> {
    // Each mesh once, where its first node is.
    let mut meshes = Vec::with_capacity(scene.meshes.len());
    for mesh in &scene.meshes {
        let Some(node) = scene.nodes.get(mesh.node) else {
            meshes.push(None);
            continue;
        };
        let mut primitives = Vec::new();
        for p in node.primitives.iter().filter(|p| !p.indices.is_empty()) {
            let position = b.vec3(&p.positions, true);
            let normal = b.vec3(&p.normals, false);
            let uv = b.vec2(&p.uvs);
            let indices = b.indices(&p.indices);
            let mut attributes = BTreeMap::new();
            attributes.insert(Valid(json::mesh::Semantic::Positions), position);
            attributes.insert(Valid(json::mesh::Semantic::Normals), normal);
            attributes.insert(Valid(json::mesh::Semantic::TexCoords(0)), uv);
            primitives.push(json::mesh::Primitive {
                attributes,
                extensions: None,
                extras: Default::default(),
                indices: Some(indices),
                material: Some(json::Index::new(p.material as u32)),
                mode: Valid(json::mesh::Mode::Triangles),
                targets: None,
            });
        }
        meshes.push((!primitives.is_empty()).then(|| {
            b.root.push(json::Mesh {
                extensions: None,
                extras: Default::default(),
                name: Some(mesh.name.clone()),
                primitives,
                weights: None,
            })
        }));
    }
    meshes
}

/// A node per instance at its pivot, turned as it is, with its mesh and its extras.
fn push_nodes(
    b: &mut Buffers,
    scene: &Scene,
    meshes: &[Option<json::Index<json::Mesh>>],
) -> Vec<json::Index<json::Node>> {
    let mut children = Vec::with_capacity(scene.nodes.len());
    for node in &scene.nodes {
        let mut extra = serde_json::json!({
            "instance": node.instance,
            "piece": node.piece,
            "state": node.state,
            "id": node.id,
        });
        if let Some(c) = &node.chain {
            extra["chain"] = c.name.clone().into();
            extra["index"] = c.index.into();
        }
        let [x, y, z] = node.translation();
        let translation = [x as f32, y as f32, z as f32];
        let [qx, qy, qz, qw] = node.rotation();
        let rotation = [qx as f32, qy as f32, qz as f32, qw as f32];
        let finite = translation.iter().chain(&rotation).all(|v| v.is_finite());
        children.push(
            b.root.push(json::Node {
                mesh: node.mesh.and_then(|m| meshes.get(m).copied().flatten()),
                name: Some(node.name.clone()),
                extras: extras(extra),
                translation: (finite && translation != [0.0; 3]).then_some(translation),
                rotation: (finite && rotation != [0.0, 0.0, 0.0, 1.0])
                    .then_some(json::scene::UnitQuaternion(rotation)),
                ..Default::default()
            }),
        );
    }
    children
}

fn buffer(len: usize, uri: Option<String>) -> json::Buffer {
    json::Buffer {
        byte_length: USize64::from(len),
        name: None,
        uri,
        extensions: None,
        extras: Default::default(),
    }
}

/// The scene as a binary `.glb` file.
pub fn to_glb(scene: &Scene) -> Result<Vec<u8>, String> {
    let (mut root, bin) = document(scene);
    if !bin.is_empty() {
        root.push(buffer(bin.len(), None));
    }
    let json = root.to_vec().map_err(|e| e.to_string())?;
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            // `to_vec` writes the real length.
            length: 0,
        },
        json: Cow::Owned(json),
        bin: (!bin.is_empty()).then_some(Cow::Owned(bin)),
    };
    glb.to_vec().map_err(|e| e.to_string())
}

/// The scene as a self-contained `.gltf` (JSON, buffer embedded as a data URI).
pub fn to_gltf(scene: &Scene) -> Result<Vec<u8>, String> {
    let (mut root, bin) = document(scene);
    if !bin.is_empty() {
        let uri = format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&bin)
        );
        root.push(buffer(bin.len(), Some(uri)));
    }
    root.to_vec_pretty().map_err(|e| e.to_string())
}
