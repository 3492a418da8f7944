//! Standard output, standard error and `-o` files for every `clayc` subcommand. A reader that
//! closes the pipe early (`clayc check --format json ... | head -1`) is not an error: the
//! subcommand stops writing and exits with the code it would have had, without a message
//! (`println!` would panic with "failed printing to stdout: Broken pipe", exit 101). Messages on
//! stderr never panic either: when stderr has gone there is nobody left to tell.

use std::io::{ErrorKind, Write};
use std::path::Path;

/// Exit code of usage and I/O errors.
pub const IO_ERROR: u8 = 2;

/// Why writing to standard output stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stop {
    /// The reader closed the pipe: not an error, nothing more is wanted.
    ReaderGone,
    /// Standard output failed otherwise (a full disk, ...); the message is on stderr.
    Failed,
}

impl Stop {
    /// The exit code: `code` (what the subcommand would have returned) when only the reader
    /// went away, 2 when writing failed.
    pub fn exit(self, code: u8) -> u8 {
        match self {
            Stop::ReaderGone => code,
            Stop::Failed => IO_ERROR,
        }
    }
}

/// Writes `bytes` to standard output and flushes them.
pub fn stdout(bytes: &[u8]) -> Result<(), Stop> {
    let mut out = std::io::stdout().lock();
    match out.write_all(bytes).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == ErrorKind::BrokenPipe => Err(Stop::ReaderGone),
        Err(e) => {
            stderr(format_args!(
                "error: cannot write to standard output: {e}\n"
            ));
            Err(Stop::Failed)
        }
    }
}

/// Writes `text` and a newline to standard output.
pub fn stdout_line(text: &str) -> Result<(), Stop> {
    let mut line = String::with_capacity(text.len() + 1);
    line.push_str(text);
    line.push('\n');
    stdout(line.as_bytes())
}

/// Writes `bytes` to the file `output`, or to standard output when it is `-`. Gives the exit
/// code: 0 written (or the reader of standard output went away), 2 the write failed (the
/// message names the file).
pub fn write_output(output: &Path, bytes: &[u8]) -> u8 {
    if output.as_os_str() == "-" {
        return stdout(bytes).err().map_or(0, |stop| stop.exit(0));
    }
    match clay::write_atomic(output, bytes) {
        Ok(()) => 0,
        Err(e) => {
            stderr(format_args!(
                "error: cannot write `{}`: {e}\n",
                output.display()
            ));
            IO_ERROR
        }
    }
}

/// Writes to standard error, ignoring failure (there is nowhere left to report it).
pub fn stderr(args: std::fmt::Arguments<'_>) {
    let _ = std::io::stderr().lock().write_fmt(args);
}

/// `eprintln!` that never panics: a message line on standard error.
macro_rules! errln {
    ($($arg:tt)*) => {
        $crate::out::stderr(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `eprint!` that never panics.
macro_rules! err {
    ($($arg:tt)*) => {
        $crate::out::stderr(format_args!($($arg)*))
    };
}
