//! The editor application: its state and one frame of it. [`EditorApp::logic`] does the work
//! outside the UI (hot reload, the close request, the solver's budget), [`EditorApp::ui`] lays
//! out the window, whose parts only collect [`Command`]s, authoring commands and [`Action`]s,
//! and [`EditorApp::apply`] applies them after the frame (as egui's demos and rerun do).
//!
//! The jobs are in the children: `document` (the open grammar, hot reload, sessions),
//! `params` (the grammar's parameters set from the editor), `perform` (file actions),
//! `export`, `menus` (menu bar, shortcuts, status bar), `dialogs` (modal prompts) and
//! `sculpt_view` (sculpt mode's canvas and side panels, from `crate::sculpt`, over the app's
//! state). They import this module; it imports none of them. Each mode's state, canvas and
//! panels are its own module's (`crate::sculpt`, `crate::author`); this module holds both and
//! lays them out.

mod dialogs;
mod document;
mod export;
mod menus;
mod params;
mod perform;
mod sculpt_view;

use std::path::{Path, PathBuf};
use std::time::Duration;

use clay_dsl::compiled::ParamValue;
use egui::Key;

use crate::action::Action;
use crate::author::canvas::AuthorCanvas;
use crate::author::panel::AuthorForm;
use crate::author::{self, AuthorCommand, Authoring};
use crate::compile::{CASTLE_PATH, CASTLE_SOURCE, Problem, empty_grammar};
use crate::diagnostics::SourceView;
use crate::files::{Desktop, FileKind, NativeDialog, Recent};
use crate::recovery::Recovery;
use crate::sculpt::canvas::Canvas;
use crate::sculpt::follow::{Follow, Highlight};
use crate::sculpt::overlay::ViewOverlays;
use crate::sculpt::panels::ParamChange;
use crate::sculpt::{Command, Sculpt};
use crate::watch::FileWatch;

/// Budget of solver work per UI frame when the solver runs on the UI thread; the rest of a
/// 60 Hz frame is left for drawing.
pub const SOLVER_BUDGET: Duration = Duration::from_millis(12);

/// A model whose solver frames cost more than this solves on its own thread
/// ([`Sculpt::step_in_background`]) so that drawing never waits for it: the model shown is one
/// solver frame behind, the window keeps 60 Hz. Smaller models solve on the UI thread, where
/// every frame shows the latest solve.
pub const BACKGROUND_ABOVE: Duration = Duration::from_millis(4);

/// Budget of one background solver frame: about one 60 Hz frame, so the model follows the
/// mouse at up to 60 solver frames per second.
pub const BACKGROUND_BUDGET: Duration = Duration::from_micros(16_667);

/// The window title's last part: `castle.clay • Clay`.
pub const TITLE: &str = "Clay";

/// What the editor is doing: sculpting a grammar's model, or authoring a grammar from a
/// drawing. Switching keeps both.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    Sculpt,
    Author,
}

/// The typed-path dialog's state (where the desktop has no file dialog).
struct PathDialog {
    kind: FileKind,
    text: String,
    /// The file a Save was asked to write exists: it is replaced only once the user says so
    /// (issue 48: the bundled demo script was overwritten without a word).
    replace: Option<PathBuf>,
}

/// The editor.
pub struct EditorApp {
    /// The grammar file, `None` for the bundled castle.
    grammar_path: Option<PathBuf>,
    /// Diagnostics of the last compile of the grammar file.
    pub problems: Vec<Problem>,
    /// The file on disk does not compile; the model shown is the last good one.
    pub stale: bool,
    pub sculpt: Sculpt,
    pub canvas: Canvas,
    watch: Option<FileWatch>,
    /// The files the last good compile imported: hot reload watches them too.
    imports: Vec<String>,
    session_path: Option<PathBuf>,
    /// Drawing the model panicked at this revision of the sculpt, and why.
    draw_failed: Option<(u64, String)>,
    /// Crash recovery (`None`: off, as in tests that do not ask for it).
    recovery: Option<Recovery>,
    dialog: Option<PathDialog>,
    /// An action that discards unsaved work, waiting for the user's yes.
    confirm: Option<Action>,
    /// Set once the user agreed to quit.
    quitting: bool,
    /// The outcome of the last file operation, for the status bar.
    pub message: Option<String>,
    waker: Option<egui::Context>,
    commands: Vec<Command>,
    actions: Vec<Action>,
    pub mode: Mode,
    pub author: Authoring,
    pub author_canvas: AuthorCanvas,
    pub author_form: AuthorForm,
    author_commands: Vec<AuthorCommand>,
    /// Tab was pressed (taken out of the input before egui moves keyboard focus with it).
    mode_key: bool,
    desktop: Desktop,
    pub recent: Recent,
    /// A native file dialog waiting for the user.
    native: Option<NativeDialog>,
    /// What to do once the session is saved (the unsaved-changes prompt's Save).
    after_save: Option<Action>,
    /// The gestures-and-keys overlay is open.
    pub help_open: bool,
    pub overlays: ViewOverlays,
    /// The window title last sent to the window.
    title: String,
    /// A file the user asked to open that was not opened, and its problems; the current model
    /// stayed.
    pub refused: Option<(String, Vec<Problem>)>,
    /// The source line the user clicked in the diagnostics.
    pub source_view: Option<SourceView>,
    /// Following the text editor's cursor (`--follow`).
    pub follow: Option<Follow>,
    /// Values the user set for the grammar's parameters (the Grammar parameters panel), by
    /// name: the open document's, kept across hot reloads, dropped when another grammar opens.
    param_overrides: Vec<(String, ParamValue)>,
    param_changes: Vec<ParamChange>,
}

impl EditorApp {
    /// The editor on the bundled castle example.
    pub fn bundled() -> Self {
        let mut app = Self::blank();
        app.load_grammar_text(None, CASTLE_SOURCE, CASTLE_PATH);
        app
    }

    /// The editor on a grammar file; problems reading or compiling it are shown, not fatal.
    pub fn open(path: &Path) -> Self {
        let mut app = Self::blank();
        if let Err(m) = app.open_grammar(path) {
            app.message = Some(m);
        }
        app
    }

    fn blank() -> Self {
        Self {
            grammar_path: None,
            problems: Vec::new(),
            stale: false,
            sculpt: Sculpt::new(empty_grammar("")),
            canvas: Canvas::default(),
            watch: None,
            imports: Vec::new(),
            session_path: None,
            dialog: None,
            confirm: None,
            quitting: false,
            draw_failed: None,
            recovery: None,
            message: None,
            waker: None,
            commands: Vec::new(),
            actions: Vec::new(),
            mode: Mode::Sculpt,
            author: Authoring::default(),
            author_canvas: AuthorCanvas::default(),
            author_form: AuthorForm::default(),
            author_commands: Vec::new(),
            mode_key: false,
            desktop: Desktop::none(),
            recent: Recent::default(),
            native: None,
            after_save: None,
            help_open: false,
            overlays: ViewOverlays::default(),
            title: String::new(),
            refused: None,
            source_view: None,
            follow: None,
            param_overrides: Vec::new(),
            param_changes: Vec::new(),
        }
    }

    /// Switches between sculpting and authoring; the work of both stays.
    pub fn set_mode(&mut self, mode: Mode) {
        if mode == Mode::Author && self.mode != Mode::Author {
            self.author_canvas.request_fit();
        }
        self.mode = mode;
    }

    /// Uses the desktop's file dialogs and remembers recent files where it says (the binary
    /// passes [`Desktop::detect`]; tests keep [`Desktop::none`]).
    pub fn use_desktop(&mut self, desktop: Desktop) {
        self.recent = Recent::load(desktop.recent_store.as_deref());
        self.desktop = desktop;
        // The grammar opened before the desktop was known (the command line's) is recent too.
        if let Some(path) = self.grammar_path.clone() {
            self.remember(&path, false);
        }
    }

    /// Lets the file watcher wake the UI when the grammar changes on disk.
    pub fn set_waker(&mut self, ctx: egui::Context) {
        self.waker = Some(ctx);
        if let Some(path) = self.grammar_path.clone() {
            self.start_watch(&path);
        }
    }

    /// What the text editor's cursor is on, in the model (`--follow`).
    pub fn followed(&self) -> Highlight {
        self.follow.as_ref().map_or_else(Default::default, |f| {
            f.followed(self.grammar_path.as_deref(), &self.imports, &self.sculpt)
        })
    }

    /// The grammar file being edited (`None`: the bundled castle).
    pub fn grammar_path(&self) -> Option<&Path> {
        self.grammar_path.as_deref()
    }

    /// Per-frame work outside the UI: hot reload, the close request, the solver's budget.
    pub fn logic(&mut self, ctx: &egui::Context) {
        if let Some(w) = &mut self.watch {
            if w.poll() {
                self.reload();
            } else if let Some(wait) = self.watch.as_ref().and_then(FileWatch::pending) {
                ctx.request_repaint_after(wait);
            }
        }
        if ctx.input(|i| i.viewport().close_requested()) && !self.quitting && self.sculpt.dirty() {
            ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
            self.confirm = Some(Action::Quit);
        }
        self.poll_native_dialog(ctx);
        if let Some(f) = &mut self.follow {
            let sculpting = self.mode == Mode::Sculpt;
            let file = self.grammar_path.as_deref();
            if let Some(m) = f.frame(ctx, sculpting, self.canvas.hovered, file, &self.sculpt) {
                self.message = Some(m);
            }
        }
        let title = self.title();
        if title != self.title {
            ctx.send_viewport_cmd(egui::ViewportCommand::Title(title.clone()));
            self.title = title;
        }
        let heavy = self
            .sculpt
            .last_report()
            .is_some_and(|r| r.ms > BACKGROUND_ABOVE.as_secs_f64() * 1e3);
        let more = if heavy {
            self.sculpt.step_in_background(BACKGROUND_BUDGET)
        } else {
            self.sculpt.step(SOLVER_BUDGET)
        };
        self.keep_recovery();
        if more {
            ctx.request_repaint();
        }
    }

    /// One frame for a host without eframe (tests): logic, then the UI.
    pub fn frame(&mut self, ui: &mut egui::Ui) {
        self.logic(&ui.ctx().clone());
        self.ui(ui);
    }

    /// Draws the editor and applies what the user asked for.
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        self.shortcuts(ui);
        self.menu(ui);
        self.status_bar(ui);
        // A fixed width: a panel growing with its content would move the canvas.
        egui::Panel::right("panels")
            .resizable(false)
            .exact_size(340.0)
            .show(ui, |ui| {
                // Both ways: content wider than the panel scrolls instead of pushing it over.
                match self.mode {
                    Mode::Sculpt => {
                        egui::ScrollArea::both().show(ui, |ui| self.side_panels(ui));
                    }
                    // Scroll bars of their own strips, never floating over the last row (the
                    // Text header) or the right edge's buttons.
                    Mode::Author => {
                        ui.spacing_mut().scroll = egui::style::ScrollStyle::solid();
                        egui::ScrollArea::both().show(ui, |ui| {
                            author::panel::show(
                                ui,
                                &self.author,
                                &mut self.author_canvas,
                                &mut self.author_form,
                                &mut self.author_commands,
                                &mut self.actions,
                            )
                        });
                    }
                }
            });
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE)
            .show(ui, |ui| match self.mode {
                Mode::Sculpt => self.sculpt_canvas(ui),
                Mode::Author => {
                    self.author_canvas
                        .show(ui, &self.author, &mut self.author_commands)
                }
            });
        self.dialogs(ui.ctx());
        self.apply();
    }

    /// Crash recovery into `path` (`recovery::default_path`): from now on the unsaved sculpt
    /// is kept there, and work a crashed editor left there is offered for restoring.
    pub fn use_recovery(&mut self, path: PathBuf) {
        self.recovery = Some(Recovery::at(path));
    }

    /// The recovery file, if crash recovery is on.
    pub fn recovery(&self) -> Option<&Recovery> {
        self.recovery.as_ref()
    }

    /// Applies the frame's commands and file actions.
    pub fn apply(&mut self) {
        for c in std::mem::take(&mut self.commands) {
            let logged = self.sculpt.log().last().map(|e| e.seq);
            let gesture = !matches!(c, Command::MoveGrab { .. } | Command::Settings(_));
            self.sculpt.apply(c);
            // What a pin, a cut (or a cut that found nothing) did, also in the status bar, so
            // that no click goes unanswered.
            if gesture
                && let Some(e) = self.sculpt.log().last()
                && Some(e.seq) != logged
            {
                self.message = Some(e.message.clone());
            }
        }
        for c in std::mem::take(&mut self.param_changes) {
            self.apply_param_change(c);
        }
        for c in std::mem::take(&mut self.author_commands) {
            self.author.apply(c);
            if let Some(m) = self.author.take_status() {
                self.message = Some(m);
            }
        }
        for a in std::mem::take(&mut self.actions) {
            self.perform(a);
        }
        self.sync_params();
        self.drop_stale_source();
    }

    /// Queues a command as if the UI had emitted it.
    pub fn command(&mut self, c: Command) {
        self.commands.push(c);
    }

    /// Queues an authoring command as if the UI had emitted it.
    pub fn author_command(&mut self, c: AuthorCommand) {
        self.author_commands.push(c);
    }

    /// Whether a confirmation is waiting.
    pub fn confirming(&self) -> bool {
        self.confirm.is_some()
    }
}

impl eframe::App for EditorApp {
    fn logic(&mut self, ctx: &egui::Context, _frame: &mut eframe::Frame) {
        EditorApp::logic(self, ctx);
    }

    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        EditorApp::ui(self, ui);
    }

    /// Takes Tab (the mode switch) out of the input before egui sees it: egui would move the
    /// keyboard focus to a button, and a later Enter (finish a stroke) would press it. Tab in
    /// a text field is left alone.
    fn raw_input_hook(&mut self, ctx: &egui::Context, raw_input: &mut egui::RawInput) {
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        raw_input.events.retain(|e| match e {
            egui::Event::Key {
                key: Key::Tab,
                pressed,
                modifiers,
                ..
            } if modifiers.is_none() => {
                self.mode_key |= *pressed;
                false
            }
            _ => true,
        });
    }
}
