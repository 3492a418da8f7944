//! Reading the user's files: every file Clay reads (a grammar and its imports, a script, a
//! session, a compiled grammar, a drawing, a mesh asset) goes through [`read_input`], which
//! refuses, before opening it, what is not a regular file (a named pipe waits for a writer,
//! forever if none comes; `/dev/zero` never ends) and stops reading past a limit of the
//! file's kind, so that no input can block the program or eat its memory. A grammar's bytes
//! become text through [`decode_utf8`], which words what is not UTF-8 as a diagnostic.

use std::io::{self, Read};
use std::path::Path;

use crate::diagnostic::{Diagnostic, Diagnostics};
use crate::syntax::Span;

/// The code of a file that is not valid UTF-8 (here, not in `compile/codes.rs`, which
/// re-exports it, because the compiler reads its input through this module).
pub const NOT_UTF8: &str = "E003";

/// Most bytes of a file the user writes by hand or in a drawing program: a grammar (its
/// imports together, E062), a script, a drawing (32 MiB; the largest example is 8 KiB).
pub const MAX_SOURCE_BYTES: usize = 32 << 20;
/// Most bytes of a file Clay writes for itself to read back: a compiled grammar, a session
/// (1 GiB: a million-part city's session is about 300 MiB).
pub const MAX_DATA_BYTES: usize = 1 << 30;

/// The bytes of the regular file at `path` (symbolic links followed), at most `limit` of them.
///
/// Errors: what `open` gives (`NotFound`, `PermissionDenied`); `IsADirectory` for a folder;
/// `InvalidInput` saying what it is for anything else that is not a regular file (a FIFO, a
/// socket, a device); `FileTooLarge` when the file has more than `limit` bytes.
pub fn read_input(path: &Path, limit: usize) -> io::Result<Vec<u8>> {
    regular_file(path)?;
    read_bounded(std::fs::File::open(path)?, limit)
}

/// [`read_input`] of a text file: its bytes must be UTF-8 (`InvalidData` saying where not).
pub fn read_input_string(path: &Path, limit: usize) -> io::Result<String> {
    utf8(read_input(path, limit)?)
}

/// At most `limit` bytes of `reader` (standard input, for one): `FileTooLarge` if it has more.
pub fn read_bounded(reader: impl Read, limit: usize) -> io::Result<Vec<u8>> {
    let mut bytes = Vec::new();
    reader.take(limit as u64 + 1).read_to_end(&mut bytes)?;
    if bytes.len() > limit {
        return Err(io::Error::new(
            io::ErrorKind::FileTooLarge,
            format!("it has more than {}", size_words(limit)),
        ));
    }
    Ok(bytes)
}

/// The bytes as text, or `InvalidData` saying where they stop being UTF-8.
pub fn utf8(bytes: Vec<u8>) -> io::Result<String> {
    String::from_utf8(bytes).map_err(|e| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!(
                "it is not UTF-8 text (byte {} is not)",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

/// The bytes of a grammar as its text, for [`compile`](crate::compile): what is not UTF-8 is
/// E003 at the first bad byte. Render that diagnostic against
/// `String::from_utf8_lossy(bytes)`: offsets before that byte agree.
pub fn decode_utf8(bytes: &[u8]) -> Result<&str, Diagnostics> {
    std::str::from_utf8(bytes).map_err(|e| {
        let at = e.valid_up_to();
        Diagnostic::error(
            NOT_UTF8,
            "file is not valid UTF-8 text",
            Span::new(at, at + 1),
            "invalid byte here",
        )
        .with_hint("save the file as UTF-8")
        .into()
    })
}

/// `32 MiB`, `1 GiB`, `512 bytes`.
fn size_words(bytes: usize) -> String {
    if bytes >= 1 << 30 && bytes.is_multiple_of(1 << 30) {
        format!("{} GiB", bytes >> 30)
    } else if bytes >= 1 << 20 && bytes.is_multiple_of(1 << 20) {
        format!("{} MiB", bytes >> 20)
    } else {
        format!("{bytes} bytes")
    }
}

/// Refuses, before it is opened, a path (symbolic links followed) that is not a regular file:
/// opening a named pipe waits for a writer, forever if none comes, and a device may never end.
/// A folder is `IsADirectory`, anything else `InvalidInput` saying what it is.
pub fn regular_file(path: &Path) -> io::Result<()> {
    let kind = std::fs::metadata(path)?.file_type();
    if kind.is_file() {
        Ok(())
    } else if kind.is_dir() {
        Err(io::Error::new(
            io::ErrorKind::IsADirectory,
            "it is a folder, not a file",
        ))
    } else {
        Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("it is not a regular file but {}", special_kind(&kind)),
        ))
    }
}

/// What a file that is neither a regular file nor a folder is, in words.
fn special_kind(kind: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return "a named pipe (FIFO)";
        } else if kind.is_socket() {
            return "a socket";
        } else if kind.is_char_device() || kind.is_block_device() {
            return "a device";
        }
    }
    let _ = kind;
    "a special file"
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("clay-input-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn dev_zero_is_refused_before_a_byte_is_read() {
        let e = read_input(Path::new("/dev/zero"), MAX_SOURCE_BYTES).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::InvalidInput);
        assert!(e.to_string().contains("a device"), "{e}");
    }

    #[cfg(unix)]
    #[test]
    fn a_named_pipe_is_refused_without_waiting_for_a_writer() {
        let dir = scratch("fifo");
        let fifo = dir.join("grammar.clay");
        let _ = std::fs::remove_file(&fifo);
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if !made.is_ok_and(|s| s.success()) {
            return; // no mkfifo here: nothing to test against
        }
        let e = read_input(&fifo, MAX_SOURCE_BYTES).unwrap_err();
        assert!(e.to_string().contains("named pipe"), "{e}");
    }

    #[test]
    fn a_file_past_the_limit_is_too_large_and_one_at_it_is_read() {
        let dir = scratch("limit");
        let path = dir.join("big.clay");
        std::fs::write(&path, vec![b'x'; 1024]).unwrap();
        assert_eq!(read_input(&path, 1024).unwrap().len(), 1024);
        let e = read_input(&path, 1023).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::FileTooLarge);
        assert_eq!(e.to_string(), "it has more than 1023 bytes");
        let e = read_input(&dir, 1024).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::IsADirectory);
        std::fs::write(&path, [b'a', 0xff]).unwrap();
        let e = read_input_string(&path, 1024).unwrap_err();
        assert_eq!(e.to_string(), "it is not UTF-8 text (byte 1 is not)");
    }
}
