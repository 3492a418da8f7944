//! Writing the user's files: every file Clay writes (grammars from `clayc author` and the
//! editor, `build`/`render`/`sheet` outputs, `fmt --write`, sessions and exports) goes through
//! [`write_atomic`], so a crash or a full disk never leaves half a file, a symbolic link stays
//! a link to its updated target, and a pipe or a device (`/dev/stdout`) is written to.

use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// Most symbolic links followed from one path (Linux's own limit).
const MAX_LINKS: usize = 40;

/// Writes `bytes` to `path` so that readers see the old file or the new one, never a torn one.
///
/// - A regular file, or a path where nothing is yet: a temporary file in the same folder (so
///   the rename stays on one file system), flushed to disk, then renamed over the target.
/// - A symbolic link: the same for the file it leads to (created when the link dangles); the
///   link stays a link.
/// - Anything else that is not a folder (a FIFO, a character or block device, `/dev/stdout`):
///   opened and written directly, as `cat > path` would; it cannot be replaced atomically and
///   must not be replaced at all.
///
/// On failure an atomic write leaves the target untouched and removes its temporary file.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    match fs::metadata(path) {
        Ok(meta) if meta.is_file() => replace(&fs::canonicalize(path)?, bytes),
        Ok(meta) if !meta.is_dir() => write_through(path, bytes),
        // Nothing there yet (or a dangling link), or a folder, whose rename fails below.
        _ => replace(&link_target(path)?, bytes),
    }
}

/// Where `path` leads after its symbolic links, followed one by one, so that a dangling link
/// gives the path it names; `path` itself when it is no link.
fn link_target(path: &Path) -> io::Result<PathBuf> {
    let mut at = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        match fs::symlink_metadata(&at) {
            Ok(meta) if meta.file_type().is_symlink() => {
                let to = fs::read_link(&at)?;
                // A relative link is relative to its own folder; `join` keeps an absolute one.
                at = at.parent().map_or_else(|| to.clone(), |dir| dir.join(&to));
            }
            _ => return Ok(at),
        }
    }
    Err(io::Error::new(
        io::ErrorKind::InvalidInput,
        format!(
            "more than {MAX_LINKS} symbolic links from `{}`",
            path.display()
        ),
    ))
}

/// Writes into what is at `path` (a FIFO, a device): no temporary file, no rename.
fn write_through(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut file = fs::OpenOptions::new().write(true).open(path)?;
    file.write_all(bytes)?;
    file.flush()
}

/// The atomic write of a regular file (or a new one) at `path`, which is no link.
fn replace(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "the path names no file"))?;
    let tmp = dir.join(format!(
        ".{}.{}.tmp",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| {
        let mut file = fs::File::create(&tmp)?;
        file.write_all(bytes)?;
        file.sync_all()?;
        drop(file);
        // A rewritten file keeps its permissions (`clayc fmt --write` on a script, say).
        if let Ok(meta) = fs::metadata(path) {
            fs::set_permissions(&tmp, meta.permissions())?;
        }
        fs::rename(&tmp, path)?;
        // Make the rename itself durable; not every platform lets a folder be opened.
        if let Ok(d) = fs::File::open(&dir) {
            let _ = d.sync_all();
        }
        Ok(())
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh folder for one test.
    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("clay-files-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    /// Whether `path` is a symbolic link (not what it points to).
    fn is_link(path: &Path) -> bool {
        fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink())
    }

    #[test]
    fn a_write_replaces_the_file_whole_and_leaves_no_temporary() {
        let dir = scratch("plain");
        let path = dir.join("g.clay");
        fs::write(&path, "old").unwrap();
        write_atomic(&path, b"new text").unwrap();
        assert_eq!(fs::read_to_string(&path).unwrap(), "new text");
        assert_eq!(
            fs::read_dir(&dir).unwrap().count(),
            1,
            "no temporary file left"
        );
        // A folder that does not exist: an error, and nothing written.
        assert!(write_atomic(&dir.join("no/such/g.clay"), b"x").is_err());
        let _ = fs::remove_dir_all(&dir);
    }

    #[cfg(unix)]
    #[test]
    fn a_symbolic_link_stays_and_its_target_is_written() {
        use std::os::unix::fs::symlink;
        let dir = scratch("link");
        fs::create_dir(dir.join("real")).unwrap();
        fs::write(dir.join("real/out.json"), "old").unwrap();
        symlink("real/out.json", dir.join("link.json")).unwrap();
        write_atomic(&dir.join("link.json"), b"new").unwrap();
        let link = fs::symlink_metadata(dir.join("link.json")).unwrap();
        assert!(link.file_type().is_symlink(), "the link was replaced");
        assert_eq!(
            fs::read_to_string(dir.join("real/out.json")).unwrap(),
            "new"
        );
        assert_eq!(names(&dir.join("real")), ["out.json"], "no temporary left");
        // A link to a link, relative to each one's folder.
        symlink("../link.json", dir.join("real/again.json")).unwrap();
        write_atomic(&dir.join("real/again.json"), b"newer").unwrap();
        assert_eq!(
            fs::read_to_string(dir.join("real/out.json")).unwrap(),
            "newer"
        );
        assert!(is_link(&dir.join("real/again.json")));
        // A dangling link: the file it names is created.
        symlink("real/new.json", dir.join("dangling.json")).unwrap();
        write_atomic(&dir.join("dangling.json"), b"made").unwrap();
        assert_eq!(
            fs::read_to_string(dir.join("real/new.json")).unwrap(),
            "made"
        );
        assert!(is_link(&dir.join("dangling.json")));
        // A loop of links is an error, not a hang.
        symlink("b", dir.join("a")).unwrap();
        symlink("a", dir.join("b")).unwrap();
        assert!(write_atomic(&dir.join("a"), b"x").is_err());
        let _ = fs::remove_dir_all(&dir);
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_is_written_through_not_replaced() {
        use std::io::Read;
        use std::os::unix::fs::FileTypeExt;
        let dir = scratch("fifo");
        let fifo = dir.join("out.fifo");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success());
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || {
                let mut got = Vec::new();
                fs::File::open(fifo).unwrap().read_to_end(&mut got).unwrap();
                got
            })
        };
        write_atomic(&fifo, b"through the pipe").unwrap();
        // Before the join: had the FIFO been replaced, its reader would wait for ever.
        assert!(fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
        assert_eq!(reader.join().unwrap(), b"through the pipe");
        assert_eq!(names(&dir), ["out.fifo"], "no temporary left");
        let _ = fs::remove_dir_all(&dir);
    }

    #[cfg(unix)]
    #[test]
    fn dev_null_is_written_without_error_and_stays_a_device() {
        use std::os::unix::fs::FileTypeExt;
        let null = Path::new("/dev/null");
        write_atomic(null, b"nothing").unwrap();
        assert!(
            fs::symlink_metadata(null)
                .unwrap()
                .file_type()
                .is_char_device()
        );
        let temporary = format!(".null.{}.tmp", std::process::id());
        assert!(!Path::new("/dev").join(temporary).exists());
    }
}
