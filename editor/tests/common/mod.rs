//! What the editor's UI tests share: the app in an egui_kittest harness, and stepping it until
//! the solver has settled.

use clay_editor::EditorApp;
use egui::Vec2;
use egui_kittest::Harness;

/// The app in a 1200 x 800 window, driven headless.
pub fn harness(app: EditorApp) -> Harness<'static, EditorApp> {
    Harness::builder()
        .with_size(Vec2::new(1200.0, 800.0))
        .with_max_steps(8)
        .build_ui_state(|ui, app: &mut EditorApp| app.frame(ui), app)
}

/// Steps until the solver has settled (each step is one UI frame with its solver budget).
pub fn settle(h: &mut Harness<'_, EditorApp>) {
    for _ in 0..300 {
        h.step();
        if !h.state().sculpt.needs_work() {
            return;
        }
    }
    panic!("the model did not settle");
}

/// In the typed-path dialog (no desktop dialog in tests): replaces the path with `path` and
/// presses Enter, then steps `frames` frames.
#[allow(dead_code)] // not every test binary that shares this module types a path
pub fn type_path(h: &mut Harness<'_, EditorApp>, path: &std::path::Path, frames: usize) {
    use egui_kittest::kittest::Queryable;
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    h.step();
    h.get_by_role(egui::accesskit::Role::TextInput)
        .type_text(&path.display().to_string());
    h.step();
    h.key_press(egui::Key::Enter);
    for _ in 0..frames {
        h.step();
    }
}

/// File > `item`, then the typed-path dialog's suggested path (no desktop dialog in tests).
#[allow(dead_code)] // not every test binary that shares this module opens the dialog
pub fn ask_path(h: &mut Harness<'_, EditorApp>, item: &str) -> String {
    use egui_kittest::kittest::Queryable;
    h.get_by_label("File").click();
    h.step();
    h.step();
    h.get_by_label(item).click();
    for _ in 0..4 {
        h.step();
    }
    let by = egui_kittest::kittest::By::new()
        .role(egui::accesskit::Role::TextInput)
        .label_contains("Path (relative");
    h.get(by).value().unwrap_or_default()
}
