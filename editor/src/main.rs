//! The `clay-editor` binary: reads the arguments, opens the window and runs the editor.

use std::path::PathBuf;

use clay_editor::EditorApp;

fn main() -> eframe::Result {
    let mut args = std::env::args_os().skip(1);
    let path = args.next().map(PathBuf::from);
    if args.next().is_some() {
        eprintln!("usage: clay-editor [GRAMMAR.clay]");
        std::process::exit(2);
    }
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("Clay editor")
            .with_inner_size([1280.0, 800.0]),
        ..Default::default()
    };
    eframe::run_native(
        "Clay editor",
        options,
        Box::new(move |cc| {
            let mut app = match &path {
                Some(p) => EditorApp::open(p),
                None => EditorApp::bundled(),
            };
            app.set_waker(cc.egui_ctx.clone());
            Ok(Box::new(app))
        }),
    )
}
