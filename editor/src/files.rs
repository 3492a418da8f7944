//! Where files come from: the desktop's native file dialog (rfd, on its own thread so the
//! window keeps drawing), the typed-path fallback where there is no desktop portal (Xvfb), the
//! recent-files list kept in the user's config folder, and the check for a display at all.

use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, TryRecvError, channel};

use serde::{Deserialize, Serialize};

/// Most recent files remembered.
pub const RECENT_LIMIT: usize = 10;

/// What a path asked for is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    Grammar,
    OpenSession,
    SaveSession,
    Png,
    Json,
    /// The sculpted model as 3D meshes (glTF, OBJ or USD, by extension).
    Model3d,
    /// Authoring: the file the grammar is written to.
    WriteGrammar,
    /// The gestures since the initial model, as a `clayc run` script.
    GestureScript,
}

impl FileKind {
    pub fn title(self) -> &'static str {
        match self {
            FileKind::Grammar => "Open grammar",
            FileKind::OpenSession => "Open session",
            FileKind::SaveSession => "Save session as",
            FileKind::Png => "Export view as PNG",
            FileKind::Json => "Export deformed assembly as JSON",
            FileKind::Model3d => "Export 3D model (glTF, OBJ or USD)",
            FileKind::WriteGrammar => "Write grammar as",
            FileKind::GestureScript => "Save gestures as script",
        }
    }

    /// Whether the file is written (a save dialog) rather than read.
    pub fn writes(self) -> bool {
        matches!(
            self,
            FileKind::SaveSession
                | FileKind::Png
                | FileKind::Json
                | FileKind::Model3d
                | FileKind::WriteGrammar
                | FileKind::GestureScript
        )
    }

    /// The dialog's filter: a name and the extensions it shows.
    fn filter(self) -> (&'static str, &'static [&'static str]) {
        match self {
            FileKind::Grammar => ("Clay grammar", &["clay", "json"]),
            FileKind::OpenSession | FileKind::SaveSession => ("Clay session", &["json"]),
            FileKind::Png => ("PNG image", &["png"]),
            FileKind::Json => ("JSON", &["json"]),
            FileKind::Model3d => ("3D model", &["glb", "gltf", "obj", "usda"]),
            FileKind::WriteGrammar => ("Clay grammar", &["clay"]),
            FileKind::GestureScript => ("Clay script", &["json"]),
        }
    }
}

/// What the desktop offers: a native file dialog, and where to keep the recent files. Tests
/// use [`Desktop::none`], so they never open a dialog or touch the user's config.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Desktop {
    pub native_dialogs: bool,
    /// The recent-files list's file; `None`: not remembered between runs.
    pub recent_store: Option<PathBuf>,
}

impl Desktop {
    /// Neither dialogs nor a remembered list.
    pub fn none() -> Self {
        Self::default()
    }

    /// This machine's desktop. rfd asks the XDG desktop portal over D-Bus and falls back to
    /// `zenity`; with neither (a bare Xvfb) the typed path is the only way, so it is used
    /// without first failing a dialog. `CLAY_EDITOR_NO_DIALOG=1` forces the typed path.
    pub fn detect() -> Self {
        let forced_off = std::env::var_os("CLAY_EDITOR_NO_DIALOG").is_some_and(|v| v != "0");
        let native = !forced_off && (has_session_bus() || on_path("zenity"));
        let recent_store = directories::ProjectDirs::from("", "", "clay")
            .map(|d| d.config_dir().join("recent-files.json"));
        Self {
            native_dialogs: native,
            recent_store,
        }
    }
}

fn has_session_bus() -> bool {
    cfg!(any(target_os = "windows", target_os = "macos"))
        || std::env::var_os("DBUS_SESSION_BUS_ADDRESS").is_some_and(|v| !v.is_empty())
}

fn on_path(program: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|d| d.join(program).is_file()))
}

/// Why no window can open here, if that is so: on Linux and the BSDs a window needs an X11
/// or Wayland display, and winit's own error for a missing one is a nested debug structure.
pub fn no_display() -> Option<String> {
    if cfg!(any(target_os = "windows", target_os = "macos")) {
        return None;
    }
    let set = |name: &str| std::env::var_os(name).is_some_and(|v| !v.is_empty());
    if set("DISPLAY") || set("WAYLAND_DISPLAY") {
        return None;
    }
    Some(
        "no display to open a window on (neither DISPLAY nor WAYLAND_DISPLAY is set); \
         run it under a desktop or `xvfb-run -a clay-editor`, or use `clayc` without a display"
            .to_string(),
    )
}

/// A native file dialog open on its own thread.
pub struct NativeDialog {
    pub kind: FileKind,
    answer: Receiver<Option<PathBuf>>,
}

impl NativeDialog {
    /// Opens the dialog for `kind`, starting in `start`'s folder with its name suggested.
    pub fn open(kind: FileKind, start: &Path) -> Self {
        let (send, answer) = channel();
        let (name, extensions) = kind.filter();
        let folder = start
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .map(Path::to_path_buf)
            .or_else(|| std::env::current_dir().ok());
        let file_name = start.file_name().map(|n| n.to_string_lossy().into_owned());
        std::thread::spawn(move || {
            let mut dialog = rfd::FileDialog::new()
                .set_title(kind.title())
                .add_filter(name, extensions);
            if let Some(d) = folder {
                dialog = dialog.set_directory(d);
            }
            let picked = if kind.writes() {
                if let Some(n) = file_name {
                    dialog = dialog.set_file_name(n);
                }
                dialog.save_file()
            } else {
                dialog.pick_file()
            };
            // The editor may have gone meanwhile; nobody is left to tell.
            let _ = send.send(picked);
        });
        Self { kind, answer }
    }

    /// `None` while the dialog is open; then the path picked, or `Some(None)` if cancelled.
    pub fn poll(&self) -> Option<Option<PathBuf>> {
        match self.answer.try_recv() {
            Ok(picked) => Some(picked),
            Err(TryRecvError::Empty) => None,
            // The dialog's thread died (no portal after all): as if cancelled.
            Err(TryRecvError::Disconnected) => Some(None),
        }
    }
}

/// The recently opened grammars and sessions, newest first.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Recent {
    pub files: Vec<RecentFile>,
}

/// One recent file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RecentFile {
    pub path: PathBuf,
    /// A session (otherwise a grammar).
    pub session: bool,
}

impl Recent {
    /// The list kept at `store`; a missing or unreadable list is an empty one (it is only a
    /// convenience, never a reason not to start).
    pub fn load(store: Option<&Path>) -> Self {
        store
            .and_then(|p| clay_dsl::read_input_string(p, clay_dsl::MAX_SOURCE_BYTES).ok())
            .and_then(|t| serde_json::from_str(&t).ok())
            .unwrap_or_default()
    }

    /// Puts `path` first (absolute, once) and drops the oldest beyond [`RECENT_LIMIT`].
    pub fn add(&mut self, path: &Path, session: bool) {
        let path = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
        self.files.retain(|f| f.path != path);
        self.files.insert(0, RecentFile { path, session });
        self.files.truncate(RECENT_LIMIT);
    }

    /// Writes the list atomically to `store` (its folder made first).
    pub fn save(&self, store: &Path) -> Result<(), String> {
        if let Some(dir) = store.parent() {
            std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        let text = serde_json::to_string_pretty(self).map_err(|e| e.to_string())?;
        clay::write_atomic(store, text.as_bytes()).map_err(|e| format!("{}: {e}", store.display()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recent_files_are_newest_first_once_and_bounded() {
        let mut r = Recent::default();
        for k in 0..12 {
            r.add(Path::new(&format!("/tmp/g{k}.clay")), false);
        }
        r.add(Path::new("/tmp/g5.clay"), false);
        assert_eq!(r.files.len(), RECENT_LIMIT);
        assert_eq!(r.files[0].path, Path::new("/tmp/g5.clay"));
        assert_eq!(
            r.files
                .iter()
                .filter(|f| f.path.ends_with("g5.clay"))
                .count(),
            1
        );
        assert_eq!(r.files[1].path, Path::new("/tmp/g11.clay"));
    }

    #[test]
    fn a_recent_list_survives_a_save_and_a_broken_one_is_empty() {
        let dir = std::env::temp_dir().join(format!("clay-recent-{}", std::process::id()));
        let store = dir.join("sub").join("recent-files.json");
        let mut r = Recent::default();
        r.add(Path::new("/tmp/a.clay"), false);
        r.add(Path::new("/tmp/a.session.json"), true);
        r.save(&store).unwrap();
        assert_eq!(Recent::load(Some(&store)), r);
        std::fs::write(&store, "{ not json").unwrap();
        assert_eq!(Recent::load(Some(&store)), Recent::default());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
