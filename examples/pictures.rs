//! Writes the documentation pictures: for every grammar `grammars/NAME.clay`, its sheet
//! (`docs/pictures/NAME-sheet.png`) and a render of its initial assembly
//! (`docs/pictures/NAME.png`); with a demo script `grammars/NAME.script.json` and script replay
//! available, also the assembly after the script (`docs/pictures/NAME-after.png`).
//!
//! Run with `cargo run --release --example pictures`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clay::render::{Overlays, RenderOptions, render_png, sheet_png};
use std::sync::Arc;

use clay::assembly::Assembly;
use clay::rules::Rules;
use clay::script::{Script, replay};
use clay::solver::SolverConfig;
use clay_dsl::compiled::{AssemblyData, CompiledGrammar};

fn compile(source: &str, path: &Path) -> Result<CompiledGrammar, String> {
    // Name the grammar as a reader of the docs would type it (`grammars/wall.clay`), not by this
    // machine's absolute path: the name is printed in the sheet's title.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let name = path
        .strip_prefix(root)
        .unwrap_or(path)
        .display()
        .to_string();
    clay_dsl::compile(source, &name)
        .map(|c| c.grammar)
        .map_err(|d| clay_dsl::render(&d, source, &name, false))
}

/// The grammar and the assembly its demo script ends with (solver and rules, as `clayc run`).
fn after(
    grammar: CompiledGrammar,
    script: &Path,
) -> Result<(CompiledGrammar, AssemblyData), String> {
    let text = std::fs::read_to_string(script).map_err(|e| e.to_string())?;
    let script = Script::parse(&text).map_err(|e| e.to_string())?;
    let config = SolverConfig::from_params(&grammar.solver);
    let grammar = Arc::new(grammar);
    let mut assembly = Assembly::new(grammar.clone());
    replay(&mut assembly, &script, &config, &mut Rules::new()).map_err(|e| e.to_string())?;
    Ok(((*grammar).clone(), assembly.data))
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
        let grammar = match std::fs::read_to_string(path)
            .map_err(|e| e.to_string())
            .and_then(|s| compile(&s, path))
        {
            Ok(g) => g,
            Err(e) => {
                eprintln!("skipped {name}: {e}");
                failures += 1;
                continue;
            }
        };
        let overlays = Overlays {
            sites: true,
            ..Overlays::default()
        };
        let options = RenderOptions {
            width: 1200,
            height: 800,
            overlays,
            ..RenderOptions::default()
        };
        let pictures = [
            (format!("{name}-sheet.png"), sheet_png(&grammar)),
            (
                format!("{name}.png"),
                render_png(&grammar, &grammar.assembly, &options),
            ),
        ];
        for (file, png) in pictures {
            match png
                .map_err(|e| e.to_string())
                .and_then(|b| std::fs::write(out.join(&file), b).map_err(|e| e.to_string()))
            {
                Ok(()) => println!("wrote docs/pictures/{file}"),
                Err(e) => {
                    eprintln!("error: docs/pictures/{file}: {e}");
                    failures += 1;
                }
            }
        }
        let script = path.with_extension("script.json");
        if script.exists() {
            let file = format!("{name}-after.png");
            let written = after(grammar, &script)
                .and_then(|(g, a)| render_png(&g, &a, &options).map_err(|e| e.to_string()))
                .and_then(|b| std::fs::write(out.join(&file), b).map_err(|e| e.to_string()));
            match written {
                Ok(()) => println!("wrote docs/pictures/{file}"),
                Err(e) => {
                    eprintln!("error: docs/pictures/{file}: {e}");
                    failures += 1;
                }
            }
        }
    }
    if failures > 0 {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}
