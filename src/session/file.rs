//! Sculpt session files (issue 40): the versioned JSON form of a sculpt (grammar path,
//! deformed assembly, pins, solver settings, rule log) that the editor saves and opens and
//! `clayc run|render|export --session` replays headlessly. Read with clear errors (a file of
//! another kind or version says so; a JSON mistake names its line and column) and written
//! atomically ([`crate::files::write_atomic`]).

use std::collections::BTreeMap;
use std::fmt;
use std::io;
use std::path::{Path, PathBuf};

use clay_dsl::compiled::AssemblyData;
use glam::DVec2;
use serde::{Deserialize, Serialize};

/// The `format` field every session file carries.
pub const SESSION_FORMAT: &str = "clay-session";
/// The session version this library writes and reads.
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
pub struct SavedSession {
    pub format: String,
    pub version: u32,
    /// The grammar file the sculpt was made from, as the editor opened it (`clayc` reads a
    /// relative path from the session file's folder).
    pub grammar: String,
    pub assembly: AssemblyData,
    #[serde(default)]
    pub pins: Vec<Pin>,
    #[serde(default)]
    pub settings: Option<Settings>,
    /// The rule log when it was saved, so an opened session shows its history.
    #[serde(default)]
    pub log: Vec<LogEntry>,
    /// The grammar's parameters as set when it was saved (`param NAME = ...`), by name; the
    /// grammar is compiled with them before the assembly is checked against it. Absent or
    /// empty: every parameter at its default.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub params: BTreeMap<String, clay_dsl::compiled::ParamValue>,
}

impl SavedSession {
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
            params: BTreeMap::new(),
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
    /// The text is not JSON, or not a session of a version this library reads. A JSON
    /// mistake's message names its line and column (`at line 3 column 14`).
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
pub fn parse(text: &str) -> Result<SavedSession, SessionError> {
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
                "session version {v} is not supported (this version of Clay reads version {SESSION_VERSION})"
            )));
        }
        None => {
            return Err(SessionError::Malformed(
                "session file has no numeric \"version\"".to_string(),
            ));
        }
    }
    // From the text, not the value: serde's message then names the line and column.
    serde_json::from_str(text)
        .map_err(|e| SessionError::Malformed(format!("malformed session file: {e}")))
}

/// Reads and parses a session file.
pub fn read(path: &Path) -> Result<SavedSession, SessionError> {
    let text = clay_dsl::read_input_string(path, clay_dsl::MAX_DATA_BYTES).map_err(|error| {
        SessionError::Io {
            path: path.to_path_buf(),
            error,
        }
    })?;
    parse(&text)
}

/// Writes a session file atomically.
pub fn write(path: &Path, session: &SavedSession) -> Result<(), SessionError> {
    let text = serde_json::to_string_pretty(session)
        .map_err(|e| SessionError::Malformed(format!("cannot encode the session: {e}")))?;
    crate::files::write_atomic(path, text.as_bytes()).map_err(|error| SessionError::Io {
        path: path.to_path_buf(),
        error,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs;

    fn assembly() -> AssemblyData {
        let source = "site type s\npiece p {\n    vertex a (0, 0)\n    vertex b (1, 0)\n    \
                      vertex c (0, 1)\n    edges a-b-c-a\n    site e: s [a, b] out (0, -1)\n}\n\
                      model {\n    x = p at (0, 0)\n}\n";
        clay_dsl::compile(source, "t.clay", &clay_dsl::CompileOptions::default())
            .unwrap()
            .grammar
            .assembly
    }

    fn session() -> SavedSession {
        let pins = vec![Pin {
            vertices: vec![0, 1],
            at: vec![DVec2::new(0.0, 0.0), DVec2::new(1.0, 0.25)],
        }];
        let settings = Settings {
            hysteresis: 0.1,
            norm: 1.0,
            merge_distance: 0.5,
        };
        SavedSession::new("t.clay".into(), assembly(), pins, Some(settings))
    }

    fn malformed(text: &str) -> String {
        match parse(text) {
            Err(SessionError::Malformed(m)) => m,
            other => panic!("expected a malformed-session error, got {other:?}"),
        }
    }

    #[test]
    fn a_written_session_reads_back_equal() {
        let dir = std::env::temp_dir().join(format!("clay-session-file-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let path = dir.join("s.json");
        let s = session();
        write(&path, &s).unwrap();
        assert_eq!(read(&path).unwrap(), s);
        let _ = fs::remove_dir_all(&dir);
    }

    #[test]
    fn parameters_are_written_when_set_and_optional_when_read() {
        let mut s = session();
        let plain = serde_json::to_string(&s).unwrap();
        assert!(!plain.contains("\"params\""), "{plain}");
        assert_eq!(parse(&plain).unwrap().params, BTreeMap::new());
        s.params.insert("bays".into(), 6.0.into());
        let text = serde_json::to_string(&s).unwrap();
        assert!(text.contains("\"params\":{\"bays\":6.0}"), "{text}");
        assert_eq!(parse(&text).unwrap(), s);
    }

    #[test]
    fn mistakes_say_what_is_wrong_and_where() {
        let good = serde_json::to_string_pretty(&session()).unwrap();
        let m = malformed("{\n  \"format\": \"clay-session\",\n  oops\n}");
        assert!(
            m.contains("invalid JSON") && m.contains("line 3 column 3"),
            "{m}"
        );
        assert!(malformed("[1, 2]").contains("\"format\" must be"));
        let v2 = good.replacen("\"version\": 1", "\"version\": 2", 1);
        assert!(malformed(&v2).contains("version 2 is not supported"));
        let no_version = good.replacen("\"version\": 1,", "", 1);
        assert!(malformed(&no_version).contains("no numeric \"version\""));
        // A body that does not fit: the field named, at its line and column.
        let bad = good.replacen("\"pins\": [", "\"pins\": [7, ", 1);
        let m = malformed(&bad);
        assert!(m.starts_with("malformed session file"), "{m}");
        let line = bad.lines().position(|l| l.contains("\"pins\"")).unwrap() + 1;
        assert!(m.contains(&format!("line {line} column")), "{m}");
        match read(Path::new("/nonexistent/clay/s.json")) {
            Err(e @ SessionError::Io { .. }) => {
                assert!(
                    e.to_string().starts_with("/nonexistent/clay/s.json: "),
                    "{e}"
                )
            }
            other => panic!("expected an I/O error, got {other:?}"),
        }
    }
}
