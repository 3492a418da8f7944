//! `clayc export`: the assembly (initial, or after a sculpting script) as 3D meshes: glTF 2.0
//! (`.glb`, `.gltf`), Wavefront OBJ (`.obj` with its `.mtl` beside it) or USD (`.usda`).
//! docs/export.md.

use std::path::{Path, PathBuf};

use clay::{ExportFormat, ExportOptions, encode_export, mtl_path, scene};

use crate::out::{IO_ERROR, write_output};
use crate::params::ParamArgs;
use crate::render::sculpted;

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    Glb,
    Gltf,
    Obj,
    Usda,
}

#[derive(clap::Args)]
pub struct ExportArgs {
    #[command(flatten)]
    pub model: crate::from_session::ModelArgs,
    /// The file to write: .glb, .gltf, .obj (the .mtl is written beside an .obj) or .usda; `-` writes
    /// to standard output (glb unless --format says otherwise; an .obj's materials are then
    /// not written).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The format, when the output's extension does not say it.
    #[arg(long, value_enum)]
    pub format: Option<Format>,
    /// Replay this sculpting script first (on the session's sculpt, with --session) and export
    /// the assembly it ends with.
    #[arg(long)]
    pub script: Option<PathBuf>,
    /// Height given to flat proxy geometry, in metres.
    #[arg(long, default_value_t = ExportOptions::default().thickness, value_parser = parse_thickness)]
    pub thickness: f64,
    #[command(flatten)]
    pub params: ParamArgs,
}

/// `--thickness`: a number within the bound the library keeps (`ExportOptions::with_thickness`).
fn parse_thickness(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    ExportOptions::with_thickness(v).map(|o| o.thickness)
}

impl From<Format> for ExportFormat {
    fn from(f: Format) -> Self {
        match f {
            Format::Glb => ExportFormat::Glb,
            Format::Gltf => ExportFormat::Gltf,
            Format::Obj => ExportFormat::Obj,
            Format::Usda => ExportFormat::Usda,
        }
    }
}

pub fn export(args: ExportArgs) -> u8 {
    let to_stdout = args.output.as_os_str() == "-";
    let format = match (args.format.map(ExportFormat::from))
        .or_else(|| ExportFormat::of_path(&args.output))
    {
        Some(f) => f,
        None if to_stdout => ExportFormat::Glb,
        None if is_usdc(&args.output) && usdcat().is_some() => ExportFormat::Usda,
        None => {
            errln!(
                "error: cannot tell the format of `{}`: {}, or pass --format",
                args.output.display(),
                ExportFormat::unknown(&args.output)
            );
            if is_usdc(&args.output) {
                errln!("hint: with `usdcat` on the PATH, clayc export writes .usdc itself");
            }
            return IO_ERROR;
        }
    };
    let (grammar, assembly, _, _) = match sculpted(
        args.model.file.as_deref(),
        args.model.session.as_deref(),
        args.script.as_deref(),
        &args.params,
    ) {
        Ok(model) => model,
        Err(code) => return code,
    };
    // `parse_thickness` kept it within the library's bound
    let options = ExportOptions {
        thickness: args.thickness,
        ..ExportOptions::default()
    };
    let scene = scene(&grammar, &assembly, &options);
    if is_usdc(&args.output) && args.format.is_none() {
        return export_usdc(&scene, &args.output);
    }
    match encode_export(&scene, format, &args.output) {
        // the .obj first: a failed export leaves the .mtl beside it as it was (issue 47)
        Ok((bytes, materials)) => {
            let code = write_output(&args.output, &bytes);
            match materials {
                Some(m) if code == 0 && !to_stdout => write_output(&mtl_path(&args.output), &m),
                _ => code,
            }
        }
        Err(e) => {
            errln!("error: cannot encode the model: {e}");
            IO_ERROR
        }
    }
}

/// Whether `path` names USD's binary form.
fn is_usdc(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("usdc"))
}

/// `usdcat` on the `PATH` (a USD installation: Houdini, Omniverse, a USD build), which
/// converts the text form to the binary one; no Rust crate writes USD's crate format.
fn usdcat() -> Option<PathBuf> {
    let name = if cfg!(windows) {
        "usdcat.exe"
    } else {
        "usdcat"
    };
    std::env::split_paths(&std::env::var_os("PATH")?)
        .map(|dir| dir.join(name))
        .find(|p| p.is_file())
}

/// `.usdc`: the `.usda` export written beside the output, converted by `usdcat`, removed.
fn export_usdc(scene: &clay::Scene, output: &Path) -> u8 {
    let Some(usdcat) = usdcat() else {
        return IO_ERROR;
    };
    let text = output.with_extension("clay-export.usda");
    let bytes = match encode_export(scene, ExportFormat::Usda, &text) {
        Ok((bytes, _)) => bytes,
        Err(e) => {
            errln!("error: cannot encode the model: {e}");
            return IO_ERROR;
        }
    };
    let code = write_output(&text, &bytes);
    if code != 0 {
        return code;
    }
    let run = std::process::Command::new(&usdcat)
        .arg(&text)
        .arg("-o")
        .arg(output)
        .output();
    let _ = std::fs::remove_file(&text);
    match run {
        Ok(out) if out.status.success() && output.is_file() => 0,
        Ok(out) => {
            errln!(
                "error: `{}` could not convert the model to `{}`: {}",
                usdcat.display(),
                output.display(),
                String::from_utf8_lossy(&out.stderr).trim()
            );
            IO_ERROR
        }
        Err(e) => {
            errln!("error: cannot run `{}`: {e}", usdcat.display());
            IO_ERROR
        }
    }
}
