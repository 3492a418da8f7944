//! Crash recovery (hot exit): while the sculpt has unsaved changes it is kept in a recovery
//! file, a session file written atomically after each undo step and at most every few seconds
//! while the model moves; a clean exit, a save or a discard removes it. The next start finds
//! it and offers to restore the work (`EditorApp::use_recovery`).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime};

use crate::session::{self, SavedSession};

/// Between two writes while the model moves without a new undo step.
pub const WRITE_EVERY: Duration = Duration::from_secs(3);

/// The recovery file of this user: `$CLAY_RECOVERY_FILE` if set (empty: recovery off), else
/// `clay/recovery.clay-session` under `$XDG_STATE_HOME` or `~/.local/state`.
pub fn default_path() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("CLAY_RECOVERY_FILE") {
        return (!p.is_empty()).then(|| PathBuf::from(p));
    }
    let state = std::env::var_os("XDG_STATE_HOME")
        .filter(|p| !p.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".local/state")))?;
    Some(state.join("clay").join("recovery.clay-session"))
}

/// Makes the folder `path` is to be written in, with its parents, readable by this user only
/// where the system has such permissions (the XDG base directory specification asks that of
/// the state folders it makes).
fn make_folder(path: &Path) -> Result<(), String> {
    let Some(folder) = path.parent().filter(|f| !f.as_os_str().is_empty()) else {
        return Ok(());
    };
    if folder.is_dir() {
        return Ok(());
    }
    let mut builder = std::fs::DirBuilder::new();
    builder.recursive(true);
    #[cfg(unix)]
    std::os::unix::fs::DirBuilderExt::mode(&mut builder, 0o700);
    builder
        .create(folder)
        .map_err(|e| format!("cannot make the folder {}: {e}", folder.display()))
}

/// Work found in a recovery file at start: what it is, for the offer to restore it.
#[derive(Clone, Debug, PartialEq)]
pub struct Offer {
    /// The grammar the sculpt was made from.
    pub grammar: String,
    /// When the file was last written.
    pub written: Option<SystemTime>,
}

/// The recovery file and what was last written to it.
#[derive(Debug)]
pub struct Recovery {
    path: PathBuf,
    /// `(history, revision)` of the sculpt last written, and when.
    written: Option<((u64, u64), Instant)>,
    /// Work found at start and not yet restored or discarded: nothing is written over it.
    offer: Option<Offer>,
    /// Why the last write failed, until one succeeds: the editor shows it for as long as
    /// unsaved work is not kept.
    failure: Option<String>,
}

impl Recovery {
    /// Recovery into `path`, with the work a crashed editor left there (if it reads as a
    /// session) on offer.
    pub fn at(path: PathBuf) -> Self {
        let offer = session::read(&path).ok().map(|s| Offer {
            grammar: s.grammar,
            written: std::fs::metadata(&path).and_then(|m| m.modified()).ok(),
        });
        Self {
            path,
            written: None,
            offer,
            failure: None,
        }
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Why unsaved work is not being kept (the last write failed), until a write succeeds.
    pub fn failure(&self) -> Option<&str> {
        self.failure.as_deref()
    }

    /// The work found at start, until it is restored or discarded.
    pub fn offer(&self) -> Option<&Offer> {
        self.offer.as_ref()
    }

    /// The offer is answered (restored or discarded): from now on the file is this editor's.
    pub fn answered(&mut self) {
        self.offer = None;
    }

    /// Keeps the file up to date with the sculpt: `stamp` is its `(history, revision)`,
    /// `unsaved` whether it has changes to lose, `session` makes the session to write (`None`
    /// when it cannot be written, e.g. an authored grammar not yet written to a file).
    /// Returns an error message the first time a write fails.
    pub fn keep(
        &mut self,
        stamp: (u64, u64),
        unsaved: bool,
        session: impl FnOnce() -> Option<SavedSession>,
    ) -> Option<String> {
        if self.offer.is_some() {
            return None;
        }
        if !unsaved {
            self.clear();
            return None;
        }
        let due = match self.written {
            None => true,
            Some((last, _)) if last == stamp => false,
            Some(((history, _), _)) if history != stamp.0 => true,
            Some((_, at)) => at.elapsed() >= WRITE_EVERY,
        };
        if !due {
            return None;
        }
        let session = session()?;
        // a first-time user has no state folder yet: it is made, for this user only
        let written = make_folder(&self.path)
            .and_then(|()| session::write(&self.path, &session).map_err(|e| e.to_string()));
        match written {
            Ok(()) => {
                self.written = Some((stamp, Instant::now()));
                self.failure = None;
                None
            }
            Err(e) => {
                let first = self.failure.is_none();
                self.failure = Some(format!(
                    "crash recovery is off: cannot write {}: {e}",
                    self.path.display()
                ));
                first.then(|| self.failure.clone()).flatten()
            }
        }
    }

    /// Removes the file (a clean exit, a save, a discard).
    pub fn clear(&mut self) {
        if self.written.take().is_some() || self.offer.take().is_some() {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}
