//! The real editor UI driven without a display through egui_kittest: pointer drags on the
//! canvas sculpt the model, Ctrl+Z undoes the gesture, and a failed hot reload keeps the model
//! and shows the diagnostics.

mod common;

use std::time::{Duration, Instant};

use clay_dsl::compiled::PartKind;
use clay_editor::EditorApp;
use clay_editor::compile::CASTLE_SOURCE;
use egui::{Modifiers, Pos2, Vec2};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;

use common::{ask_path, harness, settle, type_path};

/// The first tower part (a piece part) of the castle.
fn tower(app: &EditorApp) -> usize {
    let s = &app.sculpt;
    s.data()
        .parts
        .iter()
        .position(|p| match p.kind {
            PartKind::Piece { instance } => {
                s.grammar().pieces[s.data().instances[instance].piece].name == "tower"
            }
            PartKind::Stretch { .. } => false,
        })
        .unwrap()
}

#[test]
fn dragging_a_part_sculpts_and_ctrl_z_undoes_the_gesture() {
    let mut h = harness(EditorApp::bundled());
    settle(&mut h);
    let before = h.state().sculpt.data().clone();
    let part = tower(h.state());
    let at = h.get_by_label(&format!("part {part}")).rect().center();

    h.hover_at(at);
    h.step();
    assert_eq!(
        h.state().canvas.hovered,
        Some(part),
        "the tower is under the cursor"
    );
    h.drag_at(at);
    h.step();
    let to = at + Vec2::new(80.0, -40.0);
    for k in 1..=4 {
        h.hover_at(at + (to - at) * (k as f32 / 4.0));
        h.step();
    }
    assert_eq!(
        h.state().sculpt.grabbed(),
        Some(part),
        "the tower is the handle"
    );
    h.step();
    h.drop_at(to);
    h.step();
    settle(&mut h);
    assert_eq!(h.state().sculpt.grabbed(), None);
    let after = h.state().sculpt.data().clone();
    let moved = h
        .state()
        .canvas
        .to_screen(h.state().sculpt.assembly().part_centroid(part))
        - at;
    assert!(
        (moved - (to - at)).length() < 10.0,
        "the tower follows the pointer: moved {moved:?}"
    );
    assert!(after != before, "the model changed");
    assert!(h.state().sculpt.dirty());

    h.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    h.step();
    assert!(
        h.state().sculpt.data() == &before,
        "Ctrl+Z restores the model before the drag"
    );
    h.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, egui::Key::Z);
    h.step();
    // Frames after the redo let the solver polish the pose, so compare within 0.1 mm.
    let redone = h.state().sculpt.data();
    assert!(redone.instances == after.instances && redone.docks == after.docks);
    let gap = redone
        .positions
        .iter()
        .zip(&after.positions)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f64::max);
    assert!(gap < 1e-4, "Ctrl+Shift+Z redoes the drag (gap {gap} m)");
}

#[test]
fn p_pins_the_part_under_the_cursor() {
    let mut h = harness(EditorApp::bundled());
    settle(&mut h);
    let part = tower(h.state());
    let at = h.get_by_label(&format!("part {part}")).rect().center();
    h.hover_at(at);
    h.step();
    h.key_press(egui::Key::P);
    h.step();
    assert!(h.state().sculpt.is_pinned(part));
    h.key_press(egui::Key::P);
    h.step();
    assert!(!h.state().sculpt.is_pinned(part));
}

#[test]
fn wheel_zooms_toward_the_cursor() {
    let mut h = harness(EditorApp::bundled());
    h.step();
    let at = Pos2::new(300.0, 300.0);
    h.hover_at(at);
    h.step();
    let world = h.state().canvas.to_world(at);
    let scale = h.state().canvas.camera.scale;
    h.event(egui::Event::MouseWheel {
        unit: egui::MouseWheelUnit::Point,
        delta: Vec2::new(0.0, 120.0),
        phase: egui::TouchPhase::Move,
        modifiers: Modifiers::NONE,
        source: egui::MouseWheelSource::Wheel,
    });
    for _ in 0..6 {
        h.step();
    }
    assert!(h.state().canvas.camera.scale > scale * 1.05, "zoomed in");
    let again = h.state().canvas.to_world(at);
    assert!(
        (again - world).length() < 1e-3 * scale.recip() * 100.0,
        "{again} vs {world}"
    );
}

#[test]
fn a_failed_hot_reload_keeps_the_model_and_shows_diagnostics() {
    let dir = std::env::temp_dir().join(format!("clay-editor-reload-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("castle.clay");
    std::fs::write(&path, CASTLE_SOURCE).unwrap();

    let mut h = harness(EditorApp::open(&path));
    settle(&mut h);
    assert!(h.state().problems.is_empty());
    let model = h.state().sculpt.data().clone();
    assert!(!model.parts.is_empty());

    // An editor saving by rename: write a broken grammar next to it and move it over.
    let tmp = dir.join("castle.clay.new");
    std::fs::write(&tmp, format!("{CASTLE_SOURCE}\npiece broken {{\n")).unwrap();
    std::fs::rename(&tmp, &path).unwrap();

    let start = Instant::now();
    while h.state().problems.is_empty() && start.elapsed() < Duration::from_secs(5) {
        std::thread::sleep(Duration::from_millis(50));
        h.step();
    }
    let app = h.state();
    assert!(app.stale, "the broken file is reported");
    assert!(!app.problems.is_empty());
    assert!(
        app.sculpt.data() == &model,
        "the last good model stays live"
    );
    let first = app.problems[0].to_string();
    assert!(first.contains("castle.clay:"), "{first}");
    h.step();
    h.get_by_label_contains("The file does not compile");
    h.get_by_label(&first);

    // Fix the file again: the model comes back and the errors go.
    std::fs::write(&path, CASTLE_SOURCE).unwrap();
    let start = Instant::now();
    while h.state().stale && start.elapsed() < Duration::from_secs(5) {
        std::thread::sleep(Duration::from_millis(50));
        h.step();
    }
    assert!(!h.state().stale);
    assert!(h.state().problems.is_empty());
}

#[test]
fn hot_reload_follows_the_imported_files() {
    let dir = std::env::temp_dir().join(format!("clay-editor-imports-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("lib")).unwrap();
    // The castle's declarations in a library; the main file keeps only its model.
    let at = CASTLE_SOURCE.find("\nmodel {").unwrap();
    let lib = dir.join("lib/castle.clay");
    std::fs::write(&lib, &CASTLE_SOURCE[..at]).unwrap();
    let path = dir.join("main.clay");
    let main = format!("import \"lib/castle.clay\"\n{}", &CASTLE_SOURCE[at..]);
    std::fs::write(&path, &main).unwrap();

    let mut h = harness(EditorApp::open(&path));
    settle(&mut h);
    assert!(h.state().problems.is_empty(), "{:?}", h.state().problems);
    assert!(!h.state().sculpt.data().parts.is_empty());

    // Break the library: the main file did not change, yet the problem shows, in the library.
    std::fs::write(&lib, format!("{}\npiece broken {{\n", &CASTLE_SOURCE[..at])).unwrap();
    let start = Instant::now();
    while h.state().problems.is_empty() && start.elapsed() < Duration::from_secs(5) {
        std::thread::sleep(Duration::from_millis(50));
        h.step();
    }
    let app = h.state();
    assert!(app.stale, "the broken library is reported");
    assert!(
        app.problems[0].file.ends_with("castle.clay") && app.problems[0].file.contains("lib"),
        "{}",
        app.problems[0]
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn closing_with_unsaved_changes_asks_first() {
    let mut h = harness(EditorApp::bundled());
    h.step();
    // Nothing sculpted: a close request goes through.
    request_close(&mut h);
    assert!(!h.state().confirming());

    h.state_mut().command(clay_editor::sculpt::Command::Reset);
    h.step();
    assert!(h.state().sculpt.dirty());
    request_close(&mut h);
    assert!(
        h.state().confirming(),
        "the unsaved sculpt is confirmed first"
    );
    let cancelled = h
        .output()
        .viewport_output
        .values()
        .any(|v| v.commands.contains(&egui::ViewportCommand::CancelClose));
    assert!(cancelled, "the close is held back");
    h.step();
    h.get_by_label("Discard").click();
    h.step();
    assert!(!h.state().confirming());
    let closing = h
        .output()
        .viewport_output
        .values()
        .any(|v| v.commands.contains(&egui::ViewportCommand::Close));
    assert!(closing, "after Discard the window closes");
}

#[test]
fn opening_another_file_with_unsaved_changes_asks_first() {
    let dir = temp_dir("open-ask");
    let other = dir.join("other.clay");
    std::fs::write(&other, CASTLE_SOURCE).unwrap();
    let mut h = harness(EditorApp::bundled());
    h.state_mut().command(clay_editor::sculpt::Command::Reset);
    h.step();
    let kept = h.state().sculpt.data().clone();
    h.state_mut()
        .perform(clay_editor::action::Action::OpenGrammar(other.clone()));
    assert!(h.state().confirming());
    // A new modal is laid out invisibly on its first frame.
    h.step();
    h.step();
    h.get_by_label("Save");
    h.get_by_label("Discard");
    h.get_by_label("Cancel").click();
    h.step();
    assert!(!h.state().confirming());
    assert!(h.state().sculpt.data() == &kept, "cancel keeps the sculpt");
    assert_eq!(h.state().grammar_path(), None, "still the bundled castle");
}

#[test]
fn a_failed_open_keeps_the_model_and_asks_nothing() {
    let mut h = harness(EditorApp::bundled());
    h.state_mut().command(clay_editor::sculpt::Command::Reset);
    settle(&mut h);
    let kept = h.state().sculpt.data().clone();
    assert!(!kept.parts.is_empty());
    h.state_mut()
        .perform(clay_editor::action::Action::OpenGrammar(
            "no/such/file.clay".into(),
        ));
    assert!(
        !h.state().confirming(),
        "a file that cannot be read is not worth discarding the sculpt for"
    );
    h.step();
    let app = h.state();
    assert!(app.sculpt.data() == &kept, "the model stays");
    assert!(app.sculpt.dirty(), "and so does its unsaved state");
    assert_eq!(app.grammar_path(), None);
    let m = app.message.clone().unwrap_or_default();
    assert!(
        m.contains("no/such/file.clay was not opened") && m.contains("the current model stays"),
        "{m}"
    );
    assert!(
        app.sculpt
            .log()
            .iter()
            .any(|e| e.message.contains("was not opened")),
        "the failure is in the log"
    );

    // A file that reads but does not compile: the same, with its problems listed.
    let dir = temp_dir("open-broken");
    let broken = dir.join("broken.clay");
    std::fs::write(&broken, "piece broken {\n").unwrap();
    h.state_mut()
        .perform(clay_editor::action::Action::OpenGrammar(broken.clone()));
    assert!(!h.state().confirming());
    h.step();
    h.step();
    let app = h.state();
    assert!(app.sculpt.data() == &kept);
    let (file, problems) = app.refused.clone().expect("the refused file is shown");
    assert_eq!(file, broken.display().to_string());
    assert!(!problems.is_empty());
    h.get_by_label(&format!(
        "{} was not opened: the current model stays.",
        broken.display()
    ));
}

#[test]
fn save_in_the_prompt_saves_the_session_then_opens() {
    let dir = temp_dir("prompt-save");
    let other = dir.join("other.clay");
    std::fs::write(&other, CASTLE_SOURCE).unwrap();
    let session = dir.join("castle.session.json");
    let mut h = harness(EditorApp::bundled());
    h.state_mut().command(clay_editor::sculpt::Command::Reset);
    h.step();
    h.state_mut()
        .perform(clay_editor::action::Action::OpenGrammar(other.clone()));
    h.step();
    h.step();
    h.get_by_label("Save").click();
    h.step();
    h.step();
    // No session file yet: Save asks where (the typed path where no desktop dialog exists).
    h.step();
    h.get_by_label("Save session as");
    type_path(&mut h, &session, 4);
    assert!(session.exists(), "the session was saved first");
    assert_eq!(
        h.state().grammar_path(),
        Some(other.as_path()),
        "then the other grammar opened"
    );
    assert!(!h.state().sculpt.dirty());
}

fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("clay-editor-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn request_close(h: &mut Harness<'_, EditorApp>) {
    h.input_mut()
        .viewports
        .entry(egui::ViewportId::ROOT)
        .or_default()
        .events
        .push(egui::ViewportEvent::Close);
    h.step();
}

#[test]
fn right_drag_turns_the_grabbed_part() {
    let mut h = harness(EditorApp::bundled());
    settle(&mut h);
    let part = tower(h.state());
    let vertices = h.state().sculpt.data().parts[part].vertices.clone();
    let edge = |h: &Harness<'_, EditorApp>| {
        let p = &h.state().sculpt.data().positions;
        p[vertices[1]] - p[vertices[0]]
    };
    let e0 = edge(&h);
    let centre = h.get_by_label(&format!("part {part}")).rect().center();
    let button = |pos: Pos2, pressed: bool| egui::Event::PointerButton {
        pos,
        button: egui::PointerButton::Secondary,
        pressed,
        modifiers: Modifiers::NONE,
    };
    // Press to the right of the centre and swing a quarter turn counter-clockwise (screen y
    // points down, so "up" on screen is north).
    let start = centre + Vec2::new(30.0, 0.0);
    h.hover_at(start);
    h.event(button(start, true));
    h.step();
    for k in 1..=6 {
        let a = std::f32::consts::FRAC_PI_2 * k as f32 / 6.0;
        h.hover_at(centre + Vec2::new(30.0 * a.cos(), -30.0 * a.sin()));
        h.step();
    }
    // The solver catches up with the last move while the button is held: within a frame when
    // the machine is idle, a few more when a loaded one cuts frames at the UI's time budget
    // (how fast is the drag bench's question, not this test's).
    for _ in 0..200 {
        h.step();
        if !h.state().sculpt.needs_work() {
            break;
        }
    }
    let turned = e0.angle_to(edge(&h));
    h.event(button(centre + Vec2::new(0.0, -30.0), false));
    h.step();
    assert!(
        (turned - std::f64::consts::FRAC_PI_2).abs() < 0.15,
        "the tower turned by {turned} rad"
    );
}

/// Drags the tower by (80, -40) points with the left button, as a user would.
fn drag_tower(h: &mut Harness<'_, EditorApp>) {
    let part = tower(h.state());
    let at = h.get_by_label(&format!("part {part}")).rect().center();
    h.hover_at(at);
    h.step();
    h.drag_at(at);
    h.step();
    let to = at + Vec2::new(80.0, -40.0);
    for k in 1..=4 {
        h.hover_at(at + (to - at) * (k as f32 / 4.0));
        h.step();
    }
    h.drop_at(to);
    h.step();
    settle(h);
}

/// Whether the status bar says the castle has unsaved changes (`grammars/castle.clay
/// (unsaved)`) or not (`grammars/castle.clay`).
fn status_unsaved(h: &Harness<'_, EditorApp>) -> bool {
    let path = clay_editor::compile::CASTLE_PATH;
    let unsaved = h.query_by_label(&format!("{path} (unsaved)")).is_some();
    let saved = h.query_by_label(path).is_some();
    assert!(unsaved != saved, "the status bar shows the file once");
    unsaved
}

#[test]
fn undoing_every_change_counts_as_saved() {
    let dir = temp_dir("undo-saved");
    let mut h = harness(EditorApp::bundled());
    settle(&mut h);
    drag_tower(&mut h);
    drag_tower(&mut h);
    assert!(h.state().sculpt.dirty());
    assert!(status_unsaved(&h));

    // Both drags undone: the model is the one opened, so nothing is unsaved.
    for _ in 0..2 {
        h.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
        h.step();
    }
    assert!(!h.state().sculpt.can_undo());
    assert!(!h.state().sculpt.dirty(), "every change undone");
    h.step();
    assert!(!status_unsaved(&h));
    request_close(&mut h);
    assert!(!h.state().confirming(), "quitting asks nothing");

    // Redo one, save there: undoing it is unsaved again, redoing it saved again.
    h.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, egui::Key::Z);
    h.step();
    assert!(h.state().sculpt.dirty());
    let session = dir.join("castle.clay-session.json");
    h.state_mut().save_session(&session).unwrap();
    assert!(!h.state().sculpt.dirty());
    h.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    h.step();
    assert!(
        h.state().sculpt.dirty(),
        "the saved model was the one with the drag"
    );
    h.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, egui::Key::Z);
    h.step();
    assert!(!h.state().sculpt.dirty(), "redone to the saved model");
}

#[test]
fn the_unsaved_prompts_buttons_stay_put_whatever_the_message() {
    let dir = temp_dir("prompt-places");
    let other = dir.join("other.clay");
    std::fs::write(&other, CASTLE_SOURCE).unwrap();
    let mut h = harness(EditorApp::bundled());
    h.state_mut().command(clay_editor::sculpt::Command::Reset);
    h.step();
    let mut places = Vec::new();
    for action in [
        clay_editor::action::Action::Quit,
        clay_editor::action::Action::OpenGrammar(other.clone()),
    ] {
        h.state_mut().perform(action);
        assert!(h.state().confirming());
        // A new modal is laid out invisibly on its first frame.
        for _ in 0..4 {
            h.step();
        }
        let rects: Vec<egui::Rect> = ["Save", "Discard", "Cancel"]
            .iter()
            .map(|b| h.get_by_label(b).rect())
            .collect();
        places.push(rects);
        h.get_by_label("Cancel").click();
        h.step();
        assert!(!h.state().confirming());
    }
    assert_eq!(places[0], places[1], "the buttons sit where they sat");
}

#[test]
fn a_new_session_file_is_suggested_beside_the_grammar_not_in_the_working_folder() {
    let dir = temp_dir("session-default");
    let path = dir.join("castle.clay");
    std::fs::write(&path, CASTLE_SOURCE).unwrap();
    for (app, folder) in [
        (EditorApp::open(&path), Some(dir.clone())),
        (EditorApp::bundled(), None),
    ] {
        let mut h = harness(app);
        h.step();
        let text = ask_path(&mut h, "Save session");
        h.get_by_label("Save session as");
        let suggested = std::path::Path::new(&text);
        assert!(suggested.is_absolute(), "{text}");
        if let Some(folder) = &folder {
            assert_eq!(suggested, folder.join("castle.clay-session.json"));
        }
    }
}

/// Issue 48: "Save gestures as script" suggested `grammars/wall.script.json`, the bundled
/// demo, and replaced it. A typed path that exists is written only after Replace; Cancel
/// leaves the file as it was.
#[test]
fn a_save_to_a_file_that_exists_asks_before_replacing_it() {
    let dir = temp_dir("save-replace");
    let grammar = dir.join("wall.clay");
    let script = dir.join("wall.script.json");
    let demo = "{\"steps\": [{\"hold\": {\"frames\": 3}}]}\n";
    std::fs::write(&grammar, include_str!("../../grammars/wall.clay")).unwrap();
    std::fs::write(&script, demo).unwrap();
    let mut h = harness(EditorApp::open(&grammar));
    h.step();
    let ask = |h: &mut Harness<'_, EditorApp>| ask_path(h, "Save gestures as script…");
    // The suggestion is a name no file has.
    let suggested = ask(&mut h);
    assert_eq!(
        std::path::Path::new(&suggested),
        std::path::absolute(dir.join("wall-2.script.json")).unwrap()
    );
    // The demo's own name typed: asked, not written; Cancel keeps it.
    type_path(&mut h, &script, 3);
    h.get_by_label_contains("exists. Replace it?");
    assert_eq!(std::fs::read_to_string(&script).unwrap(), demo);
    h.get_by_label("Cancel").click();
    for _ in 0..3 {
        h.step();
    }
    assert_eq!(std::fs::read_to_string(&script).unwrap(), demo);
    // Asked again, and Replace: now it is written.
    ask(&mut h);
    type_path(&mut h, &script, 3);
    h.get_by_label("Replace").click();
    for _ in 0..4 {
        h.step();
    }
    let written = std::fs::read_to_string(&script).unwrap();
    assert_ne!(written, demo);
    assert!(clay::Script::parse(&written).is_ok(), "{written}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 48, item 7: the README's first drag (wall.clay at the default zoom, the leftmost
/// brick pinned, the rightmost dragged right) had no room: the fitted wall reaches the canvas's
/// edge. Held at the edge, the view follows the drag, and the wall grows bricks.
#[test]
fn the_readmes_first_drag_has_room_at_the_default_zoom() {
    let mut h = harness(EditorApp::open(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../grammars/wall.clay"),
    ));
    settle(&mut h);
    let first = h.get_by_label("part 0").rect().center();
    h.hover_at(first);
    h.step();
    h.key_press(egui::Key::P);
    h.step();
    settle(&mut h);
    let bricks = h.state().sculpt.data().instances.len();
    let last = h.state().sculpt.data().parts.len() - 1;
    let at = h.get_by_label(&format!("part {last}")).rect().center();
    let edge = h.state().canvas.rect.max.x - 2.0;
    assert!(
        edge - at.x < 200.0,
        "the fitted wall ends {} px from the edge",
        edge - at.x
    );
    h.hover_at(at);
    h.step();
    h.drag_at(at);
    h.step();
    let to = Pos2::new(edge, at.y);
    for k in 1..=8 {
        h.hover_at(at + (to - at) * (k as f32 / 8.0));
        h.step();
    }
    // Held at the edge for about two seconds of frames.
    for _ in 0..120 {
        h.hover_at(to);
        h.step();
    }
    let grown = h.state().sculpt.data().instances.len();
    h.drop_at(to);
    h.step();
    assert!(
        grown >= bricks + 3,
        "{bricks} bricks, {grown} while held at the edge"
    );
}

/// Drags `part` by `by` metres with the left button and lets go, then lets the model settle.
fn drag_part(h: &mut Harness<'_, EditorApp>, part: usize, by: glam::DVec2) {
    let at = h.get_by_label(&format!("part {part}")).rect().center();
    let world = h.state().canvas.to_world(at);
    let to = h.state().canvas.to_screen(world + by);
    h.hover_at(at);
    h.step();
    h.drag_at(at);
    h.step();
    for k in 1..=6 {
        h.hover_at(at + (to - at) * (k as f32 / 6.0));
        h.step();
    }
    h.drop_at(to);
    h.step();
    settle(h);
}

#[test]
fn a_dragged_part_springs_back_unless_pinned_as_the_readme_says() {
    let mut h = harness(EditorApp::open(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../grammars/wall.clay"),
    ));
    settle(&mut h);
    let last = h.state().sculpt.data().parts.len() - 1;
    let x = |h: &Harness<'_, EditorApp>| h.state().sculpt.assembly().part_centroid(last).x;
    // The first brick pinned (P over it), the last dragged 0.5 m east and let go: the wall
    // relaxes and the brick springs back.
    let first = h.get_by_label("part 0").rect().center();
    h.hover_at(first);
    h.step();
    h.key_press(egui::Key::P);
    h.step();
    let rest = x(&h);
    drag_part(&mut h, last, glam::DVec2::new(0.5, 0.0));
    assert!(
        (x(&h) - rest).abs() < 0.05,
        "sprang back: {} vs {rest}",
        x(&h)
    );
    // Pinned first, then dragged: it stays where it is dropped.
    let at = h.get_by_label(&format!("part {last}")).rect().center();
    h.hover_at(at);
    h.step();
    h.key_press(egui::Key::P);
    h.step();
    drag_part(&mut h, last, glam::DVec2::new(0.5, 0.0));
    assert!(
        (x(&h) - (rest + 0.5)).abs() < 0.05,
        "stayed where dropped: {} vs {}",
        x(&h),
        rest + 0.5
    );
    let readme = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../README.md"),
    )
    .unwrap();
    assert!(
        readme.contains("springs back"),
        "the README's first five minutes say so"
    );
}
