//! The documentation's pictures of one grammar, made by code so they never show what the code
//! no longer does: its sheet (every piece in every rest state), its initial assembly and, with
//! a demo script, the assembly after the script (solver and rules, as `clayc run`); and for a
//! grammar with heights (`extrude`), the same two assemblies in the isometric 3D view.
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

/// `NAME-sheet.png`, `NAME.png` and, with `script`, `NAME-after.png` for the grammar `name`;
/// with heights also `NAME-iso.png` (and `NAME-iso-after.png`).
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
    let three_d = grammar
        .pieces
        .iter()
        .flat_map(|p| &p.states)
        .flat_map(|s| &s.geometry)
        .any(|g| g.extrude.is_some());
    let iso = |assembly: &clay_dsl::compiled::AssemblyData| -> Result<Vec<u8>, String> {
        let scene = crate::export::scene(grammar, assembly, &Default::default());
        crate::export::iso::iso_pixmap(&scene, options.width, options.height)
            .map_err(|e| e.to_string())?
            .encode_png()
            .map_err(|e| e.to_string())
    };
    if three_d {
        out.push(Picture {
            file: format!("{name}-iso.png"),
            png: iso(&grammar.assembly)?,
        });
    }
    if let Some(script) = script {
        let config = SolverConfig::from_params(&grammar.solver);
        let mut assembly = Assembly::new(Arc::new(grammar.clone()));
        replay(&mut assembly, script, &mut Session::new(config)).map_err(|e| e.to_string())?;
        out.push(Picture {
            file: format!("{name}-after.png"),
            png: render_png(grammar, assembly.data(), &options).map_err(|e| e.to_string())?,
        });
        if three_d {
            out.push(Picture {
                file: format!("{name}-iso-after.png"),
                png: iso(assembly.data())?,
            });
        }
    }
    Ok(out)
}
