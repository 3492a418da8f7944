//! `clayc run|render|export --session FILE.json` (issue 40): a sculpt saved in the session file
//! format (`clay::session_file`, what the editor writes) replayed headlessly by the real
//! binary. The export of a saved session is the export of the sculpted assembly itself; its
//! pins are held again, so a script after it moves the model around them; a malformed file is
//! an error naming the file, line and column, with a non-zero exit.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::Arc;

use clay::{
    Assembly, ExportOptions, HandleKind, Script, Session, SolverConfig, replay, scene,
    session_file, session_file::Pin, session_file::SavedSession as SessionFile,
    session_file::Settings,
};
use clay_dsl::compiled::CompiledGrammar;

const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/..");

fn clayc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_clayc"))
        .current_dir(ROOT)
        .args(args)
        .output()
        .unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "clay-session-file-cli-{}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn wall() -> (String, CompiledGrammar) {
    let source = std::fs::read_to_string(Path::new(ROOT).join("grammars/wall.clay")).unwrap();
    let grammar = clay_dsl::compile(&source, "wall.clay", &clay_dsl::CompileOptions::default())
        .unwrap()
        .grammar;
    (source, grammar)
}

/// The wall sculpted as a user would: its west end pinned, its east end pulled 6 m (the
/// stretch rule adds bricks), then let go.
fn sculpted(grammar: &CompiledGrammar) -> Assembly {
    let script = Script::parse(
        r#"{"steps": [
            {"pin": {"extreme": "west"}},
            {"grab": {"extreme": "east"}},
            {"drag": {"by": [6, 0], "frames": 60}},
            {"release": {}},
            {"hold": {"frames": 10}}
        ]}"#,
    )
    .unwrap();
    let mut asm = Assembly::new(Arc::new(grammar.clone()));
    let mut session = Session::new(SolverConfig::from_params(&grammar.solver));
    replay(&mut asm, &script, &mut session).unwrap();
    asm
}

/// The pins of `asm` as the editor saves them.
fn pins(asm: &Assembly) -> Vec<Pin> {
    (asm.handles().iter())
        .filter(|h| h.kind() == HandleKind::Pin)
        .map(|h| Pin {
            vertices: h.vertices().to_vec(),
            at: (0..h.vertices().len()).map(|k| h.target(k)).collect(),
        })
        .collect()
}

/// Writes the wall's grammar and a session of `asm` on it into `dir` (the grammar named
/// relative to the session file), as the library writes sessions.
fn save(dir: &Path, source: &str, grammar: &CompiledGrammar, asm: &Assembly) -> PathBuf {
    std::fs::create_dir_all(dir.join("grammars")).unwrap();
    std::fs::write(dir.join("grammars/wall.clay"), source).unwrap();
    std::fs::create_dir_all(dir.join("sessions")).unwrap();
    let path = dir.join("sessions/pulled.json");
    let settings = Settings {
        hysteresis: grammar.solver.hysteresis,
        norm: grammar.solver.norm,
        merge_distance: grammar.solver.merge_distance,
    };
    let saved = SessionFile::new(
        "../grammars/wall.clay".into(),
        asm.data().clone(),
        pins(asm),
        Some(settings),
    );
    session_file::write(&path, &saved).unwrap();
    path
}

fn gltf_json(bytes: &[u8]) -> serde_json::Value {
    serde_json::from_slice(bytes).unwrap()
}

fn nodes_with_instances(gltf: &serde_json::Value) -> Vec<(String, Vec<f64>)> {
    (gltf["nodes"].as_array().unwrap().iter())
        .filter_map(|n| {
            let name = n["extras"]["instance"].as_str()?.to_string();
            let t = (n["translation"].as_array()).map_or(vec![0.0; 3], |t| {
                t.iter().map(|x| x.as_f64().unwrap()).collect()
            });
            Some((name, t))
        })
        .collect()
}

#[test]
fn exporting_a_saved_session_exports_the_sculpted_assembly() {
    let (source, grammar) = wall();
    let asm = sculpted(&grammar);
    let instances = asm.data().instances.len();
    assert!(
        instances > grammar.assembly.instances.len(),
        "the pull stretched the wall: {instances} instances"
    );
    let dir = scratch("export");
    let session = save(&dir, &source, &grammar, &asm);
    let out_path = dir.join("pulled.gltf");
    let out = clayc(&[
        "export",
        "--session",
        session.to_str().unwrap(),
        "-o",
        out_path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let cli = gltf_json(&std::fs::read(&out_path).unwrap());

    let direct = scene(&grammar, asm.data(), &ExportOptions::default());
    let direct = gltf_json(&clay::testing::to_gltf(&direct).unwrap());
    let (cli_nodes, direct_nodes) = (nodes_with_instances(&cli), nodes_with_instances(&direct));
    assert_eq!(cli_nodes.len(), instances);
    assert_eq!(
        cli_nodes, direct_nodes,
        "the same instances at the same places"
    );
    assert_eq!(cli["nodes"], direct["nodes"]);
    assert_eq!(cli["buffers"], direct["buffers"], "the same geometry");

    // `run` reports the saved sculpt: its parts and vertices, no frame run.
    let out = clayc(&["run", "--session", session.to_str().unwrap(), "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(summary["frames"], 0);
    assert_eq!(summary["parts"], asm.data().parts.len());
    assert_eq!(summary["vertices"], asm.data().positions.len());
    assert_eq!(summary["pieces"]["brick"], instances);
}

#[test]
fn a_script_after_a_session_moves_the_model_around_its_pins() {
    let (source, grammar) = wall();
    let asm = sculpted(&grammar);
    assert_eq!(pins(&asm).len(), 1, "the west end is pinned");
    let dir = scratch("pins");
    let session = save(&dir, &source, &grammar, &asm);
    let script = dir.join("push.json");
    std::fs::write(
        &script,
        r#"{"steps": [
            {"grab": {"extreme": "east"}},
            {"drag": {"by": [-2, 1], "frames": 40}}
        ]}"#,
    )
    .unwrap();
    let export = |name: &str, with_script: bool| -> Vec<(String, Vec<f64>)> {
        let path = dir.join(name);
        let mut args = vec!["export", "--session", session.to_str().unwrap()];
        if with_script {
            args.extend(["--script", script.to_str().unwrap()]);
        }
        args.extend(["-o", path.to_str().unwrap()]);
        let out = clayc(&args);
        assert!(out.status.success(), "{}", stderr(&out));
        nodes_with_instances(&gltf_json(&std::fs::read(&path).unwrap()))
    };
    let before = export("before.gltf", false);
    let after = export("after.gltf", true);
    let place = |nodes: &[(String, Vec<f64>)], name: &str| -> Vec<f64> {
        (nodes.iter().find(|(n, _)| n == name))
            .unwrap_or_else(|| panic!("no node of {name}: {nodes:?}"))
            .1
            .clone()
    };
    let distance = |a: &[f64], b: &[f64]| -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y) * (x - y))
            .sum::<f64>()
            .sqrt()
    };
    // The pinned west brick stays where the session holds it; the grabbed east end moved.
    let (west, east) = (&before[0].0, &before[before.len() - 1].0);
    assert!(
        distance(&place(&before, west), &place(&after, west)) < 1e-3,
        "{west}: {:?} then {:?}",
        place(&before, west),
        place(&after, west)
    );
    // The script did move the model: the east brick (or the chain, if a rule rewrote it).
    let east_after = after.iter().find(|(n, _)| n == east);
    assert!(
        after.len() != before.len()
            || east_after.is_some_and(|(_, t)| distance(&place(&before, east), t) > 0.5),
        "{east} moved: {before:?} then {after:?}"
    );
}

#[test]
fn a_malformed_session_names_the_file_line_and_column() {
    let dir = scratch("malformed");
    let path = dir.join("broken.json");
    let shown = path.to_str().unwrap();
    for (text, says) in [
        (
            "{\n  \"format\": \"clay-session\",\n  \"version\": 1,\n  oops\n}\n",
            "line 4 column 3",
        ),
        (
            "{\n  \"format\": \"clay-session\",\n  \"version\": 1,\n  \"grammar\": 5\n}\n",
            "line 4 column 14",
        ),
        (
            "{\"format\": \"png\", \"version\": 1}",
            "\"format\" must be",
        ),
        (
            "{\"format\": \"clay-session\", \"version\": 9}",
            "version 9 is not supported",
        ),
    ] {
        std::fs::write(&path, text).unwrap();
        for sub in [
            vec!["run", "--session", shown],
            vec!["render", "--session", shown, "-o", "-"],
            vec!["export", "--session", shown, "-o", "-"],
        ] {
            let out = clayc(&sub);
            let err = stderr(&out);
            assert_eq!(out.status.code(), Some(1), "{sub:?}: {err}");
            assert!(err.contains(shown), "{sub:?}: {err}");
            assert!(err.contains(says), "{sub:?}: {err}");
            assert!(out.stdout.is_empty(), "{sub:?}");
        }
    }
}

#[test]
fn a_session_whose_grammar_is_missing_or_does_not_fit_is_refused() {
    let (source, grammar) = wall();
    let asm = sculpted(&grammar);
    let dir = scratch("misfit");
    let session = save(&dir, &source, &grammar, &asm);
    let shown = session.to_str().unwrap();

    // Vertices the grammar's pieces do not have.
    let mut saved = session_file::read(&session).unwrap();
    saved.assembly.instances[0].vertices[0] = 999_999;
    session_file::write(&session, &saved).unwrap();
    let out = clayc(&["export", "--session", shown, "-o", "-"]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("does not fit its grammar"), "{err}");

    // Positions of 1e308 (issue 47: they ran to an infinite energy with exit 0): refused,
    // the vertex named.
    let mut saved = session_file::read(&session).unwrap();
    saved.assembly.instances[0].vertices[0] = asm.data().instances[0].vertices[0];
    saved.assembly.positions[3].x = 1e308;
    session_file::write(&session, &saved).unwrap();
    for cmd in ["run", "export"] {
        let out = clayc(&[cmd, "--session", shown, "-o", "-"][..if cmd == "run" { 3 } else { 5 }]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{cmd}: {err}");
        assert!(err.contains("vertex 3 is at"), "{cmd}: {err}");
    }

    // An instance of a piece the grammar lacks, its parts to be derived again from it: refused,
    // without a panic.
    let mut saved = session_file::read(&session).unwrap();
    saved.assembly.positions[3].x = asm.data().positions[3].x;
    saved.assembly.instances[0].piece = 99;
    saved.assembly.parts.clear();
    session_file::write(&session, &saved).unwrap();
    let out = clayc(&["run", "--session", shown]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("does not fit its grammar"), "{err}");
    assert!(!err.contains("panicked"), "{err}");

    // The grammar is gone: an I/O error naming it.
    std::fs::remove_file(dir.join("grammars/wall.clay")).unwrap();
    let out = clayc(&["run", "--session", shown]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("wall.clay"), "{err}");

    // A grammar FILE and a session at once, or neither: a usage error.
    let out = clayc(&["run", "grammars/wall.clay", "--session", shown]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("--session"), "{}", stderr(&out));
    let out = clayc(&["export", "-o", "-"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
}

/// Four posts in a chain, `height` tall in 3D, a parameter.
const POSTS: &str = "param height = 1 in 0.5..3\n\nsite type joint\n\npiece post {\n    \
                     vertex sw (0, 0)\n    vertex se (1, 0)\n    vertex ne (1, 0.5)\n    \
                     vertex nw (0, 0.5)\n    edges sw-se-ne-nw-sw, sw-ne, se-nw\n    \
                     site west: joint [nw, sw] out (-1, 0)\n    site east: joint [se, ne] out (1, 0)\n    \
                     polygon fill #777777 extrude height { (0, 0) (1, 0) (1, 0.5) (0, 0.5) }\n}\n\n\
                     stretch post from west to east\n\nmodel {\n    row = chain post x 4\n}\n";

#[test]
fn a_session_compiles_its_grammar_with_the_parameters_it_was_saved_with() {
    let dir = scratch("params");
    std::fs::write(dir.join("posts.clay"), POSTS).unwrap();
    let options = clay_dsl::CompileOptions::default().param("height", 2.5);
    let grammar = clay_dsl::compile(POSTS, "posts.clay", &options)
        .unwrap()
        .grammar;
    let mut saved = SessionFile::new("posts.clay".into(), grammar.assembly.clone(), vec![], None);
    saved.params.insert("height".into(), 2.5.into());
    let path = dir.join("tall.json");
    session_file::write(&path, &saved).unwrap();
    let shown = path.to_str().unwrap();
    // The exported model's height: the largest y (up) of any accessor.
    let height = |extra: &[&str]| -> f64 {
        let mut args = vec!["export", "--session", shown, "-o", "-", "--format", "gltf"];
        args.extend_from_slice(extra);
        let out = clayc(&args);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        let doc = gltf_json(&out.stdout);
        (doc["accessors"].as_array().unwrap().iter())
            .filter_map(|a| a["max"].as_array().filter(|m| m.len() == 3))
            .map(|m| m[1].as_f64().unwrap())
            .fold(f64::MIN, f64::max)
    };

    // Compiled with the session's height 2.5, the posts are 2.5 m tall.
    assert!((height(&[]) - 2.5).abs() < 1e-6, "{}", height(&[]));
    // The same session without its parameters: the grammar's default, 1 m; `--param` gives
    // back what the session did not say.
    saved.params.clear();
    session_file::write(&path, &saved).unwrap();
    assert!((height(&[]) - 1.0).abs() < 1e-6, "{}", height(&[]));
    let h = height(&["--param", "height=2.5"]);
    assert!((h - 2.5).abs() < 1e-6, "{h}");
    let _ = std::fs::remove_dir_all(&dir);
}
