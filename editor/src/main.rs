//! The `clay-editor` binary: reads the arguments, opens the window and runs the editor.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use clay_editor::EditorApp;

/// Sculpt a Clay grammar's model live: drag, turn, pin and cut it while the mutable elastic
/// solver keeps every part in its best rest state. Press F1 in the window for every gesture.
#[derive(Parser, Debug)]
#[command(name = "clay-editor", version)]
struct Args {
    /// The grammar to open (`.clay`, or a compiled `.json`); the bundled castle without one.
    grammar: Option<PathBuf>,
    /// Follow the text editor: highlight what its cursor is on (through `clayc lsp`), and
    /// show a part's declaration there with G (docs/editors.md).
    #[arg(long)]
    follow: bool,
}

fn main() -> ExitCode {
    let args = Args::parse();
    if let Some(missing) = clay_editor::files::no_display() {
        eprintln!("clay-editor: {missing}");
        return ExitCode::from(1);
    }
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title(clay_editor::app::TITLE)
            .with_inner_size([1280.0, 800.0]),
        ..Default::default()
    };
    let result = eframe::run_native(
        "Clay editor",
        options,
        Box::new(move |cc| {
            let mut app = match &args.grammar {
                Some(p) => EditorApp::open(p),
                None => EditorApp::bundled(),
            };
            app.set_waker(cc.egui_ctx.clone());
            if let Some(path) = clay_editor::recovery::default_path() {
                app.use_recovery(path);
            }
            app.use_desktop(clay_editor::files::Desktop::detect());
            if args.follow {
                let channel = clay_dsl::analysis::follow::channel();
                app.follow = Some(clay_editor::follow::Follow::new(channel));
            }
            Ok(Box::new(app))
        }),
    );
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // One line, in words: winit's and glutin's errors are nested debug structures.
            eprintln!("clay-editor: cannot open a window: {}", one_line(&e));
            ExitCode::from(1)
        }
    }
}

/// An eframe error as a single line of text.
fn one_line(e: &eframe::Error) -> String {
    e.to_string()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}
