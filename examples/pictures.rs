//! Writes the documentation pictures ([`clay::testing::gallery`]): for every grammar
//! `grammars/NAME.clay`, its sheet (`docs/pictures/NAME-sheet.png`), a render of its initial
//! assembly (`docs/pictures/NAME.png`) and, with a demo script `grammars/NAME.script.json`,
//! the assembly after the script (`docs/pictures/NAME-after.png`). `tests/doc_pictures.rs`
//! fails when the files no longer match.
//!
//! Run with `cargo run --release --example pictures`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clay::Script;
use clay_dsl::compiled::CompiledGrammar;

fn compile(source: &str, path: &Path) -> Result<CompiledGrammar, String> {
    // Name the grammar as a reader of the docs would type it (`grammars/wall.clay`), not by this
    // machine's absolute path: the name is printed in the sheet's title.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let name = path
        .strip_prefix(root)
        .unwrap_or(path)
        .display()
        .to_string();
    clay_dsl::compile(source, &name, &clay_dsl::CompileOptions::default())
        .map(|c| c.grammar)
        .map_err(|d| clay_dsl::render(&d, source, &name, false))
}

/// The pictures of the grammar at `path`, with its demo script if it has one.
fn pictures(path: &Path, name: &str) -> Result<Vec<clay::testing::gallery::Picture>, String> {
    let source = std::fs::read_to_string(path).map_err(|e| e.to_string())?;
    let grammar = compile(&source, path)?;
    let script_path = path.with_extension("script.json");
    let script = if script_path.exists() {
        let text = std::fs::read_to_string(&script_path).map_err(|e| e.to_string())?;
        Some(Script::parse(&text).map_err(|e| e.to_string())?)
    } else {
        None
    };
    clay::testing::gallery::pictures(name, &grammar, script.as_ref())
}

fn main() -> ExitCode {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = root.join("docs/pictures");
    if let Err(e) = std::fs::create_dir_all(&out) {
        eprintln!("error: cannot create {}: {e}", out.display());
        return ExitCode::from(2);
    }
    let mut grammars: Vec<PathBuf> = match std::fs::read_dir(root.join("grammars")) {
        Ok(dir) => dir
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "clay"))
            .collect(),
        Err(e) => {
            eprintln!("error: cannot list grammars/: {e}");
            return ExitCode::from(2);
        }
    };
    grammars.sort();
    let mut failures = 0;
    for path in &grammars {
        let name = path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("grammar");
        match pictures(path, name) {
            Ok(pictures) => {
                for p in pictures {
                    match std::fs::write(out.join(&p.file), &p.png) {
                        Ok(()) => println!("wrote docs/pictures/{}", p.file),
                        Err(e) => {
                            eprintln!("error: docs/pictures/{}: {e}", p.file);
                            failures += 1;
                        }
                    }
                }
            }
            Err(e) => {
                eprintln!("error: {name}: {e}");
                failures += 1;
            }
        }
    }
    if failures > 0 {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}
