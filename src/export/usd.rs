//! A [`Scene`] as a USD layer in its text form (`.usda`), the interchange format of film, VFX
//! and Omniverse pipelines (Blender, Houdini and Maya import it).
//!
//! The stage declares metres (`metersPerUnit = 1`) and **Z up** (`upAxis = "Z"`): USD tools
//! expect Z up for architecture, so the glTF's y-up frame is turned a quarter about x (a point
//! `(x, y, z)` of a node's glTF frame is `(x, -z, y)` here: x east, y north, z the height, the
//! floor plan as drawn). One `Xform` per instance under one root `Xform` (the default prim,
//! named as the glTF's root), placed by `xformOp:translate` at its pivot and
//! `xformOp:rotateZ` by its turn, and named as its glTF node (`wall_n_4`). Every distinct mesh
//! is written once, as a prototype under the abstract `class` prim `Prototypes`; each node has a
//! child `geometry` that references its prototype and is `instanceable`, so the wall's eight
//! bricks are one prototype. A prototype holds one `Mesh` per fill colour, bound to a
//! `UsdPreviewSurface` material under `Looks` (named as in every output, `fill_9a958cff`;
//! diffuse colour linear, as glTF's factor). The instance's assembly name, piece, rest state, id
//! and place in its stretch chain are custom attributes `userProperties:instance`, `:piece`,
//! `:state`, `:id`, `:chain` and `:index` on its `Xform`: USD's namespace for user data, which
//! Blender's importer reads as the custom properties `instance`, `piece`, ... that its glTF
//! importer gives from the glTF's extras.
//!
//! Names: prim names must be identifiers; node and mesh names are letters, digits and `_`
//! already (`names.rs`), so only one that starts with a digit (a grammar file `1st.clay`) gets
//! a leading `_`. The binary crate form (`.usdc`) is not written here: `usdcat model.usda -o
//! model.usdc` converts it, and the Python package writes it through usd-core's `pxr`.

use std::fmt::Write as _;

use super::model::{Node, Primitive, Scene, material_name, srgb_to_linear};

/// The `.usda` text of `scene`.
pub fn to_usda(scene: &Scene) -> String {
    let root = prim_name(&scene.name);
    let mut out = String::new();
    let _ = writeln!(
        out,
        "#usda 1.0\n(\n    defaultPrim = \"{root}\"\n    doc = \"clayc {} export: metres, Z up\"\n    metersPerUnit = 1\n    upAxis = \"Z\"\n)\n",
        env!("CARGO_PKG_VERSION")
    );
    let _ = writeln!(out, "def Xform \"{root}\"\n{{");
    looks(scene, &root, &mut out);
    let _ = writeln!(out, "    class Scope \"Prototypes\"\n    {{");
    for mesh in &scene.meshes {
        let node = &scene.nodes[mesh.node];
        let _ = writeln!(
            out,
            "        def Xform \"{}\"\n        {{",
            prim_name(&mesh.name)
        );
        for p in &node.primitives {
            primitive(scene, p, &root, &mut out);
        }
        let _ = writeln!(out, "        }}");
    }
    let _ = writeln!(out, "    }}");
    for node in &scene.nodes {
        instance(scene, node, &root, &mut out);
    }
    let _ = writeln!(out, "}}");
    out
}

/// A prim name for a node, mesh or root name (letters, digits and `_`): as it is, with a
/// leading `_` when it starts with a digit.
fn prim_name(name: &str) -> String {
    if name.starts_with(|c: char| c.is_ascii_digit()) || name.is_empty() {
        format!("_{name}")
    } else {
        name.to_string()
    }
}

/// A USD string literal.
fn quoted(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The materials: one `UsdPreviewSurface` per fill colour.
fn looks(scene: &Scene, root: &str, out: &mut String) {
    let _ = writeln!(out, "    def Scope \"Looks\"\n    {{");
    for &c in &scene.materials {
        let name = material_name(c);
        let [r, g, b, a] = c.0;
        let [r, g, b] = [r, g, b].map(srgb_to_linear);
        let _ = writeln!(
            out,
            "        def Material \"{name}\"\n        {{\n            token outputs:surface.connect = </{root}/Looks/{name}/Surface.outputs:surface>\n\n            def Shader \"Surface\"\n            {{\n                uniform token info:id = \"UsdPreviewSurface\"\n                color3f inputs:diffuseColor = ({r}, {g}, {b})\n                float inputs:opacity = {}\n                float inputs:roughness = 0.8\n                token outputs:surface\n            }}\n        }}",
            a as f32 / 255.0
        );
    }
    let _ = writeln!(out, "    }}");
}

/// A node's glTF-frame vector in the stage's Z-up frame.
fn z_up(v: [f32; 3]) -> [f32; 3] {
    [v[0], -v[2], v[1]]
}

fn array<const N: usize>(items: impl Iterator<Item = [f32; N]>) -> String {
    let parts: Vec<String> = items
        .map(|v| {
            let coords: Vec<String> = v.iter().map(|x| format!("{x}")).collect();
            format!("({})", coords.join(", "))
        })
        .collect();
    format!("[{}]", parts.join(", "))
}

/// One colour of a prototype: a triangle mesh with its normals, texture coordinates (`st`,
/// v up as USD has it), extent and material.
fn primitive(scene: &Scene, p: &Primitive, root: &str, out: &mut String) {
    let points: Vec<[f32; 3]> = p.positions.iter().copied().map(z_up).collect();
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for q in &points {
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    if points.is_empty() {
        (lo, hi) = ([0.0; 3], [0.0; 3]);
    }
    let counts = vec!["3"; p.indices.len() / 3].join(", ");
    let indices: Vec<String> = p.indices.iter().map(u32::to_string).collect();
    let m = material_name(scene.materials[p.material]);
    let _ = writeln!(
        out,
        "            def Mesh \"{m}\" (\n                prepend apiSchemas = [\"MaterialBindingAPI\"]\n            )\n            {{\n                uniform bool doubleSided = 0\n                float3[] extent = {}\n                int[] faceVertexCounts = [{counts}]\n                int[] faceVertexIndices = [{}]\n                rel material:binding = </{root}/Looks/{m}>\n                normal3f[] normals = {} (\n                    interpolation = \"vertex\"\n                )\n                point3f[] points = {}\n                texCoord2f[] primvars:st = {} (\n                    interpolation = \"vertex\"\n                )\n                uniform token subdivisionScheme = \"none\"\n            }}",
        array([lo, hi].into_iter()),
        indices.join(", "),
        array(p.normals.iter().copied().map(z_up)),
        array(points.into_iter()),
        array(p.uvs.iter().map(|t| [t[0], -t[1]])),
    );
}

/// One instance: its `Xform` at its pivot and turn, its extras, and its geometry.
fn instance(scene: &Scene, node: &Node, root: &str, out: &mut String) {
    // As the glTF writer: a node whose placement is not finite stands at the origin, unturned
    // (no NaN reaches a file).
    let turn = Some(node.turn.y.atan2(node.turn.x).to_degrees()).filter(|t| t.is_finite());
    let pivot = Some(node.pivot)
        .filter(|p| p.is_finite())
        .unwrap_or_default();
    let _ = writeln!(out, "\n    def Xform \"{}\"\n    {{", prim_name(&node.name));
    let _ = writeln!(
        out,
        "        custom string userProperties:instance = {}\n        custom string userProperties:piece = {}\n        custom string userProperties:state = {}\n        custom {} userProperties:id = {}",
        quoted(&node.instance),
        quoted(&node.piece),
        quoted(&node.state),
        // Blender's importer takes 32-bit integers only.
        if i32::try_from(node.id).is_ok() {
            "int"
        } else {
            "int64"
        },
        node.id
    );
    if let Some(c) = &node.chain {
        let _ = writeln!(
            out,
            "        custom string userProperties:chain = {}\n        custom int userProperties:index = {}",
            quoted(&c.name),
            c.index
        );
    }
    let _ = writeln!(
        out,
        "        double3 xformOp:translate = ({}, {}, 0)\n        double xformOp:rotateZ = {}\n        uniform token[] xformOpOrder = [\"xformOp:translate\", \"xformOp:rotateZ\"]",
        pivot.x,
        pivot.y,
        turn.unwrap_or(0.0)
    );
    if let Some(m) = node.mesh {
        let _ = writeln!(
            out,
            "\n        def Xform \"geometry\" (\n            instanceable = true\n            prepend references = </{root}/Prototypes/{}>\n        )\n        {{\n        }}",
            prim_name(&scene.meshes[m].name)
        );
    }
    let _ = writeln!(out, "    }}");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prim_names_are_identifiers_and_strings_are_escaped() {
        assert_eq!(prim_name("wall_n_4"), "wall_n_4");
        assert_eq!(prim_name("1st_floor"), "_1st_floor");
        assert_eq!(prim_name(""), "_");
        assert_eq!(quoted("wall[3]"), "\"wall[3]\"");
        assert_eq!(quoted("a\"b\\c\nd"), "\"a\\\"b\\\\c\\nd\"");
    }

    #[test]
    fn a_y_up_point_is_z_up_by_a_quarter_turn_about_x() {
        // (x, height, -north) in glTF is (x, north, height) here.
        assert_eq!(z_up([1.0, 2.0, -3.0]), [1.0, 3.0, 2.0]);
    }
}
