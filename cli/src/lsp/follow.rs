//! The server's side of the Clay editor following the text editor
//! (`clay_dsl::analysis::follow`, docs/editors.md): the requests a client sends as the cursor
//! moves (`documentHighlight`, `hover`) publish what the cursor is on, and the server's loop
//! turns the Clay editor's reveal file into a `window/showDocument` request to the client.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime};

use clay_dsl::analysis::follow::{self, Focus};

/// How often the reveal file is looked at.
pub const POLL: Duration = Duration::from_millis(200);

/// Where the cursor was last published.
pub struct Cursor {
    dir: PathBuf,
    last: Option<Focus>,
}

impl Cursor {
    pub fn new(dir: PathBuf) -> Self {
        Self { dir, last: None }
    }

    /// Publishes `focus` when it changed and an editor follows (the folder exists). A failure
    /// is logged: following is a convenience, the requests are answered either way.
    pub fn publish(&mut self, focus: Option<Focus>) {
        let Some(focus) = focus else { return };
        if self.last.as_ref() == Some(&focus) || !self.dir.is_dir() {
            return;
        }
        if let Err(e) = follow::write(&self.dir, follow::CURSOR, &focus) {
            errln!("clayc lsp: cannot write {}: {e}", self.dir.display());
        }
        self.last = Some(focus);
    }
}

/// The Clay editor's reveal file, looked at every [`POLL`] from the server's loop. A reveal
/// written before the server started is old news and is skipped.
pub struct Reveals {
    file: PathBuf,
    seen: Option<SystemTime>,
    looked: Instant,
}

impl Reveals {
    pub fn new(dir: &Path) -> Self {
        let file = dir.join(follow::REVEAL);
        Self {
            seen: modified(&file),
            file,
            looked: Instant::now(),
        }
    }

    /// A focus written since the last look, if [`POLL`] has passed since then.
    pub fn poll(&mut self) -> Option<Focus> {
        if self.looked.elapsed() < POLL {
            return None;
        }
        self.looked = Instant::now();
        let now = modified(&self.file);
        if now == self.seen {
            return None;
        }
        self.seen = now;
        follow::read(&self.file)
    }
}

fn modified(file: &Path) -> Option<SystemTime> {
    std::fs::metadata(file).and_then(|m| m.modified()).ok()
}

/// Two paths of one file (symbolic links and `..` resolved where the file exists).
pub fn same_file(a: &str, b: &str) -> bool {
    let real = |p: &str| std::fs::canonicalize(p).unwrap_or_else(|_| PathBuf::from(p));
    a == b || real(a) == real(b)
}
