//! The `clay-editor` binary: reads the arguments, opens the window and runs the editor. Its two
//! arguments are read here by hand (`--help`, `--version`, usage errors with exit code 2, as
//! `clayc`'s clap does), so the editor compiles no argument parser.

use std::ffi::OsString;
use std::path::PathBuf;
use std::process::ExitCode;

use clay_editor::EditorApp;

const USAGE: &str = "Usage: clay-editor [OPTIONS] [GRAMMAR]";

const HELP: &str = "\
Sculpt a Clay grammar's model live: drag, turn, pin and cut it while the mutable elastic solver \
keeps every part in its best rest state. Press F1 in the window for every gesture

Usage: clay-editor [OPTIONS] [GRAMMAR]

Arguments:
  [GRAMMAR]  The grammar to open (`.clay`, or a compiled `.json`); the bundled castle without one

Options:
      --follow   Follow the text editor: highlight what its cursor is on (through `clayc lsp`), \
and show a part's declaration there with G (docs/editors.md)
  -h, --help     Print help
  -V, --version  Print version
";

/// What the command line asks for.
#[derive(Debug, Default)]
struct Args {
    /// The grammar to open (`.clay`, or a compiled `.json`); the bundled castle without one.
    grammar: Option<PathBuf>,
    /// Follow the text editor: highlight what its cursor is on (through `clayc lsp`), and
    /// show a part's declaration there with G (docs/editors.md).
    follow: bool,
}

/// The arguments, or what to print instead of opening a window: the help or the version
/// (`Ok`, on standard output, exit 0) or a usage error (`Err`, on standard error, exit 2).
fn parse(args: impl IntoIterator<Item = OsString>) -> Result<Result<Args, String>, String> {
    let mut parsed = Args::default();
    let mut options = true;
    for arg in args {
        match arg.to_str() {
            Some("--") if options => options = false,
            Some("-h" | "--help") if options => return Ok(Err(HELP.to_string())),
            Some("-V" | "--version") if options => {
                return Ok(Err(format!("clay-editor {}\n", env!("CARGO_PKG_VERSION"))));
            }
            Some("--follow") if options => parsed.follow = true,
            Some(flag) if options && flag.starts_with('-') && flag != "-" => {
                return Err(usage_error(flag, true));
            }
            _ if parsed.grammar.is_none() => parsed.grammar = Some(PathBuf::from(arg)),
            _ => return Err(usage_error(&arg.to_string_lossy(), false)),
        }
    }
    Ok(Ok(parsed))
}

/// The usage error for an argument the editor does not take.
fn usage_error(arg: &str, flag: bool) -> String {
    let tip = if flag {
        format!("\n  tip: to pass '{arg}' as a value, use '-- {arg}'\n")
    } else {
        String::new()
    };
    format!(
        "error: unexpected argument '{arg}' found\n{tip}\n{USAGE}\n\nFor more information, try \
         '--help'.\n"
    )
}

fn main() -> ExitCode {
    let args = match parse(std::env::args_os().skip(1)) {
        Ok(Ok(args)) => args,
        Ok(Err(text)) => {
            print!("{text}");
            return ExitCode::SUCCESS;
        }
        Err(usage) => {
            eprint!("{usage}");
            return ExitCode::from(2);
        }
    };
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
                app.follow = Some(clay_editor::sculpt::follow::Follow::new(channel));
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
