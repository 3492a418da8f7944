//! What the editor shows and tells, driven headless through egui_kittest: the window title
//! with its unsaved marker, the View menu's overlays (drawn by the renderer's overlay code),
//! the F1 help, the rule log following undo and kept in sessions and in the user's words,
//! failed reloads in the log, and a click on a diagnostic showing its line.

mod common;

use std::path::{Path, PathBuf};
use std::time::Duration;

use clay_editor::EditorApp;
use clay_editor::compile::CASTLE_SOURCE;
use clay_editor::sculpt::Command;
use clay_editor::sculpt::panels::NAMES_NOTE;
use egui::Shape;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;

use common::{harness, settle};
use glam::DVec2;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("clay-editor-view-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn grammar(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../grammars")
        .join(name)
}

/// The titles the app sent to the window in the last frame.
fn titles(h: &Harness<'_, EditorApp>) -> Vec<String> {
    h.output()
        .viewport_output
        .values()
        .flat_map(|v| v.commands.iter())
        .filter_map(|c| match c {
            egui::ViewportCommand::Title(t) => Some(t.clone()),
            _ => None,
        })
        .collect()
}

/// Every text the last frame painted.
fn painted_texts(h: &Harness<'_, EditorApp>) -> Vec<String> {
    let mut out = Vec::new();
    for s in &h.output().shapes {
        collect_texts(&s.shape, &mut out);
    }
    out
}

fn collect_texts(shape: &Shape, out: &mut Vec<String>) {
    match shape {
        Shape::Text(t) => out.push(t.galley.text().to_string()),
        Shape::Vec(v) => v.iter().for_each(|s| collect_texts(s, out)),
        _ => {}
    }
}

fn count_circles(h: &Harness<'_, EditorApp>) -> usize {
    fn count(shape: &Shape) -> usize {
        match shape {
            Shape::Circle(_) => 1,
            Shape::Vec(v) => v.iter().map(count).sum(),
            _ => 0,
        }
    }
    h.output().shapes.iter().map(|s| count(&s.shape)).sum()
}

#[test]
fn the_title_names_the_file_and_marks_unsaved_changes() {
    let mut h = harness(EditorApp::bundled());
    h.step();
    assert_eq!(h.state().title(), "castle.clay \u{2022} Clay");
    h.state_mut().command(Command::Reset);
    let mut sent = Vec::new();
    for _ in 0..3 {
        h.step();
        sent.extend(titles(&h));
    }
    assert_eq!(h.state().title(), "castle.clay* \u{2022} Clay");
    assert_eq!(
        sent,
        vec!["castle.clay* \u{2022} Clay".to_string()],
        "the new title is sent to the window once"
    );
    let wall = grammar("wall.clay");
    let mut h = harness(EditorApp::open(&wall));
    h.step();
    assert_eq!(h.state().title(), "wall.clay \u{2022} Clay");
}

#[test]
fn view_menu_turns_on_the_renderers_overlays() {
    let mut h = harness(EditorApp::open(&grammar("bend.clay")));
    settle(&mut h);
    let plain_texts = painted_texts(&h);
    let plain_circles = count_circles(&h);
    assert!(!plain_texts.iter().any(|t| t == "strain 0"));

    h.get_by_label("View").click();
    h.step();
    h.step();
    h.get_by_label("Strain").click();
    h.step();
    assert!(
        h.state().overlays.strain,
        "the menu's checkbox turns strain on"
    );
    h.step();
    let texts = painted_texts(&h);
    assert!(
        texts.iter().any(|t| t == "strain 0"),
        "the strain legend is drawn: {texts:?}"
    );

    let app = h.state_mut();
    app.overlays.strain = false;
    app.overlays.states = true;
    app.overlays.sites = true;
    h.step();
    h.step();
    let texts = painted_texts(&h);
    // Every bend segment has alternatives (base, left, right): its state's name is shown.
    let parts = h.state().sculpt.data().parts.len();
    let names = texts.iter().filter(|t| *t == "base").count();
    assert_eq!(names, parts, "one state label per part: {texts:?}");
    assert!(
        count_circles(&h) > plain_circles,
        "site vertices are drawn as dots"
    );
    let _ = plain_texts;
}

#[test]
fn f1_shows_every_gesture_and_the_docs_list_them_too() {
    let mut h = harness(EditorApp::bundled());
    h.step();
    h.key_press(egui::Key::F1);
    h.step();
    h.step();
    assert!(h.state().help_open);
    h.get_by_label("Gestures and keys");
    h.get_by_label("Ctrl + click");
    h.key_press(egui::Key::F1);
    h.step();
    assert!(!h.state().help_open, "F1 again closes it");

    let docs =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/editor.md"))
            .unwrap();
    for table in [
        clay_editor::help::SCULPT,
        clay_editor::help::AUTHOR,
        clay_editor::help::GLOBAL,
    ] {
        for (keys, what) in table {
            let row = format!("| {keys} | {what} |");
            assert!(docs.contains(&row), "docs/editor.md lacks the row `{row}`");
        }
    }
}

/// Pulls the wall's last brick east by `by` metres and lets go.
fn pull(h: &mut Harness<'_, EditorApp>, by: f64) {
    let data = h.state().sculpt.data();
    let last = data.parts.len() - 1;
    let at = h.state().sculpt.assembly().part_centroid(last);
    h.state_mut().command(Command::Grab { part: last, at });
    for k in 1..=40 {
        h.state_mut().command(Command::MoveGrab {
            translation: DVec2::new(by * k as f64 / 40.0, 0.0),
            angle: 0.0,
        });
        h.step();
    }
    h.state_mut().command(Command::Release);
    settle(h);
}

#[test]
fn undo_takes_back_the_rules_log_lines_and_a_session_keeps_the_log() {
    let mut h = harness(EditorApp::open(&grammar("wall.clay")));
    settle(&mut h);
    let at = h.state().sculpt.assembly().part_centroid(0);
    h.state_mut().command(Command::TogglePin { part: 0, at });
    settle(&mut h);
    let before = h.state().sculpt.log().to_vec();
    pull(&mut h, 4.0);
    let after = h.state().sculpt.log().to_vec();
    let grew: Vec<_> = after
        .iter()
        .filter(|e| e.message.contains("became three bricks"))
        .collect();
    assert!(!grew.is_empty(), "the pull inserted bricks: {after:#?}");
    let line = &grew[0].message;
    assert!(
        line.contains("`wall` has") && line.contains(" inserted") && line.contains(" at ("),
        "in the grammar's names: {line}"
    );

    h.state_mut().command(Command::Undo);
    h.step();
    assert_eq!(
        h.state().sculpt.log(),
        &before[..],
        "undo takes the gesture's lines back"
    );
    h.state_mut().command(Command::Redo);
    h.step();
    assert_eq!(h.state().sculpt.log(), &after[..], "redo brings them again");

    let dir = scratch("session-log");
    let session = dir.join("wall.session.json");
    h.state_mut()
        .perform(clay_editor::action::Action::SaveSession(session.clone()));
    let mut again = EditorApp::bundled();
    again.perform(clay_editor::action::Action::OpenSession(session));
    assert_eq!(again.sculpt.log(), &after[..], "the session kept its log");
}

#[test]
fn a_failed_reload_is_logged_and_undo_leaves_that_line() {
    let dir = scratch("reload-log");
    let path = dir.join("castle.clay");
    std::fs::write(&path, CASTLE_SOURCE).unwrap();
    let mut app = EditorApp::open(&path);
    app.command(Command::Reset);
    app.apply();
    std::fs::write(&path, format!("{CASTLE_SOURCE}\npiece broken {{\n")).unwrap();
    app.reload();
    let failed = |app: &EditorApp| {
        app.sculpt
            .log()
            .iter()
            .any(|e| e.message.starts_with("reload failed:") && e.message.contains("castle.clay"))
    };
    assert!(failed(&app), "{:#?}", app.sculpt.log());
    app.command(Command::Undo);
    app.apply();
    assert!(
        failed(&app),
        "a failed reload is not part of the undone gesture"
    );
}

#[test]
fn clicking_a_diagnostic_shows_its_line_in_the_source_view() {
    let dir = scratch("diagnostic-click");
    let path = dir.join("broken.clay");
    let source = CASTLE_SOURCE.replacen("chain wall x 4", "chain wal x 4", 1);
    std::fs::write(&path, &source).unwrap();
    let mut h = harness(EditorApp::open(&path));
    h.step();
    h.step();
    let p = h
        .state()
        .problems
        .iter()
        .find(|p| p.code == "E011")
        .cloned()
        .expect("the unknown piece is reported");
    assert_eq!(p.snippet.trim(), "wall_s1 = chain wal x 4");
    // The snippet with its underline and the hint are in the panel.
    h.get_by_label_contains("^^^ ");
    h.get_by_label_contains("help: did you mean `wall`?");
    h.get_by_label(&p.to_string()).click();
    h.step();
    h.step();
    let view = h
        .state()
        .source_view
        .clone()
        .expect("the source view opened");
    assert_eq!(
        (view.line, view.col, view.end_col),
        (p.line, p.col, p.end_col)
    );
    h.get_by_label(&format!("{} | {}", p.line, p.snippet));
    let _ = Duration::ZERO;
}

#[test]
fn the_source_view_closes_once_its_problem_is_fixed_or_another_file_opens() {
    let dir = scratch("source-stale");
    let path = dir.join("castle.clay");
    std::fs::write(&path, CASTLE_SOURCE).unwrap();
    let typo = CASTLE_SOURCE.replacen("chain wall x 4", "chain wal x 4", 1);
    let mut h = harness(EditorApp::open(&path));
    h.step();
    // A typo saved, its diagnostic clicked: the Source view shows its line.
    let show_typo = |h: &mut Harness<'_, EditorApp>| {
        std::fs::write(&path, &typo).unwrap();
        h.state_mut().reload();
        h.step();
        h.step();
        let p = (h.state().problems.iter().find(|p| p.code == "E011"))
            .cloned()
            .expect("the typo is reported");
        h.get_by_label(&p.to_string()).click();
        h.step();
        h.step();
        let line = format!("{} | {}", p.line, p.snippet);
        h.get_by_label("Source");
        h.get_by_label(&line);
        line
    };
    let line = show_typo(&mut h);

    // Fixed and reloaded: "No problems", and the Source view no longer shows the old line.
    std::fs::write(&path, CASTLE_SOURCE).unwrap();
    h.state_mut().reload();
    h.step();
    h.step();
    h.get_by_label("No problems.");
    assert!(h.state().source_view.is_none());
    assert!(h.query_by_label("Source").is_none());
    assert!(h.query_by_label(&line).is_none());

    // The same after another grammar is opened over the broken one's view.
    show_typo(&mut h);
    h.state_mut()
        .perform(clay_editor::action::Action::OpenGrammar(grammar(
            "wall.clay",
        )));
    h.step();
    h.step();
    assert!(h.state().grammar_path().unwrap().ends_with("wall.clay"));
    assert!(h.state().source_view.is_none());
    assert!(h.query_by_label("Source").is_none());
}

#[test]
fn a_cut_click_that_finds_nothing_says_why_in_the_status_bar() {
    let mut app = EditorApp::bundled();
    app.command(Command::Cut {
        point: DVec2::new(1e4, 1e4),
    });
    app.apply();
    let m = app.message.clone().unwrap_or_default();
    assert!(m.starts_with("cut failed: "), "{m}");
}

#[test]
fn opened_files_are_remembered_and_offered_in_the_open_dialog() {
    let dir = scratch("recent");
    let store = dir.join("config").join("recent-files.json");
    let desktop = clay_editor::files::Desktop {
        native_dialogs: false,
        recent_store: Some(store.clone()),
    };
    let wall = grammar("wall.clay");
    let mut app = EditorApp::bundled();
    app.use_desktop(desktop.clone());
    app.perform(clay_editor::action::Action::OpenGrammar(wall.clone()));
    assert!(store.exists(), "the list is kept in the config folder");

    // A new editor reads the list; its typed Open dialog offers the file.
    let mut app = EditorApp::bundled();
    app.use_desktop(desktop);
    let remembered = std::path::absolute(&wall).unwrap();
    assert_eq!(app.recent.files[0].path, remembered);
    let mut h = harness(app);
    h.step();
    h.state_mut().perform(clay_editor::action::Action::Ask(
        clay_editor::files::FileKind::Grammar,
    ));
    for _ in 0..3 {
        h.step();
    }
    h.get_by_label(&remembered.display().to_string()).click();
    for _ in 0..3 {
        h.step();
    }
    assert_eq!(h.state().grammar_path(), Some(remembered.as_path()));
}

#[test]
fn the_iso_view_draws_the_live_model_as_clayc_does_and_takes_no_drags() {
    let mut h = harness(EditorApp::open(&grammar("keep.clay")));
    settle(&mut h);
    h.get_by_label("View").click();
    h.step();
    h.step();
    h.get_by_label("Isometric 3D").click();
    h.step();
    h.step();
    assert!(
        h.state().canvas.iso,
        "the menu's checkbox turns the iso view on"
    );
    let same_as_clayc = |h: &Harness<'_, EditorApp>| {
        let app = h.state();
        let picture = app.canvas.iso_picture.as_ref().expect("a picture is shown");
        let scene = clay::scene(
            app.sculpt.grammar(),
            app.sculpt.data(),
            &clay::ExportOptions::default(),
        );
        let want = clay::iso_pixmap(&scene, picture.size[0], picture.size[1]).unwrap();
        assert!(
            picture.pixels == want.data(),
            "the picture is clayc's iso view"
        );
        picture.size
    };
    let size = same_as_clayc(&h);
    assert!(size[0] > 100 && size[1] > 100, "{size:?}");

    // A drag across the picture neither grabs nor moves anything.
    let before = h.state().sculpt.data().positions.clone();
    let centre = h.state().canvas.rect.center();
    let button = |pos: egui::Pos2, pressed: bool| egui::Event::PointerButton {
        pos,
        button: egui::PointerButton::Primary,
        pressed,
        modifiers: egui::Modifiers::NONE,
    };
    h.hover_at(centre);
    h.event(button(centre, true));
    h.step();
    for k in 1..=6 {
        h.hover_at(centre + egui::Vec2::new(20.0 * k as f32, 0.0));
        h.step();
    }
    h.event(button(centre + egui::Vec2::new(120.0, 0.0), false));
    settle(&mut h);
    assert!(h.state().sculpt.grabbed().is_none());
    assert!(h.state().sculpt.data().positions == before, "nothing moved");

    // The live model: a change to the sculpt is drawn again, still as clayc draws it.
    pull_tower(&mut h);
    assert!(h.state().sculpt.data().positions != before);
    same_as_clayc(&h);

    // I goes back to the floor plan.
    h.key_press(egui::Key::I);
    h.step();
    assert!(!h.state().canvas.iso);
}

/// Pulls the keep's first part 2 m north through commands (as the canvas would) and lets go.
fn pull_tower(h: &mut Harness<'_, EditorApp>) {
    let at = h.state().sculpt.assembly().part_centroid(0);
    h.state_mut().command(Command::Grab { part: 0, at });
    for k in 1..=20 {
        h.state_mut().command(Command::MoveGrab {
            translation: DVec2::new(0.0, 2.0 * k as f64 / 20.0),
            angle: 0.0,
        });
        h.step();
    }
    h.state_mut().command(Command::Release);
    settle(h);
}

#[test]
fn rest_states_are_labelled_on_the_wall_and_the_castle() {
    for app in [EditorApp::open(&grammar("wall.clay")), EditorApp::bundled()] {
        let mut h = harness(app);
        settle(&mut h);
        h.state_mut().overlays.states = true;
        h.step();
        h.step();
        let data = h.state().sculpt.data();
        // Every part with alternatives: the chains' stretch parts (`one`, `two`, `three`)
        // and pieces with more than one rest state.
        let named: Vec<String> = (data.parts.iter())
            .filter(|p| {
                p.states.len() > 1 || matches!(p.kind, clay_dsl::compiled::PartKind::Stretch { .. })
            })
            .map(|p| p.states[p.active].name.clone())
            .collect();
        assert!(named.len() > 3, "{} parts with alternatives", named.len());
        let texts = painted_texts(&h);
        assert!(named.iter().any(|n| n == "two"), "{named:?}");
        let mut names = named.clone();
        names.sort();
        names.dedup();
        for name in &names {
            let want = named.iter().filter(|n| *n == name).count();
            let got = texts.iter().filter(|t| *t == name).count();
            assert_eq!(got, want, "`{name}` on every part in it: {texts:?}");
        }
    }
}

#[test]
fn after_fit_the_strain_legend_covers_none_of_the_model() {
    let mut h = harness(EditorApp::bundled());
    settle(&mut h);
    h.get_by_label("View").click();
    h.step();
    h.step();
    h.get_by_label("Strain").click();
    h.step();
    h.key_press(egui::Key::Escape);
    h.step();
    h.get_by_label("Fit").click();
    h.step();
    h.step();
    let app = h.state();
    let [x, y, w, ht] = clay::STRAIN_LEGEND;
    let legend =
        egui::Rect::from_min_size(app.canvas.rect.min + egui::vec2(x, y), egui::vec2(w, ht));
    assert!(painted_texts(&h).iter().any(|t| t == "strain 0"));
    let top = (app.sculpt.data().positions.iter())
        .map(|p| app.canvas.to_screen(*p).y)
        .fold(f32::INFINITY, f32::min);
    assert!(
        top > legend.max.y,
        "the model's top ({top}) is below the legend's plate ({legend:?})"
    );
}

#[test]
fn the_inspector_and_parameters_say_what_they_mean() {
    let mut h = harness(EditorApp::open(&grammar("bend.clay")));
    settle(&mut h);
    let part = 0;
    let at = h.get_by_label(&format!("part {part}")).rect().center();
    h.hover_at(at);
    h.step();
    h.step();
    let report = h.state().sculpt.inspect(part).unwrap();
    let active = &report.why.states[report.why.active];
    // The sentence names the active state's misfit as the table shows it, and what the other
    // state's must fall below: no "fits 100% better".
    h.get_by_label_contains("would take over once its misfit is below");
    // (The names in the monospace font, without backticks: prose.)
    h.get_by_label_contains(&format!("{}'s {:.4} (the hysteresis)", active.0, active.1));
    h.get_by_label(&format!("{:.4}", active.1));
    assert!(h.query_by_label_contains("better").is_none());
    // The slider says which number it is.
    assert!(h.query_all_by_label("norm exponent p").count() > 0);
    assert!(h.query_by_label("p (norm)").is_none());
}

#[test]
fn inserted_elements_names_are_explained_beside_the_grammars() {
    let mut h = harness(EditorApp::open(&grammar("wall.clay")));
    settle(&mut h);
    // Shown as prose: the names in the monospace font, without their backticks.
    let note = NAMES_NOTE.replace('`', "");
    assert!(h.query_by_label(&note).is_none());
    let at = h.state().sculpt.assembly().part_centroid(0);
    h.state_mut().command(Command::TogglePin { part: 0, at });
    settle(&mut h);
    pull(&mut h, 4.0);
    assert!(
        (h.state().sculpt.log().iter()).any(|e| e.message.contains("wall#")),
        "bricks were inserted"
    );
    h.step();
    // The rule log says `wall#N` and `wall[N]`: the note says what each is.
    h.get_by_label(&note);
    assert!(
        h.query_by_label(NAMES_NOTE).is_none(),
        "backticks on screen"
    );
}

#[test]
fn open_recent_lists_the_command_line_grammar_and_a_tried_one() {
    let dir = scratch("recent-cli");
    let store = dir.join("config").join("recent-files.json");
    let wall = grammar("wall.clay");
    // As main.rs does: the grammar opened first, the desktop known after.
    let mut app = EditorApp::open(&wall);
    app.use_desktop(clay_editor::files::Desktop {
        native_dialogs: false,
        recent_store: Some(store.clone()),
    });
    let mut h = harness(app);
    h.step();
    h.get_by_label("File").click();
    h.step();
    h.step();
    h.get_by_label("Open recent").hover();
    h.step();
    h.step();
    assert!(h.query_by_label("Nothing opened yet.").is_none());
    let shown = |p: &Path| format!("{} (grammar)", std::path::absolute(p).unwrap().display());
    h.get_by_label(&shown(&wall));
    h.key_press(egui::Key::Escape);
    h.step();

    // A grammar written in Author mode and opened with Try it is listed too.
    let svg = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fixtures/authoring/wall.svg");
    let tried = dir.join("tried.clay");
    {
        use clay_editor::action::Action;
        let app = h.state_mut();
        app.set_mode(clay_editor::app::Mode::Author);
        app.perform(Action::ImportSvg(svg, 0.01));
        app.perform(Action::WriteGrammar(tried.clone()));
        app.perform(Action::TryAuthored);
    }
    h.step();
    assert_eq!(h.state().grammar_path(), Some(tried.as_path()));
    h.get_by_label("File").click();
    h.step();
    h.step();
    h.get_by_label("Open recent").hover();
    h.step();
    h.step();
    h.get_by_label(&shown(&tried));
    h.get_by_label(&shown(&wall));
    let kept = clay_editor::files::Recent::load(Some(&store));
    assert_eq!(kept.files[0].path, std::path::absolute(&tried).unwrap());
}

/// Issue 48, item 7: a long status message ran past the window's edge. The status line is one
/// line; the message is cut to the width left, and reads whole on hover.
#[test]
fn a_long_status_message_fits_the_status_line() {
    let mut h = harness(EditorApp::open(&grammar("wall.clay")));
    settle(&mut h);
    let long = format!(
        "{} the end",
        "`wall[5]` and `wall[6]` became three bricks: `wall#12` inserted; ".repeat(12)
    );
    h.state_mut().message = Some(long.clone());
    h.step();
    h.step();
    let shown = long.replace('`', "");
    let label = h.get_by_label(&shown);
    let r = label.rect();
    assert!(r.max.x <= 1200.5, "{r:?}");
    assert!(r.height() < 30.0, "one line: {r:?}");
}
