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
