//! Sculpt session files: the versioned JSON form of a sculpt (grammar path, deformed assembly,
//! pins, solver settings), read with clear errors and written atomically. The format is the
//! library's (`clay::session_file`), so `clayc run|render|export --session` replays what the
//! editor saves; this module keeps the editor's paths to it.

pub use clay::session_file::*;
