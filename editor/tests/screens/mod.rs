//! The editor screenshots in `docs/pictures/`: each scene drives the real app headless
//! (egui_kittest, rendered by wgpu) to a state worth showing. `tests/screenshots.rs` renders
//! them and compares with the files; `examples/screenshots.rs` writes them.

use std::path::{Path, PathBuf};

use clay_editor::EditorApp;
use clay_editor::sculpt::Command;
use egui_kittest::Harness;
use glam::DVec2;

/// Where the pictures live.
pub fn pictures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/pictures")
}

/// A bundled grammar, by a path relative to the crate (the status bar shows it, and the
/// pictures must not show where the checkout is).
fn grammar(name: &str) -> PathBuf {
    std::env::set_current_dir(env!("CARGO_MANIFEST_DIR")).expect("the crate's folder");
    Path::new("../grammars").join(name)
}

fn harness(app: EditorApp) -> Harness<'static, EditorApp> {
    Harness::builder()
        .with_size(egui::Vec2::new(1200.0, 760.0))
        .with_max_steps(8)
        .wgpu()
        .build_ui_state(|ui, app: &mut EditorApp| app.frame(ui), app)
}

fn settle(h: &mut Harness<'_, EditorApp>) {
    for _ in 0..400 {
        h.step();
        if !h.state().sculpt.needs_work() {
            break;
        }
    }
    // A few more frames for the panels to catch up with the last solve.
    for _ in 0..4 {
        h.step();
    }
}

/// Pins the wall's first brick and pulls its last one east by `by` metres, still holding it.
fn pull_wall(h: &mut Harness<'_, EditorApp>, by: f64) {
    let at = h.state().sculpt.assembly().part_centroid(0);
    h.state_mut().command(Command::TogglePin { part: 0, at });
    settle(h);
    let last = h.state().sculpt.data().parts.len() - 1;
    let at = h.state().sculpt.assembly().part_centroid(last);
    h.state_mut().command(Command::Grab { part: last, at });
    for k in 1..=60 {
        h.state_mut().command(Command::MoveGrab {
            translation: DVec2::new(by * k as f64 / 60.0, 0.0),
            angle: 0.0,
        });
        h.step();
        // Every move solved to rest before the next, whatever the machine's speed: the UI
        // frame's time budget would otherwise decide how far the solver got, and so where
        // the rules fired.
        h.state_mut()
            .sculpt
            .step(std::time::Duration::from_secs(60));
    }
    settle(h);
    h.state_mut().canvas.request_fit();
    h.step();
    h.step();
}

/// The scenes: file name and the harness in the state to show.
pub fn scenes() -> Vec<(&'static str, Harness<'static, EditorApp>)> {
    let mut out = Vec::new();

    // The wall pulled to 1.6x with the strain, state and handle overlays: the rule log says
    // which bricks were inserted.
    let mut h = harness(EditorApp::open(&grammar("wall.clay")));
    settle(&mut h);
    {
        let o = &mut h.state_mut().overlays;
        o.strain = true;
        o.handles = true;
        o.sites = true;
    }
    pull_wall(&mut h, 4.8);
    out.push(("editor-wall-pulled.png", h));

    // The castle with docking sites and rest states shown, and the help over it.
    let mut h = harness(EditorApp::bundled());
    settle(&mut h);
    {
        let o = &mut h.state_mut().overlays;
        o.sites = true;
        o.states = true;
        o.part_graph = true;
    }
    h.step();
    out.push(("editor-overlays.png", h));

    let mut h = harness(EditorApp::bundled());
    settle(&mut h);
    h.state_mut().help_open = true;
    for _ in 0..3 {
        h.step();
    }
    out.push(("editor-help.png", h));
    out
}
