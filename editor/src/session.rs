//! Sculpt session files: the versioned JSON form of a sculpt (grammar path, deformed assembly,
//! pins, solver settings), read with clear errors and written atomically.

use std::fmt;
use std::fs;
use std::io;
use std::path::{Path, PathBuf};

use clay_dsl::compiled::AssemblyData;
use glam::DVec2;
use serde::{Deserialize, Serialize};

/// The `format` field every session file carries.
pub const SESSION_FORMAT: &str = "clay-session";
/// The session version this editor writes and reads.
pub const SESSION_VERSION: u32 = 1;

/// A pinned set of vertices and where they are held.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pin {
    pub vertices: Vec<usize>,
    pub at: Vec<DVec2>,
}

/// The solver and rule settings the sliders change.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    pub hysteresis: f64,
    pub norm: f64,
    pub merge_distance: f64,
}

/// An entry of the rule log.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LogEntry {
    /// The solver frame it happened in.
    pub frame: u64,
    pub message: String,
    /// Where it happened (world coordinates), if anywhere in particular.
    pub at: Option<DVec2>,
    /// Not part of a gesture (a failed reload, a file error): undo leaves it.
    #[serde(default)]
    pub outside: bool,
    /// Order of entries, kept across undo and redo.
    #[serde(default)]
    pub seq: u64,
}

/// A saved sculpt.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Session {
    pub format: String,
    pub version: u32,
    /// The grammar file the sculpt was made from, as the editor opened it.
    pub grammar: String,
    pub assembly: AssemblyData,
    #[serde(default)]
    pub pins: Vec<Pin>,
    #[serde(default)]
    pub settings: Option<Settings>,
    /// The rule log when it was saved, so an opened session shows its history.
    #[serde(default)]
    pub log: Vec<LogEntry>,
}

impl Session {
    pub fn new(
        grammar: String,
        assembly: AssemblyData,
        pins: Vec<Pin>,
        settings: Option<Settings>,
    ) -> Self {
        Self {
            format: SESSION_FORMAT.to_string(),
            version: SESSION_VERSION,
            grammar,
            assembly,
            pins,
            settings,
            log: Vec::new(),
        }
    }
}

/// Why a session could not be read or written.
#[derive(Debug)]
pub enum SessionError {
    Io {
        path: PathBuf,
        error: io::Error,
    },
    /// The text is not JSON, or not a session of a version this editor reads.
    Malformed(String),
}

impl fmt::Display for SessionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SessionError::Io { path, error } => write!(f, "{}: {error}", path.display()),
            SessionError::Malformed(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for SessionError {}

/// Parses session text. Checks the format tag and version before the body so that a file of
/// another kind or version says so rather than naming a missing field.
pub fn parse(text: &str) -> Result<Session, SessionError> {
    let value: serde_json::Value = serde_json::from_str(text)
        .map_err(|e| SessionError::Malformed(format!("not a session file: invalid JSON ({e})")))?;
    let format = value.get("format").and_then(|f| f.as_str());
    if format != Some(SESSION_FORMAT) {
        return Err(SessionError::Malformed(format!(
            "not a session file: \"format\" must be \"{SESSION_FORMAT}\", found {}",
            value
                .get("format")
                .map_or("nothing".to_string(), |f| f.to_string())
        )));
    }
    match value.get("version").and_then(|v| v.as_u64()) {
        Some(v) if v == u64::from(SESSION_VERSION) => {}
        Some(v) => {
            return Err(SessionError::Malformed(format!(
                "session version {v} is not supported (this editor reads version {SESSION_VERSION})"
            )));
        }
        None => {
            return Err(SessionError::Malformed(
                "session file has no numeric \"version\"".to_string(),
            ));
        }
    }
    serde_json::from_value(value)
        .map_err(|e| SessionError::Malformed(format!("malformed session file: {e}")))
}

/// Reads and parses a session file.
pub fn read(path: &Path) -> Result<Session, SessionError> {
    let text = fs::read_to_string(path).map_err(|error| SessionError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    parse(&text)
}

/// Writes a session file atomically.
pub fn write(path: &Path, session: &Session) -> Result<(), SessionError> {
    let text = serde_json::to_string_pretty(session)
        .map_err(|e| SessionError::Malformed(format!("cannot encode the session: {e}")))?;
    clay::files::write_atomic(path, text.as_bytes()).map_err(|error| SessionError::Io {
        path: path.to_path_buf(),
        error,
    })
}
