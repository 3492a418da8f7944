//! What the user asks of the editor's files: open, save, export, import, write, quit. Panels
//! emit these during a frame; the app performs them after it.

use std::path::PathBuf;

use crate::files::FileKind;

/// A file operation the user asked for.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    OpenGrammar(PathBuf),
    OpenSession(PathBuf),
    SaveSession(PathBuf),
    ExportPng(PathBuf),
    ExportJson(PathBuf),
    /// The sculpted model as 3D meshes: `.glb`, `.gltf` or `.obj` (with its `.mtl`).
    Export3d(PathBuf),
    /// The gestures since the grammar's initial model as a script `clayc run --script` replays.
    SaveGestures(PathBuf),
    /// Ask for a path first.
    Ask(FileKind),
    Quit,
    /// Authoring: make an SVG file (metres per SVG unit) the drawing.
    ImportSvg(PathBuf, f64),
    /// Authoring: write the grammar text to a file (one the user chose: asked for with
    /// [`Action::Ask`] the first time).
    WriteGrammar(PathBuf),
    /// Authoring: compile the grammar and sculpt it.
    TryAuthored,
    /// Show a message in the status bar.
    Report(String),
    /// Restore the sculpt a crashed editor left in the recovery file.
    RestoreRecovery,
    /// Forget the sculpt a crashed editor left (the recovery file is removed).
    DiscardRecovery,
}

impl Action {
    /// The action a picked path is for.
    pub fn for_path(kind: FileKind, path: PathBuf) -> Self {
        match kind {
            FileKind::Grammar => Action::OpenGrammar(path),
            FileKind::OpenSession => Action::OpenSession(path),
            FileKind::SaveSession => Action::SaveSession(path),
            FileKind::Png => Action::ExportPng(path),
            FileKind::Json => Action::ExportJson(path),
            FileKind::Model3d => Action::Export3d(path),
            FileKind::WriteGrammar => Action::WriteGrammar(path),
            FileKind::GestureScript => Action::SaveGestures(path),
        }
    }
}
