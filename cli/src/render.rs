//! `clayc render` and `clayc sheet`: load a grammar, draw its assembly (or every piece and rest
//! state) with the renderer, and write a PNG or SVG file (`-o -`: standard output).

use std::path::{Path, PathBuf};

use std::sync::Arc;

use crate::out;
use crate::params::ParamArgs;

use clay::{
    Assembly, HandleKind, Overlays, RenderOptions, Script, Session, SolverConfig, render_png,
    render_svg, sheet_png, sheet_svg,
};
use clay_dsl::compiled::{AssemblyData, CompiledGrammar};

/// An overlay that `--overlay` can ask for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum OverlayKind {
    /// The edges and vertices of every part.
    Graph,
    /// Docking sites coloured by type, with out arrows on free sites.
    Sites,
    /// Part edges coloured by strain |len / rest_len - 1|.
    Strain,
    /// The script's handles and pins.
    Handles,
    /// The active rest state of parts that have alternatives.
    States,
}

#[derive(clap::Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub model: crate::from_session::ModelArgs,
    /// The picture to write (.png, or .svg for SVG; `-` writes PNG, or SVG with --svg, to
    /// standard output).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Replay this sculpting script first (on the session's sculpt, with --session) and render
    /// the assembly it ends with.
    #[arg(long)]
    pub script: Option<PathBuf>,
    /// Image size in pixels.
    #[arg(long, default_value = "1024x768", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Overlays to draw, comma separated.
    #[arg(long, value_delimiter = ',')]
    pub overlay: Vec<OverlayKind>,
    /// Write SVG whatever the output's extension.
    #[arg(long)]
    pub svg: bool,
    /// `plan` (from above, with overlays) or `iso` (an isometric view of the 3D export: heights
    /// shown, PNG only, no overlays).
    #[arg(long, value_enum, default_value_t = ViewKind::Plan)]
    pub view: ViewKind,
    #[command(flatten)]
    pub params: ParamArgs,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ViewKind {
    Plan,
    Iso,
}

#[derive(clap::Args)]
pub struct SheetArgs {
    /// A grammar (.clay) or a compiled grammar (.json from `clayc build`).
    pub file: PathBuf,
    /// The picture to write (.png, or .svg for SVG; `-` writes PNG, or SVG with --svg, to
    /// standard output).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Write SVG whatever the output's extension.
    #[arg(long)]
    pub svg: bool,
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, got `{s}`"))?;
    let side = |v: &str| -> Result<u32, String> {
        let n: u32 = v
            .trim()
            .parse()
            .map_err(|_| format!("`{v}` is not a whole number of pixels"))?;
        if (1..=clay::MAX_SIDE).contains(&n) {
            Ok(n)
        } else {
            Err(format!("{n} is not between 1 and {}", clay::MAX_SIDE))
        }
    };
    Ok((side(w)?, side(h)?))
}

/// Exit codes: 1 the input has errors, 2 usage or I/O.
const INPUT_ERROR: u8 = 1;
use crate::out::IO_ERROR;

/// Loads and compiles a grammar with the parameter values `params`; on failure prints why and
/// gives the exit code. A compiled grammar (.json) has its parameters' values already: giving
/// it `--param` is a usage error.
pub(crate) fn load(path: &Path, params: &ParamArgs) -> Result<CompiledGrammar, u8> {
    let json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    let limit = if json {
        clay_dsl::MAX_DATA_BYTES
    } else {
        clay_dsl::MAX_SOURCE_BYTES
    };
    let source = clay_dsl::read_input_string(path, limit).map_err(|e| {
        errln!("error: cannot read {}: {e}", path.display());
        IO_ERROR
    })?;
    if json {
        if !params.is_empty() {
            errln!(
                "error: --param sets the parameters of a grammar (.clay) as it is compiled; {} is \
                 compiled already (build it again with `clayc build --param`)",
                path.display()
            );
            return Err(IO_ERROR);
        }
        let grammar: CompiledGrammar = serde_json::from_str(&source).map_err(|e| {
            errln!("error: {} is not a compiled grammar: {e}", path.display());
            INPUT_ERROR
        })?;
        // read back, not compiled: every index and number checked before anything uses it
        let problems = grammar.problems();
        if !problems.is_empty() {
            errln!(
                "error: {} is not a compiled grammar Clay can use:\n  {}",
                path.display(),
                problems.join("\n  ")
            );
            errln!("  = help: build it again from its .clay with `clayc build`");
            return Err(INPUT_ERROR);
        }
        return Ok(grammar);
    }
    crate::params::compile(&source, path, params)
}

/// The model to draw or export: the grammar (`file`, or the one a saved `session` names) and
/// its assembly (the initial one, or the session's), after the sculpting `script` if one is
/// given (solver and rules, as `clayc run` does); with the global vertices of its grab
/// handles and of its pins. On failure prints why and gives the exit code.
pub(crate) fn sculpted(
    file: Option<&Path>,
    session: Option<&Path>,
    script: Option<&Path>,
    params: &ParamArgs,
) -> Result<(CompiledGrammar, AssemblyData, Vec<usize>, Vec<usize>), u8> {
    let (grammar, mut assembly, config) = match (session, file) {
        (Some(session), _) => {
            let loaded = crate::from_session::load(session, params, &[])?;
            (loaded.grammar, loaded.assembly, loaded.config)
        }
        (None, Some(file)) => {
            let grammar = load(file, params)?;
            if script.is_none() {
                let initial = grammar.assembly.clone();
                return Ok((grammar, initial, Vec::new(), Vec::new()));
            }
            let config = SolverConfig::from_params(&grammar.solver);
            let assembly = Assembly::new(Arc::new(grammar.clone()));
            (grammar, assembly, config)
        }
        (None, None) => {
            errln!("error: name a grammar FILE or a --session");
            return Err(IO_ERROR);
        }
    };
    if let Some(path) = script {
        let text = clay_dsl::read_input_string(path, clay_dsl::MAX_SOURCE_BYTES).map_err(|e| {
            errln!("error: cannot read {}: {e}", path.display());
            IO_ERROR
        })?;
        let script = Script::parse(&text).map_err(|e| {
            errln!("{}", e.located(path));
            INPUT_ERROR
        })?;
        if let Err(why) = script.check_params(assembly.grammar()) {
            errln!("error: {}: {why}", path.display());
            return Err(INPUT_ERROR);
        }
        if let Err(e) = clay::replay(&mut assembly, &script, &mut Session::new(config)) {
            errln!("error: {}: {e}", path.display());
            return Err(INPUT_ERROR);
        }
    }
    let vertices = |kind: HandleKind| -> Vec<usize> {
        assembly
            .handles()
            .iter()
            .filter(|h| h.kind() == kind)
            .flat_map(|h| h.vertices().iter().copied())
            .collect()
    };
    let (handles, pins) = (vertices(HandleKind::Grab), vertices(HandleKind::Pin));
    Ok((grammar, assembly.into_data(), handles, pins))
}

fn wants_svg(output: &Path, flag: bool) -> bool {
    flag || output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("svg"))
}

pub fn render(args: RenderArgs) -> u8 {
    if args.view == ViewKind::Iso && (wants_svg(&args.output, args.svg) || !args.overlay.is_empty())
    {
        errln!("error: the iso view is a PNG without overlays: drop --svg, .svg and --overlay");
        return IO_ERROR;
    }
    let (grammar, assembly, handles, pins) = match sculpted(
        args.model.file.as_deref(),
        args.model.session.as_deref(),
        args.script.as_deref(),
        &args.params,
    ) {
        Ok(model) => model,
        Err(code) => return code,
    };
    if args.view == ViewKind::Iso {
        let scene = clay::scene(&grammar, &assembly, &Default::default());
        let png = clay::iso_pixmap(&scene, args.size.0, args.size.1).and_then(|p| {
            p.encode_png()
                .map_err(|e| clay::RenderError::Encode(e.to_string()))
        });
        return match png {
            Ok(png) => out::write_output(&args.output, &png),
            Err(e) => {
                errln!("error: {e}");
                IO_ERROR
            }
        };
    }
    let has = |k: OverlayKind| args.overlay.contains(&k);
    let overlays = Overlays {
        part_graph: has(OverlayKind::Graph),
        sites: has(OverlayKind::Sites),
        strain: has(OverlayKind::Strain),
        states: has(OverlayKind::States),
        handles: if has(OverlayKind::Handles) {
            handles
        } else {
            Vec::new()
        },
        pins: if has(OverlayKind::Handles) {
            pins
        } else {
            Vec::new()
        },
    };
    let options = RenderOptions {
        width: args.size.0,
        height: args.size.1,
        overlays,
        ..RenderOptions::default()
    };
    if wants_svg(&args.output, args.svg) {
        return out::write_output(
            &args.output,
            render_svg(&grammar, &assembly, &options).as_bytes(),
        );
    }
    match render_png(&grammar, &assembly, &options) {
        Ok(png) => out::write_output(&args.output, &png),
        Err(e) => {
            errln!("error: {e}");
            IO_ERROR
        }
    }
}

pub fn sheet(args: SheetArgs) -> u8 {
    let grammar = match load(&args.file, &ParamArgs::default()) {
        Ok(g) => g,
        Err(code) => return code,
    };
    if wants_svg(&args.output, args.svg) {
        return out::write_output(&args.output, sheet_svg(&grammar).as_bytes());
    }
    match sheet_png(&grammar) {
        Ok(png) => out::write_output(&args.output, &png),
        Err(e) => {
            errln!("error: {e}");
            IO_ERROR
        }
    }
}
