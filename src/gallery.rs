//! The documentation's pictures of one grammar, made by code so they never show what the code
//! no longer does: its sheet (every piece in every rest state), its initial assembly and, with
//! a demo script, the assembly after the script (solver and rules, as `clayc run`).
//! `examples/pictures.rs` writes them into `docs/pictures/`; `tests/doc_pictures.rs` fails
//! when the files there no longer match what this draws.

use std::sync::Arc;

use clay_dsl::compiled::CompiledGrammar;

use crate::assembly::Assembly;
use crate::render::{Overlays, RenderOptions, render_png, sheet_png};
use crate::script::Script;
use crate::session::{Session, replay};
use crate::solver::SolverConfig;

/// One picture: its file name in `docs/pictures/` and its PNG bytes.
#[derive(Clone, Debug, PartialEq)]
pub struct Picture {
    pub file: String,
    pub png: Vec<u8>,
}

/// The render settings of the documentation pictures (docking sites shown).
fn options() -> RenderOptions {
    RenderOptions {
        width: 1200,
        height: 800,
        overlays: Overlays {
            sites: true,
            ..Overlays::default()
        },
        ..RenderOptions::default()
    }
}

/// `NAME-sheet.png`, `NAME.png` and, with `script`, `NAME-after.png` for the grammar `name`.
pub fn pictures(
    name: &str,
    grammar: &CompiledGrammar,
    script: Option<&Script>,
) -> Result<Vec<Picture>, String> {
    let options = options();
    let mut out = vec![
        Picture {
            file: format!("{name}-sheet.png"),
            png: sheet_png(grammar).map_err(|e| e.to_string())?,
        },
        Picture {
            file: format!("{name}.png"),
            png: render_png(grammar, &grammar.assembly, &options).map_err(|e| e.to_string())?,
        },
    ];
    if let Some(script) = script {
        let config = SolverConfig::from_params(&grammar.solver);
        let mut assembly = Assembly::new(Arc::new(grammar.clone()));
        replay(&mut assembly, script, &mut Session::new(config)).map_err(|e| e.to_string())?;
        out.push(Picture {
            file: format!("{name}-after.png"),
            png: render_png(grammar, assembly.data(), &options).map_err(|e| e.to_string())?,
        });
    }
    Ok(out)
}
