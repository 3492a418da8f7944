//! The Grammar parameters panel (issue 39): a grammar's `param`s shown as sliders; a value set
//! recompiles the grammar as hot reload does; the value survives hot reloads of the file (fitted
//! to what the file declares) and goes when another grammar opens.

mod common;

use std::path::Path;
use std::time::{Duration, Instant};

use clay_editor::EditorApp;
use clay_editor::action::Action;
use clay_editor::sculpt::panels::ParamChange;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;

use common::{harness, settle};

/// `bays` posts in a chain, `bays` a parameter in 2..12.
fn posts(range: &str, colour: &str) -> String {
    format!(
        "\
param bays = 4{range}

site type joint

piece post {{
    vertex sw (0, 0)
    vertex se (1, 0)
    vertex ne (1, 0.5)
    vertex nw (0, 0.5)
    edges sw-se-ne-nw-sw, sw-ne, se-nw
    site west: joint [nw, sw] out (-1, 0)
    site east: joint [se, ne] out (1, 0)
    polygon skinned fill {colour} {{
        (0, 0) (1, 0) (1, 0.5) (0, 0.5)
    }}
}}

stretch post from west to east

model {{
    row = chain post x bays at (0, 0)
}}
"
    )
}

const RANGE: &str = " in 2..12";

fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("clay-editor-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The parameter's slider.
fn slider() -> egui_kittest::kittest::By<'static> {
    egui_kittest::kittest::By::new()
        .role(egui::accesskit::Role::Slider)
        .label("bays")
}

fn instances(h: &Harness<'_, EditorApp>) -> usize {
    h.state().sculpt.data().instances.len()
}

fn overrides(h: &Harness<'_, EditorApp>) -> Vec<(String, f64)> {
    (h.state().param_overrides().iter())
        .map(|(n, v)| (n.clone(), v.number().expect("a number")))
        .collect()
}

/// Rewrites the grammar file by rename (as editors save) and steps until hot reload took it.
fn rewrite(h: &mut Harness<'_, EditorApp>, path: &Path, text: &str) {
    let before = h.state().sculpt.grammar().clone();
    let tmp = path.with_extension("clay.new");
    std::fs::write(&tmp, text).unwrap();
    std::fs::rename(&tmp, path).unwrap();
    let start = Instant::now();
    while std::sync::Arc::ptr_eq(&before, h.state().sculpt.grammar())
        && start.elapsed() < Duration::from_secs(5)
    {
        std::thread::sleep(Duration::from_millis(50));
        h.step();
    }
    assert!(
        !std::sync::Arc::ptr_eq(&before, h.state().sculpt.grammar()),
        "hot reload took the new file"
    );
}

#[test]
fn a_grammar_parameter_is_set_from_the_panel_and_kept_across_hot_reloads() {
    let dir = temp_dir("params");
    let path = dir.join("posts.clay");
    std::fs::write(&path, posts(RANGE, "#b5651d")).unwrap();
    let mut h = harness(EditorApp::open(&path));
    settle(&mut h);
    assert!(h.state().problems.is_empty(), "{:?}", h.state().problems);
    assert_eq!(instances(&h), 4);
    h.get_by_label_contains("Grammar parameters");
    h.get(slider());
    h.get_by_label("default 4");

    // The panel's widget: the slider focused, the right arrow key one step up (a change not
    // made by the pointer is committed at once).
    h.get(slider()).focus();
    h.step();
    h.key_press(egui::Key::ArrowRight);
    h.step();
    h.step();
    assert_eq!(overrides(&h), [("bays".to_string(), 5.0)]);
    assert_eq!(instances(&h), 5);

    // What the panel emits on release: bays = 6.
    h.state_mut()
        .param_change(ParamChange::Set("bays".into(), 6.0.into()));
    h.step();
    settle(&mut h);
    assert_eq!(instances(&h), 6, "six posts");
    assert_eq!(overrides(&h), [("bays".to_string(), 6.0)]);
    assert!(
        h.state()
            .message
            .as_deref()
            .unwrap_or("")
            .starts_with("bays = 6"),
        "{:?}",
        h.state().message
    );
    h.get_by_label("parameters: bays = 6");

    // Undo takes the value back with the model it made; redo brings both again.
    h.state_mut().command(clay_editor::sculpt::Command::Undo);
    h.step();
    assert_eq!(instances(&h), 5);
    assert_eq!(overrides(&h), [("bays".to_string(), 5.0)]);
    h.state_mut().command(clay_editor::sculpt::Command::Redo);
    h.step();
    assert_eq!(instances(&h), 6);
    assert_eq!(overrides(&h), [("bays".to_string(), 6.0)]);

    // The file changed outside the editor: the value stays.
    rewrite(&mut h, &path, &posts(RANGE, "#8b4513"));
    settle(&mut h);
    assert_eq!(overrides(&h), [("bays".to_string(), 6.0)]);
    assert_eq!(instances(&h), 6, "the override survives hot reload");

    // A narrower range: the value is clamped, and the status says so.
    rewrite(&mut h, &path, &posts(" in 2..5", "#8b4513"));
    assert_eq!(overrides(&h), [("bays".to_string(), 5.0)]);
    assert_eq!(instances(&h), 5);
    let m = h.state().message.clone().unwrap_or_default();
    assert!(m.contains("clamped to 5"), "{m}");

    // Back to the default with the reset button.
    h.step();
    h.get_by_label("reset").click();
    h.step();
    h.step();
    assert!(overrides(&h).is_empty());
    assert_eq!(instances(&h), 4);

    // A value outside the range (a command, not the slider): clamped into it.
    h.state_mut()
        .param_change(ParamChange::Set("bays".into(), 9.0.into()));
    h.step();
    assert!(!h.state().stale);
    assert_eq!(overrides(&h), [("bays".to_string(), 5.0)]);
    assert_eq!(instances(&h), 5);
    h.state_mut()
        .param_change(ParamChange::Set("bays".into(), 3.0.into()));
    h.step();
    assert_eq!(instances(&h), 3);

    // A broken file: the errors are listed, the last good model and the value stay.
    std::fs::write(
        &path,
        format!("{}\npiece broken {{\n", posts(RANGE, "#8b4513")),
    )
    .unwrap();
    let start = Instant::now();
    while !h.state().stale && start.elapsed() < Duration::from_secs(5) {
        std::thread::sleep(Duration::from_millis(50));
        h.step();
    }
    assert!(h.state().stale && !h.state().problems.is_empty());
    assert_eq!(instances(&h), 3, "the last good model stays");
    assert_eq!(overrides(&h), [("bays".to_string(), 3.0)]);

    // The file no longer declares it: the value is dropped.
    rewrite(
        &mut h,
        &path,
        &posts("", "#8b4513").replace("param bays = 4\n", "let bays = 4\n"),
    );
    assert!(overrides(&h).is_empty());
    assert_eq!(instances(&h), 4);
    let m = h.state().message.clone().unwrap_or_default();
    assert!(m.contains("no longer a parameter"), "{m}");
    h.step();
    assert!(h.query_by_label_contains("Grammar parameters").is_none());
    let _ = std::fs::remove_dir_all(&dir);
}

/// The posts grammar written into `dir` and opened, `bays` set to 6 from the panel.
fn six_bays(dir: &Path) -> (std::path::PathBuf, Harness<'static, EditorApp>) {
    let path = dir.join("posts.clay");
    std::fs::write(&path, posts(RANGE, "#b5651d")).unwrap();
    let mut h = harness(EditorApp::open(&path));
    settle(&mut h);
    h.state_mut()
        .param_change(ParamChange::Set("bays".into(), 6.0.into()));
    h.step();
    assert_eq!(instances(&h), 6);
    (path, h)
}

#[test]
fn opening_another_grammar_clears_the_parameters() {
    let dir = temp_dir("params-open");
    let path = dir.join("posts.clay");
    std::fs::write(&path, posts(RANGE, "#b5651d")).unwrap();
    let other = dir.join("other.clay");
    std::fs::write(&other, posts(RANGE, "#8b4513")).unwrap();
    let mut h = harness(EditorApp::open(&path));
    settle(&mut h);
    h.state_mut()
        .param_change(ParamChange::Set("bays".into(), 6.0.into()));
    h.step();
    assert_eq!(instances(&h), 6);
    h.state_mut().perform(Action::OpenGrammar(other.clone()));
    if h.state().confirming() {
        h.step();
        h.step();
        h.get_by_label("Discard").click();
        h.step();
    }
    assert_eq!(h.state().grammar_path(), Some(other.as_path()));
    assert!(overrides(&h).is_empty(), "{:?}", overrides(&h));
    assert_eq!(instances(&h), 4, "the other grammar at its defaults");
    h.step();
    assert!(h.query_by_label_contains("parameters: bays").is_none());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_saved_session_keeps_the_parameters_it_was_sculpted_with() {
    let dir = temp_dir("params-session");
    let (path, mut h) = six_bays(&dir);
    let saved = dir.join("posts.session.json");
    h.state_mut().save_session(&saved).unwrap();
    let text = std::fs::read_to_string(&saved).unwrap();
    assert!(text.contains("\"params\""), "{text}");

    // A fresh editor opens it: the grammar compiled with bays = 6, the model of 6 posts, and
    // the panel's value 6 (not the file's default 4).
    let mut fresh = harness(EditorApp::open(&path));
    settle(&mut fresh);
    assert_eq!(instances(&fresh), 4);
    fresh.state_mut().open_session(&saved).unwrap();
    fresh.step();
    assert_eq!(instances(&fresh), 6);
    assert_eq!(overrides(&fresh), vec![("bays".to_string(), 6.0)]);
    let bays = fresh
        .state()
        .sculpt
        .grammar()
        .params
        .iter()
        .find(|p| p.name == "bays");
    assert_eq!(bays.map(|p| p.value.clone()), Some(6.0.into()));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn saved_gestures_say_the_parameters_to_replay_them_with() {
    let dir = temp_dir("params-gestures");
    let (path, mut h) = six_bays(&dir);
    settle(&mut h);
    let script = dir.join("posts.script.json");
    let status = h.state().save_gestures(&script).unwrap();
    assert!(status.contains("--param bays=6"), "{status}");
    // Replayed on the grammar compiled with those values: the editor's model.
    let text = std::fs::read_to_string(&path).unwrap();
    let options = clay_dsl::CompileOptions::default().param("bays", 6.0);
    let grammar = clay_dsl::compile(&text, "posts.clay", &options)
        .unwrap()
        .grammar;
    let parsed = clay::Script::parse(&std::fs::read_to_string(&script).unwrap()).unwrap();
    // The script says them too, and refuses the grammar's defaults (issue 48, item 3).
    assert_eq!(parsed.params.get("bays"), Some(&6.0.into()));
    assert_eq!(parsed.check_params(&grammar), Ok(()));
    let defaults = clay_dsl::compile(&text, "posts.clay", &clay_dsl::CompileOptions::default())
        .unwrap()
        .grammar;
    assert!(parsed.check_params(&defaults).is_err());
    let mut asm = clay::Assembly::new(std::sync::Arc::new(grammar.clone()));
    let mut session = clay::Session::new(clay::SolverConfig::from_params(&grammar.solver));
    clay::replay(&mut asm, &parsed, &mut session).unwrap();
    assert_eq!(asm.data().instances.len(), instances(&h));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 48, item 7: at 1280 px the reset button sat past the side panel's edge, cut off. It is
/// on screen and inside the panel, left of its slider, with a long parameter name too.
#[test]
fn the_reset_button_is_on_screen_at_1280_px() {
    let dir = temp_dir("params-1280");
    let path = dir.join("posts.clay");
    let long = posts(RANGE, "#b5651d").replace("bays", "number_of_bays_along_the_fence");
    std::fs::write(&path, &long).unwrap();
    let mut h = Harness::builder()
        .with_size(egui::Vec2::new(1280.0, 800.0))
        .with_max_steps(8)
        .build_ui_state(
            |ui, app: &mut EditorApp| app.frame(ui),
            EditorApp::open(&path),
        );
    settle(&mut h);
    assert!(h.state().problems.is_empty(), "{:?}", h.state().problems);
    h.state_mut().param_change(ParamChange::Set(
        "number_of_bays_along_the_fence".into(),
        6.0.into(),
    ));
    settle(&mut h);
    let reset = h.get_by_label("reset").rect();
    let long_slider = egui_kittest::kittest::By::new()
        .role(egui::accesskit::Role::Slider)
        .label("number_of_bays_along_the_fence");
    let slider = h.get(long_slider).rect();
    assert!(reset.max.x <= 1280.0 && reset.min.x > 640.0, "{reset:?}");
    assert!(reset.max.x <= slider.min.x, "{reset:?} {slider:?}");
    h.get_by_label("default 4");
    h.get_by_label("reset").click();
    h.step();
    h.step();
    assert!(overrides(&h).is_empty());
}

/// Issue 48, item 3: a parameter change that rebuilds the model dropped every pin ("model
/// rebuilt"). The pins of instances the new model still has (by name) stay, each holding its
/// instance where it was pinned; a pin on an instance that is gone goes.
#[test]
fn a_count_change_keeps_the_pins_of_the_instances_that_survive() {
    let dir = temp_dir("params-pins");
    let path = dir.join("posts.clay");
    std::fs::write(&path, posts(RANGE, "#b5651d")).unwrap();
    let mut h = harness(EditorApp::open(&path));
    settle(&mut h);
    let name_of = |h: &Harness<'_, EditorApp>, v: &[usize]| {
        let data = h.state().sculpt.data();
        (data.instances.iter())
            .find(|i| i.vertices == v)
            .map(|i| i.name.clone())
    };
    // The west post pinned, then dragged 1.5 m north (a pinned part is pinned where dropped);
    // the east post (row[3]) pinned where it is.
    let data = h.state().sculpt.data();
    let last = data.parts.len() - 1;
    let west = h
        .state()
        .sculpt
        .assembly()
        .part_extreme(clay::Compass::West)
        .unwrap();
    let at = h.state().sculpt.assembly().part_centroid(west) - glam::DVec2::new(0.3, 0.0);
    h.state_mut()
        .command(clay_editor::sculpt::Command::TogglePin { part: west, at });
    h.state_mut()
        .command(clay_editor::sculpt::Command::Grab { part: west, at });
    h.state_mut()
        .command(clay_editor::sculpt::Command::MoveGrab {
            translation: glam::DVec2::new(0.0, 1.5),
            angle: 0.0,
        });
    settle(&mut h);
    h.state_mut().command(clay_editor::sculpt::Command::Release);
    let east_at = h.state().sculpt.assembly().part_centroid(last) + glam::DVec2::new(0.3, 0.0);
    h.state_mut()
        .command(clay_editor::sculpt::Command::TogglePin {
            part: last,
            at: east_at,
        });
    settle(&mut h);
    let pins = h.state().sculpt.pins();
    let mut before: Vec<(String, Vec<glam::DVec2>)> = pins
        .iter()
        .map(|p| (name_of(&h, &p.vertices).unwrap(), p.at.clone()))
        .collect();
    before.sort_by(|a, b| a.0.cmp(&b.0));
    assert_eq!(
        before.iter().map(|p| p.0.as_str()).collect::<Vec<_>>(),
        ["row[0]", "row[3]"]
    );

    // Six bays: both posts are still there; their pins hold them where they were.
    h.state_mut()
        .param_change(ParamChange::Set("bays".into(), 6.0.into()));
    settle(&mut h);
    assert_eq!(instances(&h), 6);
    let mut after: Vec<(String, Vec<glam::DVec2>)> = (h.state().sculpt.pins().iter())
        .map(|p| (name_of(&h, &p.vertices).unwrap(), p.at.clone()))
        .collect();
    after.sort_by(|a, b| a.0.cmp(&b.0));
    assert_eq!(after.len(), 2, "{after:?}");
    for ((n0, a0), (n1, a1)) in before.iter().zip(&after) {
        assert_eq!(n0, n1);
        let gap = a0
            .iter()
            .zip(a1)
            .map(|(p, q)| p.distance(*q))
            .fold(0.0, f64::max);
        assert!(gap < 1e-9, "{n0}'s pin moved by {gap} m");
    }
    let west_now = h.state().sculpt.assembly().instance_centroid(0).unwrap();
    assert!(west_now.y > 1.4, "the west post stays north: {west_now}");
    let m = h.state().message.clone().unwrap_or_default();
    assert!(m.contains("2 pins kept"), "{m}");

    // Two bays: row[3] is gone, and so is its pin; row[0]'s stays.
    h.state_mut()
        .param_change(ParamChange::Set("bays".into(), 2.0.into()));
    settle(&mut h);
    let kept: Vec<String> = (h.state().sculpt.pins().iter())
        .map(|p| name_of(&h, &p.vertices).unwrap())
        .collect();
    assert_eq!(kept, ["row[0]"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_bool_is_a_checkbox_and_a_choice_a_combo_box_of_its_pieces() {
    // keep.clay: `donjon` a bool, `gate` a choice of the great gate and the plain gatehouse.
    let keep = Path::new(env!("CARGO_MANIFEST_DIR")).join("../grammars/keep.clay");
    let mut h = harness(EditorApp::open(&keep));
    settle(&mut h);
    assert!(h.state().problems.is_empty(), "{:?}", h.state().problems);
    let pieces = |h: &Harness<'_, EditorApp>| -> Vec<String> {
        let g = h.state().sculpt.grammar().clone();
        let mut names: Vec<String> = (h.state().sculpt.data().instances.iter())
            .map(|i| g.pieces[i.piece].name.clone())
            .filter(|n| n != "wall" && n != "tower")
            .collect();
        names.sort();
        names
    };
    assert_eq!(pieces(&h), ["donjon", "great_gate"]);
    // The checkbox, clicked: the donjon goes.
    let checkbox = egui_kittest::kittest::By::new()
        .role(egui::accesskit::Role::CheckBox)
        .label("donjon");
    h.get(checkbox).click();
    h.step();
    settle(&mut h);
    assert_eq!(pieces(&h), ["great_gate"]);
    let set: Vec<(String, String)> = (h.state().param_overrides().iter())
        .map(|(n, v)| (n.clone(), v.to_string()))
        .collect();
    assert_eq!(set, [("donjon".to_string(), "false".to_string())]);
    // The combo box shows the chosen piece; opened, it lists both; the other one picked.
    let combo = egui_kittest::kittest::By::new()
        .role(egui::accesskit::Role::ComboBox)
        .label("gate");
    h.get(combo).click();
    h.step();
    h.step();
    h.get_all_by_label("gatehouse")
        .next()
        .expect("listed")
        .click();
    h.step();
    settle(&mut h);
    assert_eq!(pieces(&h), ["gatehouse"]);
}
