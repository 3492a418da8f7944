//! `clayc export`: the assembly (initial, or after a sculpting script) as 3D meshes: glTF 2.0
//! (`.glb`, `.gltf`) or Wavefront OBJ (`.obj` with its `.mtl` beside it). docs/export.md.

use std::path::{Path, PathBuf};

use clay::{ExportOptions, scene};

use crate::out::{IO_ERROR, write_output};
use crate::params::ParamArgs;
use crate::render::sculpted;

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    Glb,
    Gltf,
    Obj,
}

#[derive(clap::Args)]
pub struct ExportArgs {
    #[command(flatten)]
    pub model: crate::from_session::ModelArgs,
    /// The file to write: .glb, .gltf or .obj (the .mtl is written beside an .obj); `-` writes
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

fn parse_thickness(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if v.is_finite() && v > 0.0 && v <= 1000.0 {
        Ok(v)
    } else {
        Err(format!("{v} is not above 0 and at most 1000 metres"))
    }
}

fn format_of(path: &Path) -> Option<Format> {
    let ext = path.extension()?.to_str()?.to_ascii_lowercase();
    match ext.as_str() {
        "glb" => Some(Format::Glb),
        "gltf" => Some(Format::Gltf),
        "obj" => Some(Format::Obj),
        _ => None,
    }
}

pub fn export(args: ExportArgs) -> u8 {
    let to_stdout = args.output.as_os_str() == "-";
    let format = match args.format.or_else(|| format_of(&args.output)) {
        Some(f) => f,
        None if to_stdout => Format::Glb,
        None => {
            errln!(
                "error: cannot tell the format of `{}`: name it .glb, .gltf or .obj, or pass --format",
                args.output.display()
            );
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
    let options = ExportOptions {
        thickness: args.thickness,
        ..ExportOptions::default()
    };
    let scene = scene(&grammar, &assembly, &options);
    let bytes = match format {
        Format::Glb => clay::to_glb(&scene),
        Format::Gltf => clay::to_gltf(&scene),
        Format::Obj => {
            let mtl_path = args.output.with_extension("mtl");
            let mtl_name = mtl_path
                .file_name()
                .map_or("model.mtl".into(), |n| n.to_string_lossy().into_owned());
            let (obj_text, mtl_text) = clay::to_obj(&scene, &mtl_name);
            // the .obj first: a failed export leaves the .mtl beside it as it was (issue 47)
            let code = write_output(&args.output, obj_text.as_bytes());
            if code != 0 || to_stdout {
                return code;
            }
            return write_output(&mtl_path, mtl_text.as_bytes());
        }
    };
    match bytes {
        Ok(bytes) => write_output(&args.output, &bytes),
        Err(e) => {
            errln!("error: cannot encode the model: {e}");
            IO_ERROR
        }
    }
}
