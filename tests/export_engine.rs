//! Exports ready for engines (issue 40), read back with real readers (the `gltf` crate, `tobj`):
//! one root node per model; each instance a node at its pivot, turned as its instance, with its
//! mesh in local coordinates; one mesh shared by identical instances; extras with the piece,
//! state and place in the stretch chain; names that importers keep and that stay unique; planar
//! UVs on every mesh; OBJ colours linear as glTF's; every solid closed and manifold.

use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::Path;
use std::sync::Arc;

use clay::testing::{pose_assembly, srgb_to_linear};
use clay::{
    Assembly, ExportOptions, Scene, Script, Session, SolverConfig, TessellationCache, scene,
};
use clay_dsl::compiled::{AssemblyData, CompiledGrammar};
use glam::{DQuat, DVec2, DVec3};

const EXAMPLES: [&str; 7] = [
    "wall",
    "castle",
    "streets",
    "centipede",
    "junction",
    "bend",
    "keep",
];

fn grammar(name: &str) -> CompiledGrammar {
    let path = format!("{}/grammars/{name}.clay", env!("CARGO_MANIFEST_DIR"));
    let source = std::fs::read_to_string(&path).unwrap();
    clay_dsl::compile(&source, &path, &clay_dsl::CompileOptions::default())
        .unwrap()
        .grammar
}

/// The initial assembly, and the one after the example's script when it has one.
fn assemblies(name: &str, g: &CompiledGrammar) -> Vec<(&'static str, AssemblyData)> {
    let mut out = vec![("initial", g.assembly.clone())];
    let path = format!("{}/grammars/{name}.script.json", env!("CARGO_MANIFEST_DIR"));
    if let Ok(text) = std::fs::read_to_string(path) {
        let script = Script::parse(&text).unwrap();
        let mut assembly = Assembly::new(Arc::new(g.clone()));
        let mut session = Session::new(SolverConfig::from_params(&g.solver));
        clay::replay(&mut assembly, &script, &mut session).unwrap();
        out.push(("sculpted", assembly.into_data()));
    }
    out
}

/// three.js's `PropertyBinding.sanitizeNodeName`: whitespace to `_`, `[ ] . : /` dropped.
fn three_js(name: &str) -> String {
    name.chars()
        .map(|c| if c.is_whitespace() { '_' } else { c })
        .filter(|c| !"[].:/".contains(*c))
        .collect()
}

fn blob(doc: &::gltf::Gltf) -> Vec<u8> {
    match &doc.blob {
        Some(b) => b.clone(),
        None => {
            let ::gltf::buffer::Source::Uri(uri) = doc.buffers().next().unwrap().source() else {
                panic!("no buffer")
            };
            use base64::Engine as _;
            base64::engine::general_purpose::STANDARD
                .decode(uri.split_once(',').unwrap().1)
                .unwrap()
        }
    }
}

/// One triangle mesh as read: positions and triangles.
struct Read {
    positions: Vec<[f32; 3]>,
    uvs: usize,
    normals: usize,
    triangles: Vec<[u32; 3]>,
    material: Option<usize>,
}

fn read_primitives(mesh: &::gltf::Mesh, blob: &[u8]) -> Vec<Read> {
    mesh.primitives()
        .map(|prim| {
            let reader = prim.reader(|_| Some(blob));
            let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
            let uvs = reader
                .read_tex_coords(0)
                .map_or(0, |t| t.into_f32().count());
            let normals = reader.read_normals().map_or(0, |n| n.count());
            let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
            Read {
                positions,
                uvs,
                normals,
                triangles: indices
                    .chunks_exact(3)
                    .map(|t| [t[0], t[1], t[2]])
                    .collect(),
                material: prim.material().index(),
            }
        })
        .collect()
}

/// Problems with a triangle set as a closed, consistently wound solid: vertices welded by
/// position, every edge must be used by exactly two triangles, once in each direction.
fn solid_problems(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<String> {
    let mut weld: HashMap<[u32; 3], u32> = HashMap::new();
    let ids: Vec<u32> = positions
        .iter()
        .map(|p| {
            let key = p.map(|c| (c + 0.0).to_bits());
            let n = weld.len() as u32;
            *weld.entry(key).or_insert(n)
        })
        .collect();
    let mut directed: HashMap<[u32; 2], usize> = HashMap::new();
    for t in triangles {
        let w = t.map(|i| ids[i as usize]);
        for k in 0..3 {
            *directed.entry([w[k], w[(k + 1) % 3]]).or_default() += 1;
        }
    }
    let mut problems = Vec::new();
    for (&[a, b], &n) in &directed {
        let back = directed.get(&[b, a]).copied().unwrap_or(0);
        if n != 1 || back != 1 {
            problems.push(format!("edge {a}->{b} used {n} times, back {back} times"));
        }
    }
    problems.sort();
    problems
}

/// The renderer's floor-plan bounding box of one instance.
fn rendered_bounds(g: &CompiledGrammar, a: &AssemblyData) -> HashMap<usize, (DVec2, DVec2)> {
    let mut out: HashMap<usize, (DVec2, DVec2)> = HashMap::new();
    for m in pose_assembly(g, a, &mut TessellationCache::default()) {
        for p in &m.positions {
            let p = DVec2::new(p[0] as f64, p[1] as f64);
            let e = out.entry(m.instance).or_insert((p, p));
            e.0 = e.0.min(p);
            e.1 = e.1.max(p);
        }
    }
    out
}

fn centroid(a: &AssemblyData, instance: usize) -> DVec2 {
    let vs = &a.instances[instance].vertices;
    vs.iter().map(|&v| a.positions[v]).sum::<DVec2>() / vs.len() as f64
}

/// Everything this file checks of one glTF export of assembly `a`.
fn check_gltf(what: &str, bytes: &[u8], g: &CompiledGrammar, a: &AssemblyData, s: &Scene) {
    let doc = ::gltf::Gltf::from_slice(bytes).unwrap_or_else(|e| panic!("{what}: {e}"));
    let blob = blob(&doc);
    let stem = Path::new(&g.source).file_stem().unwrap().to_str().unwrap();

    // One root, named after the model, whose children are the instances in order.
    let scene_ = doc.default_scene().unwrap();
    let roots: Vec<_> = scene_.nodes().collect();
    assert_eq!(roots.len(), 1, "{what}: one root");
    let root = &roots[0];
    assert_eq!(root.name(), Some(stem), "{what}");
    assert!(root.mesh().is_none());
    let children: Vec<_> = root.children().collect();
    assert_eq!(children.len(), a.instances.len(), "{what}");
    assert_eq!(doc.nodes().count(), a.instances.len() + 1, "{what}");

    // Names: unchanged by three.js's sanitiser, at most 63 bytes, unique (the root's too).
    let mut names = HashSet::new();
    for n in doc.nodes() {
        let name = n.name().unwrap();
        assert_eq!(three_js(name), name, "{what}: {name}");
        assert!(name.len() <= 63, "{what}: {name}");
        assert!(names.insert(name.to_string()), "{what}: {name} twice");
    }
    let sanitised: HashSet<String> = names.iter().map(|n| three_js(n)).collect();
    assert_eq!(sanitised.len(), names.len());

    // Where every instance is in its chain.
    let mut place = HashMap::new();
    for c in &a.chains {
        for (k, &i) in c.instances.iter().enumerate() {
            place.insert(i, k);
        }
    }
    let bounds = rendered_bounds(g, a);
    let mut users: BTreeMap<usize, usize> = BTreeMap::new();
    for (i, (node, inst)) in children.iter().zip(&a.instances).enumerate() {
        let extras: serde_json::Value =
            serde_json::from_str(node.extras().as_ref().unwrap().get()).unwrap();
        assert_eq!(extras["instance"], inst.name.as_str(), "{what}");
        assert_eq!(extras["id"], inst.id, "{what}");
        assert_eq!(extras["piece"], g.pieces[inst.piece].name.as_str());
        assert_eq!(
            extras["state"],
            g.pieces[inst.piece].states[inst.state].name.as_str()
        );
        match place.get(&i) {
            Some(&k) => {
                assert_eq!(extras["index"], k, "{what}: {}", inst.name);
                let chain = extras["chain"].as_str().unwrap();
                assert_eq!(node.name(), Some(format!("{chain}_{k}").as_str()));
            }
            None => assert!(extras.get("chain").is_none() && extras.get("index").is_none()),
        }

        // The node stands at the instance's centroid on the ground.
        let (t, r, sc) = node.transform().decomposed();
        let c = centroid(a, i);
        assert!(
            (t[0] as f64 - c.x).abs() < 1e-5 && t[1] == 0.0 && (-(t[2] as f64) - c.y).abs() < 1e-5,
            "{what}: {} at {t:?}, centroid {c}",
            inst.name
        );
        assert_eq!(sc, [1.0; 3]);
        // Its mesh, placed by its node, covers what the renderer draws of the instance.
        let Some(mesh) = node.mesh() else {
            assert!(
                !bounds.contains_key(&i),
                "{what}: {} has no mesh",
                inst.name
            );
            continue;
        };
        *users.entry(mesh.index()).or_default() += 1;
        let turn = DQuat::from_array(r.map(|v| v as f64));
        let at = DVec3::from_array(t.map(|v| v as f64));
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for p in read_primitives(&mesh, &blob) {
            for q in &p.positions {
                let w = at + turn * DVec3::from_array(q.map(|v| v as f64));
                let plan = DVec2::new(w.x, -w.z);
                lo = lo.min(plan);
                hi = hi.max(plan);
            }
        }
        let (rlo, rhi) = bounds[&i];
        assert!(
            lo.distance(rlo) < 1e-4 && hi.distance(rhi) < 1e-4,
            "{what}: {} spans {lo}..{hi}, drawn {rlo}..{rhi}",
            inst.name
        );
    }
    // The file's meshes are the scene's shared ones, each used as often as the scene says.
    assert_eq!(doc.meshes().count(), s.meshes.len(), "{what}");
    for (m, shared) in s.meshes.iter().enumerate() {
        assert_eq!(users.get(&m).copied(), Some(shared.users), "{what}");
    }

    // Every mesh: UVs and normals for every vertex, and closed, manifold solids (but mesh
    // assets, whose triangles are their own).
    let asset_fills: HashSet<[u8; 4]> = g
        .pieces
        .iter()
        .flat_map(|p| &p.states)
        .flat_map(|s| &s.geometry)
        .filter(|p| matches!(p.shape, clay_dsl::compiled::ProxyShape::Mesh { .. }))
        .map(|p| p.fill.0)
        .collect();
    for mesh in doc.meshes() {
        for p in read_primitives(&mesh, &blob) {
            assert_eq!(p.uvs, p.positions.len(), "{what}: {:?}", mesh.name());
            assert_eq!(p.normals, p.positions.len(), "{what}: {:?}", mesh.name());
            let fill = s.materials[p.material.unwrap()].0;
            if asset_fills.contains(&fill) {
                continue;
            }
            let problems = solid_problems(&p.positions, &p.triangles);
            assert!(
                problems.is_empty(),
                "{what}: mesh {:?} is not a closed manifold solid: {} problems, {:?}",
                mesh.name(),
                problems.len(),
                &problems[..problems.len().min(5)]
            );
        }
    }
}

#[test]
fn every_example_exports_a_root_with_placed_shared_named_closed_meshes() {
    for name in EXAMPLES {
        let g = grammar(name);
        for (when, a) in assemblies(name, &g) {
            let s = scene(&g, &a, &ExportOptions::default());
            let what = format!("{name} {when}");
            check_gltf(
                &format!("{what} .glb"),
                &clay::testing::to_glb(&s).unwrap(),
                &g,
                &a,
                &s,
            );
            check_gltf(
                &format!("{what} .gltf"),
                &clay::testing::to_gltf(&s).unwrap(),
                &g,
                &a,
                &s,
            );
        }
    }
}

#[test]
fn identical_instances_share_one_mesh() {
    // The wall's eight bricks at rest are one mesh, placed eight times a metre apart.
    let g = grammar("wall");
    let s = scene(&g, &g.assembly, &ExportOptions::default());
    assert_eq!(s.nodes.len(), 8);
    assert_eq!(s.meshes.len(), 1, "{:?}", s.meshes);
    assert_eq!(s.meshes[0].users, 8);
    assert_eq!(s.meshes[0].name, "brick__base");
    assert_eq!(s.triangle_count(), 8 * s.mesh_triangle_count());
    let doc = ::gltf::Gltf::from_slice(&clay::testing::to_glb(&s).unwrap()).unwrap();
    assert_eq!(doc.meshes().count(), 1);
    let xs: Vec<f32> = doc
        .nodes()
        .filter(|n| n.mesh().is_some())
        .map(|n| n.transform().decomposed().0[0])
        .collect();
    assert_eq!(xs, (0..8).map(|k| k as f32 + 0.5).collect::<Vec<_>>());
    // The castle's towers and its straight wall sections repeat too.
    let g = grammar("castle");
    let s = scene(&g, &g.assembly, &ExportOptions::default());
    assert!(
        s.meshes.len() * 3 < s.nodes.len(),
        "{} meshes for {} nodes",
        s.meshes.len(),
        s.nodes.len()
    );
}

#[test]
fn a_turned_instance_is_a_turned_node_with_its_rest_mesh() {
    // keep.clay's towers are one rigid piece at four corners: one mesh each state, and a node
    // turned as the tower is.
    let g = grammar("keep");
    let mut a = g.assembly.clone();
    // Turn the whole model a quarter turn about the origin: every node turns with it.
    for p in &mut a.positions {
        *p = DVec2::new(-p.y, p.x);
    }
    let before = scene(&g, &g.assembly, &ExportOptions::default());
    let s = scene(&g, &a, &ExportOptions::default());
    assert_eq!(s.meshes.len(), before.meshes.len());
    for (n, m) in s.nodes.iter().zip(&before.nodes) {
        let angle = n.turn.y.atan2(n.turn.x) - m.turn.y.atan2(m.turn.x);
        let angle =
            (angle + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
        assert!(
            (angle - std::f64::consts::FRAC_PI_2).abs() < 1e-9,
            "{}: {angle}",
            n.name
        );
        assert_eq!(n.primitives.len(), m.primitives.len());
        for (p, q) in n.primitives.iter().zip(&m.primitives) {
            for (u, v) in p.positions.iter().zip(&q.positions) {
                assert!((0..3).all(|k| (u[k] - v[k]).abs() < 1e-4), "{}", n.name);
            }
        }
    }
}

#[test]
fn chain_elements_are_named_and_numbered_in_chain_order_after_a_stretch() {
    // wall.clay's script, pulling out only: the wall grows brick by brick.
    let g = grammar("wall");
    let script = Script::parse(
        r#"{"steps": [{"pin": {"extreme": "west"}}, {"grab": {"extreme": "east"}},
        {"drag": {"by": [8, 0], "frames": 120}}, {"hold": {"frames": 30}}]}"#,
    )
    .unwrap();
    let mut assembly = Assembly::new(Arc::new(g.clone()));
    let mut session = Session::new(SolverConfig::from_params(&g.solver));
    clay::replay(&mut assembly, &script, &mut session).unwrap();
    let after = assembly.into_data();
    assert!(after.instances.len() > 8, "the wall grows");
    let s = scene(&g, &after, &ExportOptions::default());
    let chain = &after.chains[0];
    for (k, &i) in chain.instances.iter().enumerate() {
        let node = &s.nodes[i];
        assert_eq!(node.name, format!("wall_{k}"));
        let place = node.chain.as_ref().unwrap();
        assert_eq!((place.name.as_str(), place.index), ("wall", k));
        assert_eq!(node.instance, after.instances[i].name);
    }
    // Inserted bricks keep their assembly names (`wall#12`) in the extras only.
    assert!(s.nodes.iter().any(|n| n.instance.contains('#')));
    assert!(s.nodes.iter().all(|n| !n.name.contains('#')));
}

#[test]
fn obj_has_uvs_and_glb_colours_and_the_nodes_names() {
    for name in EXAMPLES {
        let g = grammar(name);
        let s = scene(&g, &g.assembly, &ExportOptions::default());
        let (obj_text, mtl_text) = clay::testing::to_obj(&s, "model.mtl");
        let (models, materials) = tobj::load_obj_buf(
            &mut obj_text.as_bytes(),
            &tobj::LoadOptions {
                triangulate: false,
                single_index: true,
                ..Default::default()
            },
            |_| tobj::load_mtl_buf(&mut mtl_text.as_bytes()),
        )
        .unwrap();
        let materials = materials.unwrap();
        // Kd is glTF's linear base colour factor.
        let doc = ::gltf::Gltf::from_slice(&clay::testing::to_glb(&s).unwrap()).unwrap();
        for (m, gm) in materials.iter().zip(doc.materials()) {
            let kd = m.diffuse.unwrap();
            let base = gm.pbr_metallic_roughness().base_color_factor();
            for k in 0..3 {
                assert!((kd[k] - base[k]).abs() < 1e-6, "{name}: {kd:?} vs {base:?}");
            }
        }
        assert_eq!(materials.len(), s.materials.len());
        let colour = s.materials[0].0;
        assert!((materials[0].diffuse.unwrap()[0] - srgb_to_linear(colour[0])).abs() < 1e-6);
        // Every vertex has a texture coordinate; every object is a node of the glTF.
        for m in &models {
            assert_eq!(
                m.mesh.texcoords.len() / 2,
                m.mesh.positions.len() / 3,
                "{name}: {}",
                m.name
            );
        }
        let objects: HashSet<&str> = models.iter().map(|m| m.name.as_str()).collect();
        for n in &s.nodes {
            if !n.primitives.is_empty() {
                assert!(objects.contains(n.name.as_str()), "{name}: {}", n.name);
            }
        }
        let faces: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
        assert_eq!(faces, s.triangle_count(), "{name}");
    }
}

#[test]
fn uvs_are_planar_in_metres() {
    // A 2 m x 1 m slab 3 m high: its top is mapped from above, its walls along themselves with
    // v down their height, all in metres.
    let source = "piece slab {\n    vertex a (0, 0)\n    vertex b (2, 0)\n    vertex c (2, 1)\n    \
                  vertex d (0, 1)\n    edges a-b-c-d-a, a-c\n    polygon fill #777777 extrude 3 {\n        \
                  (0, 0) (2, 0) (2, 1) (0, 1)\n    }\n}\nmodel {\n    s = slab\n}\n";
    let g = clay_dsl::compile(source, "slab.clay", &clay_dsl::CompileOptions::default())
        .unwrap()
        .grammar;
    let s = scene(&g, &g.assembly, &ExportOptions::default());
    assert_eq!(s.name, "slab");
    let p = &s.nodes[0].primitives[0];
    assert_eq!(p.uvs.len(), p.positions.len());
    for ((q, n), uv) in p.positions.iter().zip(&p.normals).zip(&p.uvs) {
        if n[1].abs() > 0.5 {
            assert_eq!(*uv, [q[0], q[2]]);
        } else {
            assert_eq!(uv[1], -q[1], "v is the height, down");
        }
    }
    let span = |k: usize| {
        let (lo, hi) = p
            .uvs
            .iter()
            .zip(&p.normals)
            .filter(|(_, n)| n[1].abs() < 0.5)
            .fold((f32::MAX, f32::MIN), |(lo, hi), (uv, _)| {
                (lo.min(uv[k]), hi.max(uv[k]))
            });
        hi - lo
    };
    assert!((span(1) - 3.0).abs() < 1e-6);
    // The walls' u spans come from the 2 m and 1 m sides.
    assert!(span(0) >= 1.0 - 1e-6);
    // Closed: 2 + 2 cap triangles, 4 walls of 2.
    assert_eq!(p.indices.len() / 3, 12);
    assert!(
        solid_problems(
            &p.positions,
            &p.indices
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect::<Vec<_>>()
        )
        .is_empty()
    );
}

#[test]
fn flat_layers_share_no_face_plane_and_no_edge() {
    // wall.clay's brick: a polygon and, drawn on it, a polyline along its lower edge, both flat.
    // Before issue 40 both stood on y = 0 and shared the bottom edge (four faces on one edge).
    let g = grammar("wall");
    let s = scene(&g, &g.assembly, &ExportOptions::default());
    let node = &s.nodes[0];
    assert_eq!(node.primitives.len(), 2);
    let heights = |p: &clay::Primitive| {
        let mut hs: Vec<f32> = p.positions.iter().map(|q| q[1]).collect();
        hs.sort_by(f32::total_cmp);
        hs.dedup();
        hs
    };
    let (a, b) = (heights(&node.primitives[0]), heights(&node.primitives[1]));
    assert_eq!(a.len(), 2);
    assert_eq!(b.len(), 2);
    assert!(a.iter().all(|h| !b.contains(h)), "{a:?} {b:?}");
    // Both primitives together (one object in Blender) are still manifold.
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for p in &node.primitives {
        let base = positions.len() as u32;
        positions.extend(&p.positions);
        triangles.extend(
            p.indices
                .chunks_exact(3)
                .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
        );
    }
    assert!(solid_problems(&positions, &triangles).is_empty());
}

#[test]
fn the_floor_plan_placed_by_the_nodes_is_the_renderers_and_heights_are_rest_heights() {
    let options = ExportOptions::default();
    for name in EXAMPLES {
        let g = grammar(name);
        // The heights a proxy may have: a flat layer's bottom or top, an extrusion's, an
        // asset's own.
        let mut heights: Vec<f64> = (0..64)
            .flat_map(|k| {
                let lift = options.layer * k as f64;
                [lift, options.thickness + lift]
            })
            .collect();
        for proxy in g
            .pieces
            .iter()
            .flat_map(|p| &p.states)
            .flat_map(|s| &s.geometry)
        {
            if let Some(e) = proxy.extrude {
                heights.extend([e.base, e.base + e.height]);
            }
            if let clay_dsl::compiled::ProxyShape::Mesh { heights: h, .. } = &proxy.shape {
                heights.extend(h);
            }
        }
        for (when, a) in assemblies(name, &g) {
            let s = scene(&g, &a, &options);
            let (lo, hi) = s.floor_bounds().unwrap();
            let (mut rlo, mut rhi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for m in pose_assembly(&g, &a, &mut TessellationCache::default()) {
                for p in &m.positions {
                    for k in 0..2 {
                        rlo[k] = rlo[k].min(p[k] as f64);
                        rhi[k] = rhi[k].max(p[k] as f64);
                    }
                }
            }
            for k in 0..2 {
                assert!(
                    (lo[k] - rlo[k]).abs() < 1e-6 && (hi[k] - rhi[k]).abs() < 1e-6,
                    "{name} {when}: {lo:?}..{hi:?} vs {rlo:?}..{rhi:?}"
                );
            }
            for p in s
                .nodes
                .iter()
                .flat_map(|n| &n.primitives)
                .flat_map(|p| &p.positions)
            {
                let y = p[1] as f64;
                assert!(
                    heights.iter().any(|h| (h - y).abs() < 1e-5),
                    "{name} {when}: height {y}"
                );
            }
        }
    }
}
