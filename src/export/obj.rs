//! A [`Scene`] as Wavefront OBJ with its MTL material library: one object (`o`) per instance,
//! named as its glTF node, one material per fill colour, flat normals and planar UVs in metres.
//!
//! OBJ has no nodes: every vertex is written where its node places it (so in Blender every
//! object's origin is the scene's). OBJ has no standard place for extras either: the instance's
//! assembly name, piece, rest state, id and place in its stretch chain go into a comment line
//! after the object's name. Colours are written as glTF writes them: `Kd` is the linear value
//! of the `.clay` sRGB colour (Blender reads `Kd` as linear, so both formats import as the same
//! colour). Texture coordinates are glTF's with v turned up, OBJ's convention (`vt u -v`: a
//! wall's v is its height in metres).

use std::fmt::Write as _;

use super::model::{Scene, material_name, srgb_to_linear};

/// The OBJ text (referring to the material library `mtl_name`) and the MTL text.
pub fn to_obj(scene: &Scene, mtl_name: &str) -> (String, String) {
    let mut obj = String::new();
    let _ = writeln!(
        obj,
        "# clayc {} export: metres, y up; model {}",
        env!("CARGO_PKG_VERSION"),
        scene.name
    );
    let _ = writeln!(obj, "mtllib {mtl_name}");
    // OBJ indices are global and 1-based.
    let mut next = 1usize;
    for node in &scene.nodes {
        // Node names have no whitespace (letters, digits and `_`).
        let _ = writeln!(obj, "o {}", node.name);
        let chain = node.chain.as_ref().map_or(String::new(), |c| {
            format!(" chain {} index {}", c.name, c.index)
        });
        let _ = writeln!(
            obj,
            "# instance {} piece {} state {} id {}{chain}",
            node.instance, node.piece, node.state, node.id
        );
        for p in &node.primitives {
            for &v in &p.positions {
                let w = node.to_world(v).as_vec3();
                let _ = writeln!(obj, "v {} {} {}", w.x, w.y, w.z);
            }
            for t in &p.uvs {
                let _ = writeln!(obj, "vt {} {}", t[0], -t[1]);
            }
            for &n in &p.normals {
                let d = node.direction_to_world(n).normalize_or_zero().as_vec3();
                let _ = writeln!(obj, "vn {} {} {}", d.x, d.y, d.z);
            }
            let _ = writeln!(obj, "usemtl {}", material_name(scene.materials[p.material]));
            for t in p.indices.chunks_exact(3) {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize + next);
                let _ = writeln!(obj, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}");
            }
            next += p.positions.len();
        }
    }
    let mut mtl = String::new();
    let _ = writeln!(
        mtl,
        "# clayc {} export: Kd linear, as glTF's baseColorFactor",
        env!("CARGO_PKG_VERSION")
    );
    for &c in &scene.materials {
        let [r, g, b, a] = c.0;
        let _ = writeln!(mtl, "newmtl {}", material_name(c));
        let _ = writeln!(
            mtl,
            "Kd {} {} {}",
            srgb_to_linear(r),
            srgb_to_linear(g),
            srgb_to_linear(b)
        );
        let _ = writeln!(mtl, "d {}", a as f32 / 255.0);
    }
    (obj, mtl)
}
