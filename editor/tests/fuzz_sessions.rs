//! Session files fuzzed (issue 37): seeded mutations of sessions the editor writes (the
//! castle as opened and sculpted) are read as a session and restored onto their grammar,
//! then solved for a few frames: no panic and no hang, a malformed file only an error.
//! `CLAY_FUZZ_CASES` and `CLAY_FUZZ_SEED` as for `tests/fuzz.rs`.

#[allow(dead_code)]
#[path = "../../tests/fuzzing/mod.rs"]
mod fuzzing;

use std::sync::{Arc, OnceLock};
use std::time::Duration;

use clay_dsl::compiled::CompiledGrammar;
use clay_editor::EditorApp;
use clay_editor::compile::{CASTLE_PATH, CASTLE_SOURCE, compile};
use clay_editor::sculpt::{Command, Sculpt};
use clay_editor::session;
use glam::DVec2;

fn castle() -> Arc<CompiledGrammar> {
    static CASTLE: OnceLock<Arc<CompiledGrammar>> = OnceLock::new();
    CASTLE
        .get_or_init(|| compile(CASTLE_SOURCE, CASTLE_PATH, &[]).unwrap().grammar)
        .clone()
}

/// The castle as opened, and after a drag of one part.
fn corpus() -> Vec<Vec<u8>> {
    let mut app = EditorApp::bundled();
    let opened = serde_json::to_vec_pretty(&app.session()).unwrap();
    let part = app.sculpt.data().parts.len() - 1;
    let at = app.sculpt.assembly().part_centroid(part);
    app.sculpt.apply(Command::Grab { part, at });
    app.sculpt.apply(Command::MoveGrab {
        translation: DVec2::new(0.5, -1.0),
        angle: 0.3,
    });
    for _ in 0..10 {
        app.sculpt.step(Duration::from_millis(20));
    }
    app.sculpt.apply(Command::Release);
    app.sculpt.apply(Command::TogglePin { part, at });
    let sculpted = serde_json::to_vec_pretty(&app.session()).unwrap();
    vec![opened, sculpted]
}

/// Reads, restores and solves one input.
fn restore(input: &[u8]) -> Result<(), String> {
    let Ok(text) = std::str::from_utf8(input) else {
        return Ok(());
    };
    let Ok(s) = session::parse(text) else {
        return Ok(());
    };
    if let Ok(mut sculpt) = Sculpt::from_saved(castle(), s.assembly, s.pins, s.settings, s.log) {
        for _ in 0..3 {
            sculpt.step(Duration::from_millis(5));
        }
    }
    Ok(())
}

#[test]
fn sessions_mutated_never_panic_or_hang() {
    fuzzing::fuzz("session", corpus(), restore);
}
