//! A [`Scene`] as Wavefront OBJ with its MTL material library: one object (`o`) per instance,
//! one material per fill colour, flat normals. OBJ has no standard place for extras: the piece,
//! rest state and id go into a comment line after the object's name, so names stay the
//! assembly's.

use std::fmt::Write as _;

use super::Scene;

/// The OBJ text (referring to the material library `mtl_name`) and the MTL text.
pub fn to_obj(scene: &Scene, mtl_name: &str) -> (String, String) {
    let mut obj = String::new();
    let _ = writeln!(
        obj,
        "# clayc {} export: metres, y up",
        env!("CARGO_PKG_VERSION")
    );
    let _ = writeln!(obj, "mtllib {mtl_name}");
    // OBJ indices are global and 1-based.
    let mut next = 1usize;
    for node in &scene.nodes {
        // Whitespace would end the name; assembly names have none, generated ones neither.
        let name: String = node
            .name
            .chars()
            .map(|c| if c.is_whitespace() { '_' } else { c })
            .collect();
        let _ = writeln!(obj, "o {name}");
        let _ = writeln!(
            obj,
            "# piece {} state {} id {}",
            node.piece, node.state, node.id
        );
        for p in &node.primitives {
            for v in &p.positions {
                let _ = writeln!(obj, "v {} {} {}", v[0], v[1], v[2]);
            }
            for n in &p.normals {
                let _ = writeln!(obj, "vn {} {} {}", n[0], n[1], n[2]);
            }
            let _ = writeln!(obj, "usemtl fill_{}", p.material);
            for t in p.indices.chunks_exact(3) {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize + next);
                let _ = writeln!(obj, "f {a}//{a} {b}//{b} {c}//{c}");
            }
            next += p.positions.len();
        }
    }
    let mut mtl = String::new();
    let _ = writeln!(mtl, "# clayc {} export", env!("CARGO_PKG_VERSION"));
    for (i, c) in scene.materials.iter().enumerate() {
        let [r, g, b, a] = c.0.map(|v| v as f32 / 255.0);
        let _ = writeln!(mtl, "newmtl fill_{i}");
        let _ = writeln!(mtl, "Kd {r} {g} {b}");
        let _ = writeln!(mtl, "d {a}");
    }
    (obj, mtl)
}
