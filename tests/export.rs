//! `clay`'s export (issue 20): every example exports to glTF that the `gltf` crate reads back
//! with the assembly's nodes, names and triangles, to OBJ that `tobj` loads; the floor plan is
//! the renderer's, heights are untouched by the deformation. `clayc export` itself is tested in
//! `cli/tests/export.rs`.

use std::path::Path;
use std::sync::Arc;

use clay::testing::pose_assembly;
use clay::{
    Assembly, ExportOptions, Scene, Script, Session, SolverConfig, TessellationCache, scene,
};
use clay_dsl::compiled::{AssemblyData, CompiledGrammar};

const EXAMPLES: [&str; 6] = ["wall", "castle", "streets", "centipede", "junction", "bend"];

fn grammar(name: &str) -> CompiledGrammar {
    let path = format!("{}/grammars/{name}.clay", env!("CARGO_MANIFEST_DIR"));
    let source = std::fs::read_to_string(&path).unwrap();
    clay_dsl::compile(&source, &path, &clay_dsl::CompileOptions::default())
        .unwrap()
        .grammar
}

/// The assembly after the example's script, when it has one.
fn sculpted(name: &str, g: &CompiledGrammar) -> Option<AssemblyData> {
    let path = format!("{}/grammars/{name}.script.json", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).ok()?;
    let script = Script::parse(&text).unwrap();
    let mut assembly = Assembly::new(Arc::new(g.clone()));
    let mut session = Session::new(SolverConfig::from_params(&g.solver));
    clay::replay(&mut assembly, &script, &mut session).unwrap();
    Some(assembly.into_data())
}

/// The renderer's floor-plan bounds of an assembly.
fn rendered_bounds(g: &CompiledGrammar, a: &AssemblyData) -> ([f64; 2], [f64; 2]) {
    let meshes = pose_assembly(g, a, &mut TessellationCache::default());
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for m in &meshes {
        for p in &m.positions {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k] as f64);
                hi[k] = hi[k].max(p[k] as f64);
            }
        }
    }
    (lo, hi)
}

fn assert_bounds_match(s: &Scene, g: &CompiledGrammar, a: &AssemblyData, what: &str) {
    let (lo, hi) = s.floor_bounds().expect("something exported");
    let (rlo, rhi) = rendered_bounds(g, a);
    for k in 0..2 {
        assert!(
            (lo[k] - rlo[k]).abs() < 1e-6,
            "{what}: min {lo:?} vs {rlo:?}"
        );
        assert!(
            (hi[k] - rhi[k]).abs() < 1e-6,
            "{what}: max {hi:?} vs {rhi:?}"
        );
    }
}

#[test]
fn the_floor_plan_is_the_renderers_and_heights_stay_after_a_script() {
    let options = ExportOptions::default();
    for name in EXAMPLES {
        let g = grammar(name);
        let s = scene(&g, &g.assembly, &options);
        assert_bounds_match(&s, &g, &g.assembly, name);
        if let Some(after) = sculpted(name, &g) {
            assert_ne!(
                after.positions, g.assembly.positions,
                "{name}: the script moves it"
            );
            let s = scene(&g, &after, &options);
            assert_bounds_match(&s, &g, &after, name);
            // Every height is a rest height: a layer's bottom or its top (flat layer k spans
            // k * layer to thickness + k * layer, so no two layers share a plane).
            let tops: Vec<f64> = (0..64)
                .flat_map(|k| {
                    let bottom = options.layer * k as f64;
                    [bottom, options.thickness + bottom]
                })
                .collect();
            for p in s
                .nodes
                .iter()
                .flat_map(|n| &n.primitives)
                .flat_map(|p| &p.positions)
            {
                let y = p[1] as f64;
                assert!(
                    tops.iter().any(|t| (t - y).abs() < 1e-6),
                    "{name}: height {y} is not a rest height"
                );
            }
        }
    }
}

#[test]
fn faces_wind_counter_clockwise_around_unit_normals() {
    let g = grammar("castle");
    let s = scene(&g, &g.assembly, &ExportOptions::default());
    let mut up = 0;
    for p in s.nodes.iter().flat_map(|n| &n.primitives) {
        assert_eq!(p.positions.len(), p.normals.len());
        for t in p.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| glam::Vec3::from(p.positions[i as usize]));
            let n = glam::Vec3::from(p.normals[t[0] as usize]);
            assert!((n.length() - 1.0).abs() < 1e-5);
            assert!(
                (b - a).cross(c - a).dot(n) > 0.0,
                "a face winds against its normal"
            );
            up += usize::from(n.y > 0.99);
        }
    }
    assert!(up > 0);
}

#[test]
fn glb_and_gltf_read_back_with_the_assemblys_nodes_names_and_triangles() {
    for name in EXAMPLES {
        let g = grammar(name);
        let s = scene(&g, &g.assembly, &ExportOptions::default());
        for bytes in [
            clay::testing::to_glb(&s).unwrap(),
            clay::testing::to_gltf(&s).unwrap(),
        ] {
            let doc = ::gltf::Gltf::from_slice(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
            let blob = match &doc.blob {
                Some(b) => b.clone(),
                None => {
                    let uri = doc.buffers().next().unwrap();
                    let ::gltf::buffer::Source::Uri(uri) = uri.source() else {
                        panic!()
                    };
                    use base64::Engine as _;
                    base64::engine::general_purpose::STANDARD
                        .decode(uri.split_once(',').unwrap().1)
                        .unwrap()
                }
            };
            // One root, named after the grammar, whose children are the instances in order.
            let roots: Vec<_> = doc.scenes().next().unwrap().nodes().collect();
            let [root] = &roots[..] else {
                panic!("{name}: one root node")
            };
            assert_eq!(root.name(), Some(name));
            let nodes: Vec<_> = root.children().collect();
            assert_eq!(nodes.len(), g.assembly.instances.len(), "{name}");
            assert_eq!(doc.nodes().count(), nodes.len() + 1, "{name}");
            for ((node, inst), n) in nodes.iter().zip(&g.assembly.instances).zip(&s.nodes) {
                assert_eq!(node.name(), Some(n.name.as_str()));
                let extras: serde_json::Value =
                    serde_json::from_str(node.extras().as_ref().unwrap().get()).unwrap();
                assert_eq!(extras["instance"], inst.name.as_str());
                assert_eq!(extras["piece"], g.pieces[inst.piece].name.as_str());
                assert_eq!(
                    extras["state"],
                    g.pieces[inst.piece].states[inst.state].name.as_str()
                );
            }
            let mut triangles = 0;
            for mesh in doc.meshes() {
                for prim in mesh.primitives() {
                    let reader = prim.reader(|_| Some(&blob));
                    let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
                    let positions = reader.read_positions().unwrap().count();
                    assert!(indices.iter().all(|&i| (i as usize) < positions));
                    triangles += indices.len() / 3;
                }
            }
            // Each shared mesh is written once.
            assert_eq!(triangles, s.mesh_triangle_count(), "{name}");
        }
    }
}

#[test]
fn obj_loads_in_tobj_with_every_triangle_and_material() {
    for name in EXAMPLES {
        let g = grammar(name);
        let s = scene(&g, &g.assembly, &ExportOptions::default());
        let (obj_text, mtl_text) = clay::testing::to_obj(&s, "model.mtl");
        let (models, materials) = tobj::load_obj_buf(
            &mut obj_text.as_bytes(),
            &tobj::LoadOptions {
                triangulate: false,
                ..Default::default()
            },
            |p| {
                assert_eq!(p, Path::new("model.mtl"));
                tobj::load_mtl_buf(&mut mtl_text.as_bytes())
            },
        )
        .unwrap();
        assert_eq!(materials.unwrap().len(), s.materials.len(), "{name}");
        let faces: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
        assert_eq!(faces, s.triangle_count(), "{name}");
        let names: std::collections::BTreeSet<&str> =
            models.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(s.nodes.len(), g.assembly.instances.len(), "{name}");
        for node in &s.nodes {
            assert!(names.contains(node.name.as_str()), "{name}: {}", node.name);
        }
    }
}

#[test]
fn the_iso_view_draws_the_scene_the_same_way_every_time() {
    let g = grammar("castle");
    let s = scene(&g, &g.assembly, &ExportOptions::default());
    let a = clay::iso_pixmap(&s, 400, 300).unwrap();
    let b = clay::iso_pixmap(&s, 400, 300).unwrap();
    assert_eq!(a.data(), b.data(), "deterministic");
    let background = clay::testing::BACKGROUND.0;
    let drawn = a.pixels().iter().filter(|p| {
        let c = p.demultiply();
        [c.red(), c.green(), c.blue()] != [background[0], background[1], background[2]]
    });
    let share = drawn.count() as f64 / (400.0 * 300.0);
    assert!(share > 0.05 && share < 0.9, "{share}");
    assert!(clay::iso_pixmap(&s, 0, 300).is_err());
}

#[test]
fn extruded_proxies_keep_their_heights_when_the_floor_plan_deforms() {
    let source = "site type s\npiece tower {\n    vertex a (0, 0)\n    vertex b (2, 0)\n    vertex c (1, 2)\n    \
                  edges a-b-c-a\n    polygon fill #777777 extrude 6 above 2 {\n        (0, 0) (2, 0) (1, 2)\n    }\n    \
                  polygon fill #aa3333 {\n        (0.5, 0.5) (1.5, 0.5) (1, 1.5)\n    }\n}\nmodel {\n    t = tower\n}\n";
    let g = clay_dsl::compile(source, "t.clay", &clay_dsl::CompileOptions::default())
        .unwrap()
        .grammar;
    let mut a = g.assembly.clone();
    // Shear the floor plan, as a drag would.
    for p in &mut a.positions {
        p.x += 0.3 * p.y;
    }
    let options = ExportOptions::default();
    let s = scene(&g, &a, &options);
    assert_bounds_match(&s, &g, &a, "sheared tower");
    let [solid, flat] = [0, 1].map(|m| {
        let mut hs: Vec<f32> = s.nodes[0].primitives[m]
            .positions
            .iter()
            .map(|p| p[1])
            .collect();
        hs.sort_by(f32::total_cmp);
        hs.dedup();
        hs
    });
    assert_eq!(solid, vec![2.0, 8.0]);
    // The flat proxy is the second layer: one layer step up, its bottom and its top.
    assert_eq!(
        flat,
        vec![
            options.layer as f32,
            (options.thickness + options.layer) as f32
        ]
    );
}

/// Issue 48, item 5: the glTF, the OBJ's material library and the USD name every fill colour's
/// material the same (`clay::material_name`, `fill_` and the sRGB bytes), and the USD's
/// instances are the glTF's nodes, with the extras under the same words.
#[test]
fn every_format_names_materials_nodes_and_extras_alike() {
    for name in EXAMPLES {
        let g = grammar(name);
        let a = sculpted(name, &g).unwrap_or_else(|| g.assembly.clone());
        let s = scene(&g, &a, &ExportOptions::default());
        let expected: Vec<String> = s
            .materials
            .iter()
            .map(|&c| clay::material_name(c))
            .collect();
        assert!(
            expected
                .iter()
                .all(|m| m.starts_with("fill_") && m.len() == 13)
        );
        let encode = |f: clay::ExportFormat, file: &str| {
            clay::encode_export(&s, f, Path::new(file)).unwrap()
        };
        let (gltf, _) = encode(clay::ExportFormat::Gltf, "m.gltf");
        let doc: serde_json::Value = serde_json::from_slice(&gltf).unwrap();
        let gltf_names: Vec<&str> = doc["materials"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| m["name"].as_str().unwrap())
            .collect();
        assert_eq!(gltf_names, expected, "{name}: glTF");
        let (obj, mtl) = encode(clay::ExportFormat::Obj, "m.obj");
        let (obj, mtl) = (
            String::from_utf8(obj).unwrap(),
            String::from_utf8(mtl.unwrap()).unwrap(),
        );
        let newmtl: Vec<&str> = mtl
            .lines()
            .filter_map(|l| l.strip_prefix("newmtl "))
            .collect();
        assert_eq!(newmtl, expected, "{name}: MTL");
        assert!(
            obj.lines()
                .filter_map(|l| l.strip_prefix("usemtl "))
                .all(|m| expected.iter().any(|e| e == m))
        );
        let usda = String::from_utf8(encode(clay::ExportFormat::Usda, "m.usda").0).unwrap();
        let looks: Vec<&str> = usda
            .lines()
            .filter_map(|l| l.trim().strip_prefix("def Material \""))
            .map(|l| l.trim_end_matches('"'))
            .collect();
        assert_eq!(looks, expected, "{name}: USD");
        // Every binding names one of them.
        for line in usda.lines().filter(|l| l.contains("material:binding")) {
            let target = line.rsplit('/').next().unwrap().trim_end_matches('>');
            assert!(expected.iter().any(|e| e == target), "{name}: {line}");
        }
        for node in &s.nodes {
            assert!(
                usda.contains(&format!("def Xform \"{}\"", node.name)),
                "{name}: {}",
                node.name
            );
            assert!(usda.contains(&format!("userProperties:instance = \"{}\"", node.instance)));
            if let Some(c) = &node.chain {
                assert!(usda.contains(&format!("userProperties:chain = \"{}\"", c.name)));
            }
        }
    }
}
