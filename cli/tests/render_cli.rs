//! `clayc render` and `clayc sheet` end to end: files written, formats picked by extension,
//! exit codes for bad input and I/O.

use std::path::PathBuf;
use std::process::Command;

use clay_dsl::compiled::{
    AssemblyData, Binding, CompiledGrammar, FORMAT_VERSION, Instance, Piece, Proxy, ProxyShape,
    RestState, Rgba, Site, SiteType, SolverParams,
};
use glam::DVec2;

/// A compiled grammar with one square piece with a site, and one instance of it.
fn grammar() -> CompiledGrammar {
    let corners: Vec<DVec2> = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
        .map(|(x, y)| DVec2::new(x, y))
        .to_vec();
    CompiledGrammar {
        format_version: FORMAT_VERSION,
        source: "square.clay".into(),
        solver: SolverParams::default(),
        params: Vec::new(),
        site_types: vec![SiteType {
            name: "joint".into(),
            docks_with: vec![0],
        }],
        pieces: vec![Piece {
            name: "square".into(),
            vertices: vec!["a".into(), "b".into(), "c".into(), "d".into()],
            edges: vec![[0, 1], [1, 2], [2, 3], [3, 0]],
            sites: vec![Site {
                name: "east".into(),
                site_type: 0,
                vertices: vec![1, 2],
                out: DVec2::X,
            }],
            states: vec![RestState {
                name: "base".into(),
                positions: corners.clone(),
                geometry: vec![Proxy {
                    shape: ProxyShape::Polygon {
                        outer: corners.clone(),
                        holes: vec![],
                    },
                    fill: Rgba([90, 120, 200, 255]),
                    binding: Binding::Rigid,
                    extrude: None,
                }],
                geometry_frame: 0,
            }],
            axis: None,
        }],
        stretch_rules: vec![],
        merge_rules: vec![],
        cut_rules: vec![],
        assembly: AssemblyData {
            positions: corners,
            instances: vec![Instance {
                id: 0,
                name: "s".into(),
                piece: 0,
                vertices: vec![0, 1, 2, 3],
                state: 0,
            }],
            docks: vec![],
            chains: vec![],
            parts: vec![],
            next_id: 1,
        },
    }
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("clay-render-cli-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn clayc(args: &[&str]) -> (u8, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_clayc"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(255) as u8,
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn render_and_sheet_write_png_and_svg() {
    let dir = scratch("ok");
    let json = dir.join("square.json");
    std::fs::write(&json, serde_json::to_string(&grammar()).unwrap()).unwrap();
    let j = json.to_str().unwrap();
    let png = dir.join("a.png");
    let (code, err) = clayc(&[
        "render",
        j,
        "-o",
        png.to_str().unwrap(),
        "--size",
        "200x100",
        "--overlay",
        "graph,sites,strain,states",
    ]);
    assert_eq!(code, 0, "{err}");
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let img = tiny_skia::Pixmap::decode_png(&bytes).unwrap();
    assert_eq!((img.width(), img.height()), (200, 100));

    let svg = dir.join("a.svg");
    assert_eq!(clayc(&["render", j, "-o", svg.to_str().unwrap()]).0, 0);
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && !text.contains("NaN"));

    let sheet = dir.join("sheet.png");
    assert_eq!(clayc(&["sheet", j, "-o", sheet.to_str().unwrap()]).0, 0);
    assert!(tiny_skia::Pixmap::decode_png(&std::fs::read(&sheet).unwrap()).is_ok());
    let forced = dir.join("sheet.png.out");
    assert_eq!(
        clayc(&["sheet", j, "-o", forced.to_str().unwrap(), "--svg"]).0,
        0
    );
    assert!(
        std::fs::read_to_string(&forced)
            .unwrap()
            .starts_with("<svg")
    );
}

#[test]
fn bad_input_and_io_give_the_documented_exit_codes() {
    let dir = scratch("bad");
    let out = dir.join("x.png");
    let o = out.to_str().unwrap();
    // A missing file is an I/O error.
    assert_eq!(clayc(&["render", "/nonexistent/x.clay", "-o", o]).0, 2);
    // A file that is not a compiled grammar is an input error.
    let junk = dir.join("junk.json");
    std::fs::write(&junk, "{\"not\": 1}").unwrap();
    assert_eq!(clayc(&["render", junk.to_str().unwrap(), "-o", o]).0, 1);
    // A bad size is a usage error.
    let good = dir.join("g.json");
    std::fs::write(&good, serde_json::to_string(&grammar()).unwrap()).unwrap();
    let g = good.to_str().unwrap();
    assert_eq!(clayc(&["render", g, "-o", o, "--size", "0x10"]).0, 2);
    assert_eq!(clayc(&["render", g, "-o", o, "--size", "wide"]).0, 2);
    // An unwritable output is an I/O error.
    assert_eq!(clayc(&["render", g, "-o", "/nonexistent/dir/x.png"]).0, 2);
    assert!(!out.exists());
}

/// Issue 47: a compiled grammar edited or corrupted after `build` (an index past its list, a
/// height of 1e300) is refused with every problem named, before anything uses it; it does not
/// panic `render` or `export`, and no file is written.
#[test]
fn a_corrupted_compiled_grammar_is_refused_with_its_problems() {
    let dir = scratch("corrupt");
    let png = dir.join("x.png");
    let glb = dir.join("x.glb");
    // the pieces' problems are named first (the model is read through them), then the model's
    let mut pieces = grammar();
    pieces.pieces[0].edges.push([0, 9]);
    if let ProxyShape::Polygon { outer, .. } = &mut pieces.pieces[0].states[0].geometry[0].shape {
        outer[1].x = 1e300;
    }
    let mut model = grammar();
    model.assembly.instances[0].vertices[2] = 40;
    for (g, names) in [(pieces, ["edge", "beyond"]), (model, ["instance", "40"])] {
        let json = dir.join("corrupt.json");
        std::fs::write(&json, serde_json::to_string(&g).unwrap()).unwrap();
        let j = json.to_str().unwrap();
        for (args, out) in [
            (vec!["render", j, "-o", png.to_str().unwrap()], &png),
            (vec!["export", j, "-o", glb.to_str().unwrap()], &glb),
        ] {
            let (code, stderr) = clayc(&args);
            assert_eq!(code, 1, "{args:?}: {stderr}");
            assert!(
                stderr.contains("is not a compiled grammar Clay can use"),
                "{stderr}"
            );
            for name in names {
                assert!(stderr.contains(name), "`{name}` named: {stderr}");
            }
            assert!(stderr.contains("clayc build"), "a hint: {stderr}");
            assert!(!stderr.contains("panicked"), "{stderr}");
            assert!(!out.exists(), "{} written", out.display());
        }
    }
}
