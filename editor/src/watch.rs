//! Hot reload's ears: watches the grammar file, and the files it imports, for changes (through
//! their parent folders, since editors save by writing a new file and renaming it over the old
//! one) and debounces bursts of events into one reload.

use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, channel};
use std::time::{Duration, Instant};

use notify::{EventKind, RecommendedWatcher, RecursiveMode, Watcher};

/// How long the file must be quiet before it is reloaded.
pub const DEBOUNCE: Duration = Duration::from_millis(200);

/// Watches one file (and the files it imports, see [`FileWatch::also`]).
pub struct FileWatch {
    path: PathBuf,
    /// Imported files whose changes also count.
    also: Vec<PathBuf>,
    /// The folders being watched.
    folders: Vec<PathBuf>,
    // Kept alive: dropping the watcher stops the events.
    watcher: RecommendedWatcher,
    events: Receiver<notify::Result<notify::Event>>,
    /// When the last relevant event arrived, if a reload is pending.
    pending: Option<Instant>,
}

impl FileWatch {
    /// Starts watching `path`. `wake` is called from the watcher's thread on every event so the
    /// UI can repaint and notice the change without polling.
    pub fn new(path: &Path, wake: impl Fn() + Send + 'static) -> Result<Self, notify::Error> {
        let path = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
        let folder = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let (tx, events) = channel();
        let mut watcher = notify::recommended_watcher(move |event| {
            // The receiver only goes away with the watch itself.
            let _ = tx.send(event);
            wake();
        })?;
        watcher.watch(&folder, RecursiveMode::NonRecursive)?;
        Ok(Self {
            path,
            also: Vec::new(),
            folders: vec![folder],
            watcher,
            events,
            pending: None,
        })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Also reloads when one of `files` changes (the grammar's imports, as the last good
    /// compile found them). A folder that cannot be watched is skipped: the grammar file itself
    /// is still watched.
    pub fn also(&mut self, files: &[String]) {
        self.also = files
            .iter()
            .map(|f| std::path::absolute(f).unwrap_or_else(|_| PathBuf::from(f)))
            .collect();
        for f in &self.also {
            let Some(folder) = f.parent() else { continue };
            if !self.folders.iter().any(|w| w == folder)
                && self
                    .watcher
                    .watch(folder, RecursiveMode::NonRecursive)
                    .is_ok()
            {
                self.folders.push(folder.to_path_buf());
            }
        }
    }

    /// Drains the events; returns true once the file changed and then stayed quiet for
    /// [`DEBOUNCE`]. While a reload is pending, [`FileWatch::pending`] says when to look again.
    pub fn poll(&mut self) -> bool {
        while let Ok(event) = self.events.try_recv() {
            let Ok(event) = event else {
                continue;
            };
            let relevant = !matches!(event.kind, EventKind::Access(_))
                && event
                    .paths
                    .iter()
                    .any(|p| same_file(p, &self.path) || self.also.iter().any(|a| same_file(p, a)));
            if relevant {
                self.pending = Some(Instant::now());
            }
        }
        match self.pending {
            Some(t) if t.elapsed() >= DEBOUNCE => {
                self.pending = None;
                true
            }
            _ => false,
        }
    }

    /// Time until a pending reload is due, if one is.
    pub fn pending(&self) -> Option<Duration> {
        self.pending.map(|t| DEBOUNCE.saturating_sub(t.elapsed()))
    }
}

fn same_file(a: &Path, b: &Path) -> bool {
    if a == b {
        return true;
    }
    // Events may name the file through another spelling of the folder (symlinks, `..`).
    a.file_name() == b.file_name()
        && match (a.parent(), b.parent()) {
            (Some(pa), Some(pb)) => match (pa.canonicalize(), pb.canonicalize()) {
                (Ok(x), Ok(y)) => x == y,
                _ => false,
            },
            _ => false,
        }
}
