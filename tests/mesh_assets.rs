//! Mesh assets (`mesh "tower.glb"`) in the live model: their floor plan follows the part (rigid
//! or skinned, the renderer's posing), their heights stay (paper 6), and the exports carry them.
//! `clayc check` on a broken asset is tested in `cli/tests/mesh_assets.rs`.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use clay::testing::pose_assembly;
use clay::{
    Assembly, ExportOptions, Scene, Script, Session, SolverConfig, TessellationCache, scene,
};
use clay_dsl::compiled::{AssemblyData, CompiledGrammar, ProxyShape, Rgba};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn keep() -> CompiledGrammar {
    let path = root().join("grammars/keep.clay");
    let source = std::fs::read_to_string(&path).unwrap();
    clay_dsl::compile(
        &source,
        &path.to_string_lossy(),
        &clay_dsl::CompileOptions::default(),
    )
    .unwrap()
    .grammar
}

fn after_script(g: &CompiledGrammar) -> AssemblyData {
    let text = std::fs::read_to_string(root().join("grammars/keep.script.json")).unwrap();
    let script = Script::parse(&text).unwrap();
    let mut assembly = Assembly::new(Arc::new(g.clone()));
    let mut session = Session::new(SolverConfig::from_params(&g.solver));
    clay::replay(&mut assembly, &script, &mut session).unwrap();
    assembly.into_data()
}

/// The renderer's floor-plan bounds, and the export's.
fn assert_bounds_match(s: &Scene, g: &CompiledGrammar, a: &AssemblyData) {
    let meshes = pose_assembly(g, a, &mut TessellationCache::default());
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in meshes.iter().flat_map(|m| &m.positions) {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k] as f64);
            hi[k] = hi[k].max(p[k] as f64);
        }
    }
    let (elo, ehi) = s.floor_bounds().unwrap();
    for k in 0..2 {
        assert!((elo[k] - lo[k]).abs() < 1e-6, "min {elo:?} vs {lo:?}");
        assert!((ehi[k] - hi[k]).abs() < 1e-6, "max {ehi:?} vs {hi:?}");
    }
}

/// Every mesh proxy of each instance's shown geometry: its fill and the sorted heights of its
/// triangles' corners, as the export must write them (f32).
fn expected_mesh_heights(g: &CompiledGrammar, a: &AssemblyData) -> Vec<(usize, Rgba, Vec<f32>)> {
    let mut out = Vec::new();
    for (i, inst) in a.instances.iter().enumerate() {
        let state = &g.pieces[inst.piece].states[inst.state];
        for p in &state.geometry {
            let ProxyShape::Mesh {
                heights, triangles, ..
            } = &p.shape
            else {
                continue;
            };
            let mut hs: Vec<f32> = triangles
                .iter()
                .flatten()
                .map(|&k| heights[k as usize] as f32)
                .collect();
            hs.sort_by(f32::total_cmp);
            out.push((i, p.fill, hs));
        }
    }
    out
}

fn exported_heights(s: &Scene, instance: usize, fill: Rgba) -> Vec<f32> {
    let material = s.materials.iter().position(|m| *m == fill).unwrap();
    let mut hs: Vec<f32> = s.nodes[instance]
        .primitives
        .iter()
        .filter(|p| p.material == material)
        .flat_map(|p| &p.positions)
        .map(|p| p[1])
        .collect();
    hs.sort_by(f32::total_cmp);
    hs
}

#[test]
fn keeps_roofs_keep_their_heights_and_follow_the_floor_plan_after_the_script() {
    let g = keep();
    let after = after_script(&g);
    let options = ExportOptions::default();
    let before = scene(&g, &g.assembly, &options);
    let s = scene(&g, &after, &options);
    assert_bounds_match(&before, &g, &g.assembly);
    assert_bounds_match(&s, &g, &after);
    let expected = expected_mesh_heights(&g, &after);
    assert_eq!(expected.len(), 5, "four spires and the donjon's roof");
    for (i, fill, hs) in &expected {
        assert_eq!(
            &exported_heights(&s, *i, *fill),
            hs,
            "{}",
            after.instances[*i].name
        );
    }
    // The dragged tower's spire moved 4 m north with it; its heights did not.
    let t_ne = after
        .instances
        .iter()
        .position(|i| i.name == "t_ne")
        .unwrap();
    let slate = expected.iter().find(|e| e.0 == t_ne).unwrap().1;
    let m = s.materials.iter().position(|m| *m == slate).unwrap();
    // Where the spire is in the scene: its node places it.
    let north = |s: &Scene| {
        let node = &s.nodes[t_ne];
        let p = node.primitives.iter().find(|p| p.material == m).unwrap();
        let sum: f64 = p.positions.iter().map(|&q| -node.to_world(q).z).sum();
        (sum / p.positions.len() as f64) as f32
    };
    assert!(
        north(&s) - north(&before) > 3.0,
        "{} -> {}",
        north(&before),
        north(&s)
    );
}

#[test]
fn keep_with_its_roofs_reads_back_with_the_gltf_crate() {
    let g = keep();
    let after = after_script(&g);
    let s = scene(&g, &after, &ExportOptions::default());
    for bytes in [
        clay::testing::to_glb(&s).unwrap(),
        clay::testing::to_gltf(&s).unwrap(),
    ] {
        let doc = ::gltf::Gltf::from_slice(&bytes).unwrap();
        // One root whose children are the instances, their assembly names in the extras.
        let root = doc.default_scene().unwrap().nodes().next().unwrap();
        let nodes: Vec<_> = root.children().collect();
        assert_eq!(nodes.len(), after.instances.len());
        for ((node, inst), n) in nodes.iter().zip(&after.instances).zip(&s.nodes) {
            assert_eq!(node.name(), Some(n.name.as_str()));
            let extras: serde_json::Value =
                serde_json::from_str(node.extras().as_ref().unwrap().get()).unwrap();
            assert_eq!(extras["instance"], inst.name.as_str());
        }
        let blob = match &doc.blob {
            Some(b) => b.clone(),
            None => {
                use base64::Engine as _;
                let b = doc.buffers().next().unwrap();
                let ::gltf::buffer::Source::Uri(uri) = b.source() else {
                    panic!()
                };
                base64::engine::general_purpose::STANDARD
                    .decode(uri.split_once(',').unwrap().1)
                    .unwrap()
            }
        };
        let mut triangles = 0;
        let mut top = f32::MIN;
        for mesh in doc.meshes() {
            for prim in mesh.primitives() {
                let reader = prim.reader(|_| Some(&blob));
                triangles += reader.read_indices().unwrap().into_u32().count() / 3;
                top = reader
                    .read_positions()
                    .unwrap()
                    .fold(top, |t, p| t.max(p[1]));
            }
        }
        // Shared meshes once: the four towers are one.
        assert_eq!(triangles, s.mesh_triangle_count());
        assert!((top - 9.8).abs() < 1e-5, "the spires' apex: {top}");
    }
}

/// A folder with a grammar and its assets.
fn scratch(name: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("clay-mesh-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (file, text) in files {
        std::fs::write(dir.join(file), text).unwrap();
    }
    dir
}

const BOX: &str = "v 0 0 0.4\nv 1 0 0.4\nv 1 0 -0.4\nv 0 0 -0.4\nv 0 3 0.4\nv 1 3 0.4\nv 1 3 -0.4\n\
                   v 0 3 -0.4\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

const WALL: &str = "site type s\npiece wall {\n    vertex sw (0, -0.4)\n    vertex se (1, -0.4)\n    \
                    vertex ne (1, 0.4)\n    vertex nw (0, 0.4)\n    edges sw-se-ne-nw-sw, sw-ne\n    \
                    site west: s [nw, sw] out (-1, 0)\n    site east: s [se, ne] out (1, 0)\n    \
                    axis west -> east\n    polygon skinned fill #111111 {\n        \
                    (0, -0.4) (1, -0.4) (1, 0.4) (0, 0.4)\n    }\n    mesh skinned \"box.obj\" fill #222222\n}\n\
                    model {\n    w = wall\n}\n";

#[test]
fn a_skinned_mesh_follows_the_skin_of_its_polygon_and_keeps_its_heights() {
    let dir = scratch("skin", &[("wall.clay", WALL), ("box.obj", BOX)]);
    let path = dir.join("wall.clay");
    let g = clay_dsl::compile(
        WALL,
        &path.to_string_lossy(),
        &clay_dsl::CompileOptions::default(),
    )
    .unwrap()
    .grammar;
    let mut a = g.assembly.clone();
    // Stretch and bend the wall as a drag would: the east site moves out and up.
    for p in &mut a.positions {
        *p += glam::DVec2::new(0.8 * p.x, 0.5 * p.x * p.x);
    }
    let s = scene(&g, &a, &ExportOptions::default());
    assert_bounds_match(&s, &g, &a);
    let meshes = pose_assembly(&g, &a, &mut TessellationCache::default());
    let [polygon, mesh] = [&meshes[0], &meshes[1]];
    // The box's corners are the polygon's: skinned alike, they land on the same points.
    let at: HashMap<[u32; 2], ()> = polygon
        .positions
        .iter()
        .map(|p| {
            (
                [
                    (p[0] * 1e4).round() as u32,
                    (p[1] * 1e4 + 1e5).round() as u32,
                ],
                (),
            )
        })
        .collect();
    for p in &mesh.positions {
        let key = [
            (p[0] * 1e4).round() as u32,
            (p[1] * 1e4 + 1e5).round() as u32,
        ];
        assert!(at.contains_key(&key), "{p:?} is not a posed polygon corner");
    }
    let mut hs = exported_heights(&s, 0, Rgba([0x22, 0x22, 0x22, 0xff]));
    hs.dedup();
    assert_eq!(hs, vec![0.0, 3.0]);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn keep_with_its_roofs_loads_as_obj_in_tobj() {
    let g = keep();
    let s = scene(&g, &after_script(&g), &ExportOptions::default());
    let (obj_text, mtl_text) = clay::testing::to_obj(&s, "keep.mtl");
    let (models, materials) = tobj::load_obj_buf(
        &mut obj_text.as_bytes(),
        &tobj::LoadOptions::default(),
        |_| tobj::load_mtl_buf(&mut mtl_text.as_bytes()),
    )
    .unwrap();
    assert_eq!(materials.unwrap().len(), s.materials.len());
    let faces: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
    assert_eq!(faces, s.triangle_count());
    let top = models
        .iter()
        .flat_map(|m| m.mesh.positions.chunks_exact(3).map(|p| p[1]))
        .fold(f32::MIN, f32::max);
    assert!((top - 9.8).abs() < 1e-4, "the spires' apex: {top}");
}

/// Found by `tests/fuzz_assets.rs`: a glTF node scaled by 3e38 gave a vertex finite in f64 and
/// infinite in the export's f32 (`inf` written to the `.glb` and the `.obj`). The loader now
/// refuses a vertex beyond the grammar's coordinate limit; at the limit, in any model
/// placement, the export is finite.
#[test]
fn an_asset_at_the_coordinate_limit_exports_only_finite_numbers() {
    // One triangle, x up to 1 and z down to -1, at y up to 2 (a strip of three vertices).
    let gltf = |scale: &str| {
        let data = "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAAEAAAIC/";
        format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
            "nodes":[{{"mesh":0,"scale":[{scale},{scale},{scale}]}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
            "buffers":[{{"byteLength":36,"uri":"data:application/octet-stream;base64,{data}"}}],
            "bufferViews":[{{"buffer":0,"byteLength":36}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
            "min":[0,0,-1],"max":[1,2,0]}}]}}"#
        )
    };
    let source = WALL.replace("box.obj", "far.gltf");
    for (scale, loads) in [("3e38", false), ("5e8", true)] {
        let dir = scratch(
            &format!("far-{scale}"),
            &[("wall.clay", &source), ("far.gltf", &gltf(scale))],
        );
        let path = dir.join("wall.clay");
        let compiled = clay_dsl::compile(
            &source,
            &path.to_string_lossy(),
            &clay_dsl::CompileOptions::default(),
        );
        assert_eq!(
            compiled.is_ok(),
            loads,
            "scale {scale}: {:?}",
            compiled.as_ref().err()
        );
        if let Ok(c) = compiled {
            let s = scene(&c.grammar, &c.grammar.assembly, &ExportOptions::default());
            assert!(s.triangle_count() > 0);
            for p in s.nodes.iter().flat_map(|n| &n.primitives) {
                for v in p.positions.iter().chain(&p.normals) {
                    assert!(v.iter().all(|x| x.is_finite()), "{v:?}");
                }
            }
            let (obj, _) = clay::testing::to_obj(&s, "far.mtl");
            assert!(!obj.contains("inf") && !obj.contains("NaN"));
            assert!(clay::testing::to_glb(&s).is_ok());
        }
        std::fs::remove_dir_all(dir).unwrap();
    }
}
