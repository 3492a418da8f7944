//! `mesh "PATH"` assets (docs/language.md): what the compiler embeds, and that no file, however
//! broken, panics it: every failure is one diagnostic (E064-E067) at the path string.

use std::collections::HashMap;
use std::io::{Error, ErrorKind};

use clay_dsl::compiled::ProxyShape;
use clay_dsl::{
    CompileOptions, CompiledGrammar, Diagnostics, FsLoader, Loader, MAX_MESH_BYTES,
    MAX_MESH_VERTICES,
};

/// Files served from memory; a path missing from the map does not exist.
#[derive(Default)]
struct Files(HashMap<String, Result<Vec<u8>, ErrorKind>>);

impl Files {
    fn with(mut self, path: &str, bytes: impl Into<Vec<u8>>) -> Self {
        self.0.insert(path.to_string(), Ok(bytes.into()));
        self
    }
    fn failing(mut self, path: &str, kind: ErrorKind) -> Self {
        self.0.insert(path.to_string(), Err(kind));
        self
    }
}

impl Loader for Files {
    fn load(&self, path: &str) -> std::io::Result<Vec<u8>> {
        match self.0.get(path) {
            Some(Ok(b)) => Ok(b.clone()),
            Some(Err(k)) => Err(Error::from(*k)),
            None => Err(Error::from(ErrorKind::NotFound)),
        }
    }
}

/// A grammar of one triangle piece carrying `mesh STMT`, at `g/hut.clay`.
fn hut(mesh: &str) -> String {
    format!(
        "piece hut {{\n    vertex a (0, 0)\n    vertex b (1, 0)\n    vertex c (0, 1)\n    \
         edges a-b-c-a\n    {mesh}\n}}\nmodel {{\n    h = hut\n}}\n"
    )
}

fn compile(source: &str, loader: &dyn Loader) -> Result<CompiledGrammar, Diagnostics> {
    clay_dsl::compile(source, "g/hut.clay", &CompileOptions::with_loader(loader)).map(|c| c.grammar)
}

/// The one error of a failed compile: its code, and where it points.
fn one_error(source: &str, loader: &dyn Loader) -> (&'static str, String, usize) {
    let d = compile(source, loader).expect_err("the asset is refused");
    let errors: Vec<_> = d.iter().collect();
    assert_eq!(errors.len(), 1, "one error per mistake: {errors:?}");
    let e = errors[0];
    assert!(!e.hints.is_empty(), "{}: a help line", e.code);
    (e.code, e.message.clone(), e.primary.span.start)
}

fn tower_glb() -> Vec<u8> {
    std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../grammars/assets/tower-roof.glb"
    ))
    .unwrap()
}

const CUBE_OBJ: &str = "mtllib cube.mtl\nv 0 0 0\nv 1 0 0\nv 1 0 -1\nv 0 0 -1\nv 0 2 0\nv 1 2 0\n\
                        v 1 2 -1\nv 0 2 -1\nusemtl red\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\n\
                        f 3 4 8 7\nf 4 1 5 8\n";

#[test]
fn an_obj_asset_is_embedded_in_piece_coordinates_with_its_material_colour() {
    let files = Files::default()
        .with("g/cube.obj", CUBE_OBJ)
        .with("g/cube.mtl", "newmtl red\nKd 1 0 0\n");
    let g = compile(&hut("mesh \"cube.obj\""), &files).unwrap();
    let proxy = &g.pieces[0].states[0].geometry[0];
    assert_eq!(proxy.fill.0, [255, 0, 0, 255], "the .mtl's diffuse colour");
    let ProxyShape::Mesh {
        points,
        heights,
        triangles,
    } = &proxy.shape
    else {
        panic!("a mesh proxy")
    };
    assert_eq!(triangles.len(), 12, "six quads, triangulated");
    assert_eq!(points.len(), 8);
    // Asset (x, y, z), y up, is piece (x, -z) at height y.
    for (p, h) in points.iter().zip(heights) {
        assert!(
            [0.0, 1.0].contains(&p.x) && [0.0, 1.0].contains(&p.y),
            "{p}"
        );
        assert!([0.0, 2.0].contains(h));
    }
    // A `fill` overrides the asset's colours; the compiled grammar round-trips through JSON.
    let g = compile(&hut("mesh \"cube.obj\" fill #336699"), &files).unwrap();
    assert_eq!(
        g.pieces[0].states[0].geometry[0].fill.0,
        [0x33, 0x66, 0x99, 255]
    );
    let json = serde_json::to_string(&g).unwrap();
    assert!(json.contains("\"kind\":\"mesh\""));
    assert_eq!(serde_json::from_str::<CompiledGrammar>(&json).unwrap(), g);
}

#[test]
fn a_glb_asset_reads_its_nodes_and_base_colour() {
    let files = Files::default().with("g/tower.glb", tower_glb());
    let g = compile(&hut("mesh rigid \"tower.glb\""), &files).unwrap();
    let ProxyShape::Mesh {
        heights, triangles, ..
    } = &g.pieces[0].states[0].geometry[0].shape
    else {
        panic!()
    };
    assert_eq!(triangles.len(), 16);
    let top = heights.iter().copied().fold(f64::MIN, f64::max);
    assert!((top - 9.8).abs() < 1e-5 && heights.iter().all(|&h| h >= 7.0 - 1e-6));
}

#[test]
fn missing_unreadable_and_folder_assets_are_their_own_codes() {
    let source = hut("mesh \"tower.glb\"");
    let at = source.find("\"tower.glb\"").unwrap();
    let (code, message, start) = one_error(&source, &Files::default());
    assert_eq!((code, start), ("E064", at));
    assert!(message.contains("g/tower.glb"), "{message}");
    let denied = Files::default().failing("g/tower.glb", ErrorKind::PermissionDenied);
    assert_eq!(one_error(&source, &denied).0, "E065");
    // A real folder through the file system loader.
    let dir = std::env::temp_dir().join(format!("clay-mesh-dir-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("tower.glb")).unwrap();
    let path = dir.join("hut.clay").to_string_lossy().into_owned();
    let d = clay_dsl::compile(&source, &path, &CompileOptions::with_loader(&FsLoader)).unwrap_err();
    let codes: Vec<_> = d.iter().map(|d| d.code).collect();
    assert_eq!(codes, ["E065"], "{d:?}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn binary_junk_is_malformed_never_a_panic() {
    let source = hut("mesh \"junk.glb\"");
    let mut seed = 20u64;
    for len in [0, 1, 3, 11, 12, 19, 20, 64, 1000] {
        for magic in [false, true] {
            let mut bytes: Vec<u8> = (0..len)
                .map(|_| {
                    seed = seed
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    (seed >> 33) as u8
                })
                .collect();
            if magic && len >= 4 {
                bytes[..4].copy_from_slice(b"glTF");
            }
            let files = Files::default().with("g/junk.glb", bytes);
            assert_eq!(one_error(&source, &files).0, "E066", "{len} bytes");
        }
    }
    let obj = hut("mesh \"junk.obj\"");
    for text in [
        &b"\x00\xff\xfe garbage"[..],
        b"v 0 0 0\nv 1 0 0\nf 1 2 99\n",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\n",
        b"v nan 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n",
        b"f 1 2 3\n",
    ] {
        let files = Files::default().with("g/junk.obj", text);
        assert_eq!(
            one_error(&obj, &files).0,
            "E066",
            "{:?}",
            String::from_utf8_lossy(text)
        );
    }
}

#[test]
fn every_truncation_and_byte_flip_of_a_glb_is_an_error_or_a_mesh() {
    let glb = tower_glb();
    let source = hut("mesh \"tower.glb\"");
    for len in 0..glb.len() {
        let files = Files::default().with("g/tower.glb", &glb[..len]);
        assert_eq!(one_error(&source, &files).0, "E066", "cut at {len}");
    }
    for at in 0..glb.len() {
        let mut bytes = glb.clone();
        bytes[at] ^= 0xa5;
        let files = Files::default().with("g/tower.glb", bytes);
        if let Err(d) = compile(&source, &files) {
            let codes: Vec<_> = d.iter().map(|d| d.code).collect();
            assert!(
                codes == ["E066"] || codes == ["E067"],
                "byte {at}: {codes:?}"
            );
        }
    }
}

/// A glTF JSON asset of one triangle whose accessors declare `count` vertices and `indices`
/// corners.
fn declaring(count: u64, indices: u64) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
        "buffers":[{{"byteLength":44,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAAAAAAIC/AAABAAIAAAA="}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":8}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":{count},"type":"VEC3","min":[0,0,-1],"max":[1,0,0]}},
                     {{"bufferView":1,"componentType":5123,"count":{indices},"type":"SCALAR"}}]}}"#
    )
}

#[test]
fn huge_declared_counts_are_refused_before_anything_is_read() {
    let source = hut("mesh \"big.gltf\"");
    let ok = Files::default().with("g/big.gltf", declaring(3, 3));
    assert!(compile(&source, &ok).is_ok(), "the honest file reads");
    for (count, indices, code) in [
        (MAX_MESH_VERTICES as u64 + 1, 3, "E067"),
        (u32::MAX as u64, 3, "E067"),
        (3, 4_000_000_000, "E067"),
        // Within the limits but beyond the buffer: malformed.
        (1000, 3, "E066"),
        (3, 3000, "E066"),
    ] {
        let files = Files::default().with("g/big.gltf", declaring(count, indices));
        let (got, message, _) = one_error(&source, &files);
        assert_eq!(got, code, "{count} vertices, {indices} corners: {message}");
    }
}

#[test]
fn files_over_the_byte_limits_are_too_large() {
    let source = hut("mesh \"big.obj\"");
    let files = Files::default().with("g/big.obj", vec![b' '; MAX_MESH_BYTES + 1]);
    let (code, message, _) = one_error(&source, &files);
    assert_eq!(code, "E067", "{message}");
    // Five different 15 MiB files are more than the 64 MiB a grammar's assets may have.
    let mut files = Files::default();
    let mut stmts = String::new();
    for k in 0..5 {
        let mut obj = b"v 0 0 0\nv 1 0 0\nv 0 0 -1\nf 1 2 3\n".to_vec();
        obj.resize(15 << 20, b'\n');
        files = files.with(&format!("g/{k}.obj"), obj);
        stmts += &format!("mesh \"{k}.obj\"\n    ");
    }
    let d = compile(&hut(&stmts), &files).unwrap_err();
    let codes: Vec<_> = d.iter().map(|d| d.code).collect();
    assert_eq!(codes, ["E067"], "{d:?}");
}

#[test]
fn a_node_cycle_or_unknown_format_is_malformed() {
    let cyclic = r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],
        "nodes":[{"children":[1]},{"children":[0]}]}"#;
    let files = Files::default().with("g/loop.gltf", cyclic);
    assert_eq!(one_error(&hut("mesh \"loop.gltf\""), &files).0, "E066");
    assert_eq!(
        one_error(&hut("mesh \"tower.fbx\""), &Files::default()).0,
        "E066"
    );
    assert_eq!(
        one_error(&hut("mesh \"tower\""), &Files::default()).0,
        "E066"
    );
}

#[test]
fn an_asset_used_twice_is_read_once_and_reported_once() {
    let source = "piece a {\n    vertex p (0, 0)\n    vertex q (1, 0)\n    edges p-q\n    \
                  mesh \"gone.glb\"\n}\npiece b extends a {\n}\nmodel {\n    x = a\n    y = b at (3, 0)\n}\n";
    let d = compile(source, &Files::default()).unwrap_err();
    let codes: Vec<_> = d.iter().map(|d| d.code).collect();
    assert_eq!(codes, ["E064"]);
}

#[test]
fn a_mirrored_state_turns_the_triangles_round_and_keeps_the_heights() {
    let source = "site type s\npiece road {\n    vertex w (0, 0)\n    vertex e (2, 0)\n    vertex n (1, 1)\n    \
                  vertex s (1, -1)\n    edges w-e-n-w, w-s-e\n    site west: s [w] out (-1, 0)\n    \
                  site east: s [e] out (1, 0)\n    axis west -> east\n    mesh skinned \"cube.obj\"\n    \
                  state up {\n        w (0, 0)\n        e (2, 0)\n        n (1, 1.5)\n        s (1, -1.5)\n    }\n    \
                  state down mirror up\n}\nmodel {\n    r = road\n}\n";
    let files = Files::default().with("g/cube.obj", CUBE_OBJ);
    let g = compile(source, &files).unwrap();
    let shape = |s: usize| g.pieces[0].states[s].geometry[0].shape.clone();
    let (
        ProxyShape::Mesh {
            points: p0,
            heights: h0,
            triangles: t0,
        },
        ProxyShape::Mesh {
            points: p2,
            heights: h2,
            triangles: t2,
        },
    ) = (shape(0), shape(2))
    else {
        panic!()
    };
    assert_eq!(h0, h2);
    for (a, b) in p0.iter().zip(&p2) {
        assert!(
            (a.x - b.x).abs() < 1e-12 && (a.y + b.y).abs() < 1e-12,
            "{a} mirrors to {b}"
        );
    }
    assert_eq!(
        t2,
        t0.iter().map(|&[a, b, c]| [a, c, b]).collect::<Vec<_>>()
    );
}

#[test]
fn the_language_servers_analysis_reports_a_broken_asset_at_its_path() {
    let dir = std::env::temp_dir().join(format!("clay-mesh-analysis-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("tower.glb"), b"glTF\x02\0\0\0").unwrap();
    let source = hut("mesh \"tower.glb\"");
    let path = dir.join("hut.clay").to_string_lossy().into_owned();
    let a = clay_dsl::analysis::Analysis::new(&source, &path);
    let d: Vec<_> = a.diagnostics().iter().collect();
    assert_eq!(d.len(), 1, "{d:?}");
    assert_eq!(d[0].code, "E066");
    let at = source.find("\"tower.glb\"").unwrap();
    assert_eq!(d[0].primary.span.start, at);
    // `mesh` is a keyword there too: highlighted, offered in a piece, refused as a new name.
    assert!(clay_dsl::analysis::KEYWORDS.contains(&"mesh"));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn every_truncation_and_byte_flip_of_an_obj_or_gltf_json_is_an_error_or_a_mesh() {
    for (name, bytes) in [
        ("cube.obj", CUBE_OBJ.as_bytes().to_vec()),
        ("big.gltf", declaring(3, 3).into_bytes()),
    ] {
        let source = hut(&format!("mesh \"{name}\""));
        let path = format!("g/{name}");
        let mut variants: Vec<Vec<u8>> = (0..bytes.len()).map(|n| bytes[..n].to_vec()).collect();
        for at in 0..bytes.len() {
            for flip in [0x01u8, 0x20, 0xa5] {
                let mut b = bytes.clone();
                b[at] ^= flip;
                variants.push(b);
            }
        }
        for b in variants {
            let files = Files::default().with(&path, b.clone());
            if let Err(d) = compile(&source, &files) {
                let codes: Vec<_> = d.iter().map(|d| d.code).collect();
                // A flip in `data:` makes the buffer a file beside the asset, which is missing.
                let external =
                    codes == ["E064"] && d.iter().any(|d| d.message.contains("refers to"));
                assert!(
                    codes == ["E066"] || codes == ["E067"] || external,
                    "{name} {:?}: {codes:?}",
                    String::from_utf8_lossy(&b)
                );
            }
        }
    }
}

#[test]
fn every_number_of_a_gltf_replaced_by_an_odd_one_is_an_error_or_a_mesh() {
    // Indices, counts, offsets and lengths pointing anywhere: out of range, huge, negative.
    let text = declaring(3, 3);
    let source = hut("mesh \"big.gltf\"");
    let numbers: Vec<(usize, usize)> = {
        let b = text.as_bytes();
        let mut out = Vec::new();
        let mut i = 0;
        while i < b.len() {
            if b[i].is_ascii_digit() && (i == 0 || !b[i - 1].is_ascii_alphanumeric()) {
                let start = i;
                while i < b.len() && b[i].is_ascii_digit() {
                    i += 1;
                }
                out.push((start, i));
            }
            i += 1;
        }
        out
    };
    assert!(numbers.len() > 20);
    for &(start, end) in &numbers {
        for odd in [
            "0",
            "1",
            "2",
            "7",
            "4294967295",
            "18446744073709551615",
            "-1",
            "1e30",
        ] {
            let changed = format!("{}{odd}{}", &text[..start], &text[end..]);
            let files = Files::default().with("g/big.gltf", changed.clone());
            if let Err(d) = compile(&source, &files) {
                let codes: Vec<_> = d.iter().map(|d| d.code).collect();
                assert!(
                    codes == ["E066"] || codes == ["E067"],
                    "{changed}: {codes:?}"
                );
            }
        }
    }
}

/// Found by `tests/fuzz_assets.rs`: a relative normal or texture-coordinate index before the
/// first one (`f 1//-3`) or a huge one made tobj's index arithmetic overflow, a panic where
/// overflow is checked (debug builds, CI). Clay reads only positions, so those indices are not
/// read at all: the shape loads; a bad position index is still an error.
#[test]
fn face_normal_and_texture_indices_out_of_range_are_not_read() {
    let source = hut("mesh \"t.obj\"");
    let head = "v 0 0 0\nv 1 0 0\nv 0 0 -1\nvt 0 0\nvn 0 1 0\n";
    for faces in [
        "f 1//-3 2//1 3//1\n",
        "f 1/-3 2/1 3/1\n",
        "f 1/1/-2147483648 2/1/1 3/1/1\n",
        "f 1/6148914691236517206 2/1 3/1\n",
        "f\u{a0}1//-3 2//1 3//1\n",
        "l 1/-3 2/1\nf 1 2 3\n",
    ] {
        let files = Files::default().with("g/t.obj", format!("{head}{faces}"));
        let g = compile(&source, &files).unwrap_or_else(|d| panic!("{faces:?}: {d:?}"));
        let ProxyShape::Mesh { triangles, .. } = &g.pieces[0].states[0].geometry[0].shape else {
            panic!("a mesh proxy")
        };
        assert_eq!(triangles.len(), 1, "{faces:?}");
    }
    for faces in [
        "f 1//1 2//1 9//1\n",
        "f /1/1 2/1/1 3/1/1\n",
        "f 1/1 -9/1 3/1\n",
    ] {
        let files = Files::default().with("g/t.obj", format!("{head}{faces}"));
        assert_eq!(one_error(&source, &files).0, "E066", "{faces:?}");
    }
}

/// Found by `tests/fuzz_assets.rs`: a node's scale of 3e38 put a vertex at 6.8e38 m, finite in
/// the loader's f64 but not in the f32 of the renderer and the export, which wrote `inf`. An
/// asset's vertices are held to the coordinates a grammar may have (E066 beyond).
#[test]
fn a_vertex_beyond_the_coordinate_limit_is_malformed() {
    let source = hut("mesh \"big.gltf\"");
    let scaled = |s: &str| {
        declaring(3, 3).replace(
            r#""nodes":[{"mesh":0}]"#,
            &format!(r#""nodes":[{{"mesh":0,"scale":[{s},{s},{s}]}}]"#),
        )
    };
    assert_ne!(scaled("1"), declaring(3, 3));
    for s in ["3e38", "1e10", "-2e9"] {
        let files = Files::default().with("g/big.gltf", scaled(s));
        let (code, message, _) = one_error(&source, &files);
        assert_eq!(code, "E066", "scale {s}: {message}");
        assert!(message.contains("from the origin"), "{message}");
    }
    // At the limit itself the asset reads.
    let files = Files::default().with("g/big.gltf", scaled("1e9"));
    assert!(compile(&source, &files).is_ok());
    let far = "v 0 0 0\nv 1e10 0 0\nv 0 0 -1\nf 1 2 3\n";
    let files = Files::default().with("g/t.obj", far);
    assert_eq!(one_error(&hut("mesh \"t.obj\""), &files).0, "E066");
}
