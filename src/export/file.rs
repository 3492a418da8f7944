//! Export files: the format a path names, the thickness a user may ask for, and the writing of
//! an export (the `.obj` before its `.mtl`, each atomically). One home for what `clayc export`,
//! the editor's Export and Python's `Session.export` each parsed and wrote on their own.

use std::path::{Path, PathBuf};

use super::model::{ExportOptions, Scene};
use super::{gltf, obj, usd};

/// The formats Clay exports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExportFormat {
    /// Binary glTF 2.0.
    Glb,
    /// glTF 2.0 with its buffers embedded.
    Gltf,
    /// Wavefront OBJ, its materials in a `.mtl` beside it.
    Obj,
    /// USD in its text form, metres and Z up.
    Usda,
}

impl ExportFormat {
    /// Every format, in the order the help lists them.
    pub const ALL: [Self; 4] = [Self::Glb, Self::Gltf, Self::Obj, Self::Usda];

    /// Its file extension, lower case without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            Self::Glb => "glb",
            Self::Gltf => "gltf",
            Self::Obj => "obj",
            Self::Usda => "usda",
        }
    }

    /// Why `path` names no format, for a message after "cannot tell the format of `PATH`: ":
    /// the extensions there are, and for USD's binary form how to make it.
    pub fn unknown(path: &Path) -> String {
        let names: Vec<String> = Self::ALL
            .iter()
            .map(|f| format!(".{}", f.extension()))
            .collect();
        let (last, rest) = names.split_last().expect("formats");
        let mut why = format!("name it {} or {last}", rest.join(", "));
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("usdc") || e.eq_ignore_ascii_case("usd"))
        {
            why.push_str(
                " (USD's binary form is not written here: export .usda and convert it with `usdcat MODEL.usda -o MODEL.usdc` from a USD installation, or write it from Python with usd-core installed: `session.export(\"MODEL.usdc\")`)",
            );
        }
        why
    }

    /// The format a path's extension names (any case), if any.
    pub fn of_path(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?;
        Self::ALL
            .into_iter()
            .find(|f| f.extension().eq_ignore_ascii_case(ext))
    }
}

/// The thickest flat proxy geometry an export takes, in metres (and it must be above 0).
pub const MAX_THICKNESS: f64 = 1000.0;

impl ExportOptions {
    /// The default options with flat proxy geometry `thickness` metres high; an error (in
    /// words for the user) unless it is above 0 and at most `MAX_THICKNESS` (1000 m).
    pub fn with_thickness(thickness: f64) -> Result<Self, String> {
        if thickness.is_finite() && thickness > 0.0 && thickness <= MAX_THICKNESS {
            Ok(Self {
                thickness,
                ..Self::default()
            })
        } else {
            Err(format!(
                "{thickness} is not above 0 and at most {MAX_THICKNESS} metres"
            ))
        }
    }
}

/// The `.mtl` written beside an `.obj` at `path`.
pub fn mtl_path(path: &Path) -> PathBuf {
    path.with_extension("mtl")
}

/// The bytes of `scene` in `format` for a file at `path`, and for an `.obj` those of its
/// materials (the `.obj` names them by [`mtl_path`]'s file name).
pub fn encode_export(
    scene: &Scene,
    format: ExportFormat,
    path: &Path,
) -> Result<(Vec<u8>, Option<Vec<u8>>), String> {
    let mtl_name = (mtl_path(path).file_name())
        .map_or("model.mtl".into(), |n| n.to_string_lossy().into_owned());
    match format {
        ExportFormat::Glb => Ok((gltf::to_glb(scene)?, None)),
        ExportFormat::Gltf => Ok((gltf::to_gltf(scene)?, None)),
        ExportFormat::Obj => {
            let (obj, mtl) = obj::to_obj(scene, &mtl_name);
            Ok((obj.into_bytes(), Some(mtl.into_bytes())))
        }
        ExportFormat::Usda => Ok((usd::to_usda(scene).into_bytes(), None)),
    }
}

/// Why an export was not written.
#[derive(Debug)]
pub enum ExportFileError {
    /// The scene could not be encoded (a glTF buffer too large, say).
    Encode(String),
    /// A file could not be written.
    Write(PathBuf, std::io::Error),
}

impl std::fmt::Display for ExportFileError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Encode(e) => write!(f, "cannot encode the model: {e}"),
            Self::Write(path, e) => write!(f, "{}: {e}", path.display()),
        }
    }
}

impl std::error::Error for ExportFileError {}

/// Writes `scene` to `path` in `format`, atomically; an `.obj` first and then its `.mtl`
/// ([`mtl_path`]), so a failed export leaves the `.mtl` beside it as it was.
pub fn write_export(
    scene: &Scene,
    path: &Path,
    format: ExportFormat,
) -> Result<(), ExportFileError> {
    let (bytes, materials) = encode_export(scene, format, path).map_err(ExportFileError::Encode)?;
    crate::write_atomic(path, &bytes).map_err(|e| ExportFileError::Write(path.to_path_buf(), e))?;
    if let Some(m) = materials {
        let mtl = mtl_path(path);
        crate::write_atomic(&mtl, &m).map_err(|e| ExportFileError::Write(mtl, e))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_path_names_its_format_in_any_case() {
        assert_eq!(
            ExportFormat::of_path(Path::new("a/b.GLB")),
            Some(ExportFormat::Glb)
        );
        assert_eq!(
            ExportFormat::of_path(Path::new("b.gltf")),
            Some(ExportFormat::Gltf)
        );
        assert_eq!(
            ExportFormat::of_path(Path::new("b.Obj")),
            Some(ExportFormat::Obj)
        );
        assert_eq!(
            ExportFormat::of_path(Path::new("b.USDA")),
            Some(ExportFormat::Usda)
        );
        assert_eq!(ExportFormat::of_path(Path::new("b.mtl")), None);
        assert_eq!(ExportFormat::of_path(Path::new("b.usdc")), None);
        assert_eq!(ExportFormat::of_path(Path::new("b")), None);
    }

    #[test]
    fn thickness_is_above_zero_and_at_most_the_bound() {
        assert_eq!(ExportOptions::with_thickness(0.2).unwrap().thickness, 0.2);
        assert!(ExportOptions::with_thickness(MAX_THICKNESS).is_ok());
        for bad in [0.0, -1.0, MAX_THICKNESS * 1.001, f64::NAN, f64::INFINITY] {
            assert!(ExportOptions::with_thickness(bad).is_err(), "{bad}");
        }
    }
}
