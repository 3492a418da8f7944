//! The architecture invariants of `docs/architecture.md` that a reading of the source can
//! check: no import cycle between the modules of a crate, the editor uses only the library's
//! surfaces (the session, rendering, authoring, and the solver's settings and report types),
//! rules never import sessions or scripts, protocol types stay in the language server, a
//! solver frame changes no part, instance or connection, and the libraries print nothing.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The module path of a file under `src` (`solver/mod.rs` -> `solver`, `rules/cut.rs` ->
/// `rules::cut`, `lib.rs` -> ``).
fn module_of(src: &Path, file: &Path) -> String {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut parts: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if parts
        .last()
        .is_some_and(|l| l == "mod" || l == "lib" || l == "main")
    {
        parts.pop();
    }
    parts.join("::")
}

/// Every `crate::a::b` a file names (in `use` lines and paths), as the longest known module.
fn uses(text: &str, modules: &BTreeSet<String>) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (i, _) in text.match_indices("crate::") {
        let rest = &text[i + "crate::".len()..];
        let path: String = rest
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':')
            .collect();
        let segs: Vec<&str> = path.split("::").filter(|s| !s.is_empty()).collect();
        for n in (1..=segs.len()).rev() {
            let m = segs[..n].join("::");
            if modules.contains(&m) {
                out.insert(m);
                break;
            }
        }
    }
    out
}

/// The file-level import graph of a crate's `src` (test modules left out).
fn graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    files.retain(|f| !f.starts_with(src.join("bin")));
    let modules: BTreeSet<String> = files.iter().map(|f| module_of(src, f)).collect();
    let mut g = BTreeMap::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let text = text.split("#[cfg(test)]").next().unwrap_or("");
        // Code only: a doc link to another module is no import.
        let text: String = text
            .lines()
            .filter(|l| !l.trim_start().starts_with("//"))
            .collect::<Vec<_>>()
            .join("\n");
        let text = text.as_str();
        let m = module_of(src, f);
        let mut to = uses(text, &modules);
        // `super::x` names a sibling module.
        let parent = m
            .rsplit_once("::")
            .map_or(String::new(), |(p, _)| p.to_string());
        let base = if f.ends_with("mod.rs") {
            m.clone()
        } else {
            parent
        };
        for (i, _) in text.match_indices("super::") {
            let name: String = text[i + 7..]
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            let up = base
                .rsplit_once("::")
                .map_or(String::new(), |(p, _)| p.to_string());
            let sibling = if up.is_empty() {
                name.clone()
            } else {
                format!("{up}::{name}")
            };
            if modules.contains(&sibling) {
                to.insert(sibling);
            } else if !up.is_empty() || modules.contains(&up) {
                to.insert(up);
            }
        }
        // A module may name its parent (re-exports) and its children; only edges between
        // modules that are not one inside the other can make a cycle worth a name.
        to.retain(|t| {
            !(t.is_empty()
                || t == &m
                || m.starts_with(&format!("{t}::"))
                || t.starts_with(&format!("{m}::")))
        });
        g.insert(m, to);
    }
    g
}

fn cycle(g: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        n: &str,
        g: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(n.to_string(), 1);
        stack.push(n.to_string());
        for m in g.get(n).into_iter().flatten() {
            match state.get(m.as_str()).copied().unwrap_or(0) {
                1 => {
                    let at = stack.iter().position(|s| s == m).unwrap();
                    return Some(stack[at..].to_vec());
                }
                0 => {
                    if let Some(c) = visit(m, g, state, stack) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(n.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in g.keys() {
        if state.get(n.as_str()).copied().unwrap_or(0) == 0 {
            let mut stack = Vec::new();
            if let Some(c) = visit(n, g, &mut state, &mut stack) {
                return Some(c);
            }
        }
    }
    None
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn no_module_imports_one_that_imports_it_back() {
    for src in ["src", "dsl/src"] {
        let g = graph(&root().join(src));
        assert!(g.len() > 5, "{src}: only {} modules read", g.len());
        if let Some(c) = cycle(&g) {
            panic!("{src}: an import cycle: {}", c.join(" -> "));
        }
        // The same between the crate's top-level modules (`rules::cut` counts as `rules`).
        let mut top: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        let first = |m: &str| m.split("::").next().unwrap_or("").to_string();
        for (m, to) in &g {
            let entry = top.entry(first(m)).or_default();
            entry.extend(to.iter().map(|t| first(t)).filter(|t| *t != first(m)));
        }
        if let Some(c) = cycle(&top) {
            panic!(
                "{src}: an import cycle between top-level modules: {}",
                c.join(" -> ")
            );
        }
    }
}

#[test]
fn rules_know_nothing_of_sessions_and_scripts() {
    let g = graph(&root().join("src"));
    for (m, to) in &g {
        if m == "rules" || m.starts_with("rules::") || m == "solver" || m.starts_with("solver::") {
            for t in to {
                assert!(
                    !["session", "script", "summary", "gallery"].contains(&t.as_str()),
                    "{m} imports {t}"
                );
            }
        }
    }
}

#[test]
fn the_editor_uses_the_librarys_surfaces_only() {
    let mut files = Vec::new();
    rust_files(&root().join("editor/src"), &mut files);
    let allowed_solver = ["FrameReport", "SolverConfig", "SolverError"];
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        assert!(
            !text.contains("clay::rules::"),
            "{} reaches into the rules (use clay::session)",
            f.display()
        );
        for (i, _) in text.match_indices("clay::solver::") {
            let rest = &text[i + "clay::solver::".len()..];
            let names: String = rest.chars().take_while(|c| *c != ';').collect();
            for name in names
                .trim_matches(|c| c == '{' || c == '}')
                .split(',')
                .map(str::trim)
                .filter(|n| !n.is_empty())
            {
                assert!(
                    allowed_solver.contains(&name.trim_matches(|c| c == '{' || c == '}')),
                    "{} uses the solver's `{name}` (only its settings and report types are \
                     the editor's)",
                    f.display()
                );
            }
        }
    }
}

#[test]
fn protocol_types_live_only_in_the_language_server() {
    let server = root().join("src/bin/clayc/lsp");
    let mut files = Vec::new();
    for dir in ["src", "dsl/src", "editor/src"] {
        rust_files(&root().join(dir), &mut files);
    }
    let outside: Vec<&PathBuf> = files.iter().filter(|f| !f.starts_with(&server)).collect();
    assert!(outside.len() > 20, "only {} files read", outside.len());
    for f in outside {
        let text = std::fs::read_to_string(f).unwrap();
        for name in ["lsp_types", "lsp_server"] {
            assert!(
                !text.contains(name),
                "{} names `{name}`: protocol types belong in src/bin/clayc/lsp",
                f.display()
            );
        }
    }
    for manifest in ["dsl/Cargo.toml", "editor/Cargo.toml"] {
        let text = std::fs::read_to_string(root().join(manifest)).unwrap();
        assert!(
            !text.contains("lsp-"),
            "{manifest} depends on a protocol crate"
        );
    }
}

/// The structure of an assembly a solver frame must leave alone: its parts (all but the
/// active state), its instances (all but the state shown), docks and chains.
fn structure(data: &clay_dsl::compiled::AssemblyData) -> String {
    let parts: Vec<_> = (data.parts.iter())
        .map(|p| (p.kind, &p.vertices, &p.edges, &p.states))
        .collect();
    let instances: Vec<_> = (data.instances.iter())
        .map(|i| (i.id, &i.name, i.piece, &i.vertices))
        .collect();
    format!(
        "{parts:?}\n{instances:?}\n{:?}\n{:?}\n{}",
        data.docks,
        data.chains,
        data.positions.len()
    )
}

/// Architecture Invariant: the solver moves vertices and picks rest states; only the rules
/// change what the assembly is made of. Frames that stretch, squeeze, bend and let go of the
/// example models (where the rules would rewrite them) leave parts, instances and connections
/// as they were.
#[test]
fn a_solver_frame_changes_no_part_instance_or_connection() {
    use clay::assembly::{Assembly, Compass, HandleKind};
    use clay::solver::{Solver, SolverConfig};
    use glam::DVec2;
    let mut models = Vec::new();
    for name in [
        "wall.clay",
        "bend.clay",
        "castle.clay",
        "junction.clay",
        "centipede.clay",
    ] {
        let path = root().join("grammars").join(name);
        let Ok(text) = std::fs::read_to_string(&path) else {
            continue;
        };
        let compiled = clay_dsl::compile(&text, &path.to_string_lossy()).unwrap();
        models.push((name, compiled.grammar));
    }
    assert!(models.len() >= 3, "the example grammars are read");
    for (name, grammar) in models {
        let mut asm = Assembly::new(std::sync::Arc::new(grammar));
        let before = structure(asm.data());
        let mut solver = Solver::new(SolverConfig::from_params(&asm.grammar().solver));
        let west = asm.part_extreme(Compass::West).unwrap();
        let east = asm.part_extreme(Compass::East).unwrap();
        asm.hold_part(west, HandleKind::Pin).unwrap();
        let grab = asm.hold_part(east, HandleKind::Grab).unwrap();
        let size = clay::solver::bbox_diagonal(&asm.data().positions);
        let moves = [
            (DVec2::new(size, 0.0), 0.0),
            (DVec2::new(-0.8 * size, 0.0), 0.0),
            (DVec2::new(0.0, 0.5 * size), 1.2),
        ];
        for (translation, angle) in moves {
            let h = asm.handle_mut(grab).unwrap();
            h.translation = translation;
            h.angle = angle;
            for _ in 0..20 {
                solver.frame(&mut asm).unwrap();
                assert_eq!(structure(asm.data()), before, "{name}");
            }
        }
        asm.release(grab);
        for _ in 0..40 {
            solver.frame(&mut asm).unwrap();
        }
        assert_eq!(structure(asm.data()), before, "{name}");
    }
}

/// Architecture Invariant: the libraries (`clay` outside its binaries, `clay-dsl`) never
/// write to the terminal; they return text and diagnostics, and the binaries (and the editor)
/// decide where they go. Whole files are read, tests included.
#[test]
fn the_libraries_print_nothing() {
    let bin = root().join("src/bin");
    let mut files = Vec::new();
    for dir in ["src", "dsl/src"] {
        rust_files(&root().join(dir), &mut files);
    }
    files.retain(|f| !f.starts_with(&bin));
    assert!(files.len() > 40, "only {} files read", files.len());
    let writers = [
        "println!",
        "eprintln!",
        "print!(",
        "eprint!(",
        "dbg!(",
        "io::stdout",
        "io::stderr",
        "stdout()",
        "stderr()",
        "BufferWriter",
        "StandardStream",
    ];
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            for w in writers {
                assert!(
                    !code.contains(w),
                    "{}:{}: `{w}` in a library: return the text and let the binary print it",
                    f.display(),
                    n + 1
                );
            }
        }
    }
}
