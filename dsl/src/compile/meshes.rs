//! `mesh "PATH"`: loads the 3D mesh assets of a grammar's pieces (through the same [`Loader`] as
//! `import`, so a language server can serve them too), decodes them (`mesh_files.rs`) and keeps
//! their triangles for the pieces' proxy geometry, so that a compiled grammar needs no other
//! file. Every way an asset can fail is a diagnostic at the path string: missing (E064),
//! unreadable (E065), not a mesh Clay reads (E066), beyond a limit (E067).
//!
//! A path is resolved against the folder of the file that declares the piece (an imported
//! library's meshes sit next to the library). Each asset is read once however many pieces use it.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use super::codes;
use super::imports::Loader;
use super::imports::resolve;
use super::mesh_files::{self, AssetPart, Budget, Problem};
pub use super::mesh_files::{
    MAX_MESH_BYTES, MAX_MESH_TOTAL_BYTES, MAX_MESH_TRIANGLES, MAX_MESH_VERTICES,
};
use super::state::Meshes;
use crate::diagnostic::{Diagnostic, Diagnostics};
use crate::source_map::SourceMap;
use crate::syntax::{self, Item, PieceStmt, ShapeDecl, Span};

impl Meshes {
    /// The asset of the `mesh` statement whose path string is at `path`; `None` when it failed
    /// to load (already reported).
    pub fn get(&self, path: Span) -> Option<&[AssetPart]> {
        self.by_path_start.get(&path.start).map(|a| &a[..])
    }
}

/// Loads every asset named by a `mesh` statement of `file` (its main file `main_len` bytes
/// long, shown as `main_path`), reporting the failures into `diags`.
pub(super) fn load(
    file: &syntax::File,
    main_path: &str,
    main_len: usize,
    sources: &SourceMap,
    loader: &dyn Loader,
    diags: &mut Diagnostics,
) -> Meshes {
    let mut meshes = Meshes::default();
    let mut by_file: HashMap<String, Option<Arc<[AssetPart]>>> = HashMap::new();
    let mut total = 0usize;
    for item in &file.items {
        let Item::Piece(p) = item else { continue };
        for s in &p.stmts {
            let PieceStmt::Geometry(g) = s else { continue };
            let ShapeDecl::Mesh { path, .. } = &g.shape else {
                continue;
            };
            if meshes.by_path_start.contains_key(&path.span.start) {
                continue;
            }
            let declared_in = file_of(path.span, main_path, main_len, sources);
            let target = resolve(declared_in, &path.value);
            let loaded = by_file
                .entry(target.clone())
                .or_insert_with(|| match read(&target, loader, &mut total) {
                    Ok(parts) => Some(Arc::from(parts)),
                    Err(problem) => {
                        diags.push(diagnostic(problem, &target, declared_in, path.span));
                        None
                    }
                })
                .clone();
            if let Some(parts) = loaded {
                meshes.by_path_start.insert(path.span.start, parts);
            }
        }
    }
    meshes
}

/// The path of the file a global span lies in.
fn file_of<'a>(span: Span, main_path: &'a str, main_len: usize, sources: &'a SourceMap) -> &'a str {
    sources
        .files
        .iter()
        .rev()
        .find(|f| f.base <= span.start && span.start > main_len)
        .map_or(main_path, |f| f.path.as_str())
}

/// The format a path's extension names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Gltf,
    Obj,
}

fn read(target: &str, loader: &dyn Loader, total: &mut usize) -> Result<Vec<AssetPart>, Problem> {
    let ext = Path::new(target)
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    let format = match ext.as_deref() {
        Some("glb" | "gltf") => Format::Gltf,
        Some("obj") => Format::Obj,
        other => return Err(Problem::Format(other.map(str::to_string))),
    };
    let mut budget = Budget::new(total, loader);
    let bytes = budget.load(target)?;
    let parts = match format {
        Format::Gltf => mesh_files::gltf(&bytes, target, &mut budget)?,
        Format::Obj => mesh_files::obj(&bytes, target, &mut budget)?,
    };
    Ok(parts)
}

/// How a file is named in a message: the asset itself, or a file it refers to (a `.bin`),
/// set off by commas when the sentence goes on after it (`continues`).
fn shown(file: &str, target: &str, continues: bool) -> String {
    if file == target {
        format!("mesh asset `{file}`")
    } else if continues {
        format!("`{file}`, a file that mesh asset `{target}` refers to,")
    } else {
        format!("`{file}`, a file that mesh asset `{target}` refers to")
    }
}

/// The one diagnostic of an asset that failed to load.
fn diagnostic(problem: Problem, target: &str, declared_in: &str, at: Span) -> Diagnostic {
    let folder = Path::new(declared_in)
        .parent()
        .map_or(String::new(), |p| p.to_string_lossy().into_owned());
    let formats =
        "Clay reads glTF 2.0 (`.glb`, or `.gltf` with embedded or `.bin` buffers) and OBJ (`.obj`)";
    match problem {
        Problem::Io(file, e) if e.kind() == std::io::ErrorKind::NotFound => Diagnostic::error(
            codes::MESH_MISSING,
            format!("{} does not exist", shown(&file, target, true)),
            at,
            "no such file",
        )
        .with_hint(format!(
            "the path is relative to the folder of the grammar that names it (`{}`); check the spelling",
            if folder.is_empty() { "." } else { &folder }
        )),
        Problem::Io(file, e) => {
            let why = if e.kind() == std::io::ErrorKind::IsADirectory {
                "it is a folder, not a file".to_string()
            } else {
                e.to_string()
            };
            Diagnostic::error(
                codes::MESH_UNREADABLE,
                format!("cannot read {}: {why}", shown(&file, target, false)),
                at,
                "cannot be read",
            )
            .with_hint("give the path of a `.glb`, `.gltf` or `.obj` file that can be read")
        }
        Problem::Format(ext) => Diagnostic::error(
            codes::MESH_MALFORMED,
            match ext {
                Some(ext) => format!("`.{ext}` is not a mesh format Clay reads"),
                None => format!("mesh asset `{target}` has no file extension"),
            },
            at,
            "unknown mesh format",
        )
        .with_hint(format!("{formats}; export the model as `.glb` from your 3D tool")),
        Problem::Malformed(why) => Diagnostic::error(
            codes::MESH_MALFORMED,
            format!("mesh asset `{target}` is not a mesh Clay can read: {why}"),
            at,
            "malformed mesh asset",
        )
        .with_hint(format!("{formats}; export the model again from your 3D tool")),
        Problem::TooLarge(why) => Diagnostic::error(
            codes::MESH_TOO_LARGE,
            format!("mesh asset `{target}` is too large: {why}"),
            at,
            "too large",
        )
        .with_hint(format!(
            "an asset may have {MAX_MESH_VERTICES} vertices, {MAX_MESH_TRIANGLES} triangles and {} MiB; \
             decimate it in your 3D tool (proxy geometry needs few triangles)",
            MAX_MESH_BYTES >> 20
        )),
    }
}
