//! The editor application: the open grammar file, the sculpt, the canvas and panels, file
//! actions (open, sessions, exports) with unsaved-change confirmation, and hot reload. The UI of
//! a frame collects [`Command`]s and [`Action`]s; they are applied after it.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use clay_dsl::compiled::{AssemblyData, CompiledGrammar, FORMAT_VERSION, SolverParams};
use egui::{Key, Modifiers};
use glam::DVec2;

use crate::author::{AuthorCommand, Authoring};
use crate::author_canvas::{AuthorCanvas, Tool};
use crate::author_panel::{self, AuthorForm};
use crate::canvas::Canvas;
use crate::compile::{self, CASTLE_PATH, CASTLE_SOURCE, Problem, Severity};
use crate::panels;
use crate::sculpt::{Command, Sculpt};
use crate::session::{self, Session};
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

/// A file operation the user asked for.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    OpenGrammar(PathBuf),
    OpenSession(PathBuf),
    SaveSession(PathBuf),
    ExportPng(PathBuf),
    ExportJson(PathBuf),
    /// Ask for a path first.
    Ask(FileKind),
    Quit,
    /// Authoring: make an SVG file (metres per SVG unit) the drawing.
    ImportSvg(PathBuf, f64),
    /// Authoring: write the grammar text to a file.
    WriteGrammar(PathBuf),
    /// Authoring: compile the grammar and sculpt it.
    TryAuthored,
    /// Show a message in the status bar.
    Report(String),
}

/// What the editor is doing: sculpting a grammar's model, or authoring a grammar from a
/// drawing. Switching keeps both.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    Sculpt,
    Author,
}

/// What a path asked for in the file dialog is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    Grammar,
    OpenSession,
    SaveSession,
    Png,
    Json,
}

impl FileKind {
    fn title(self) -> &'static str {
        match self {
            FileKind::Grammar => "Open grammar",
            FileKind::OpenSession => "Open session",
            FileKind::SaveSession => "Save session as",
            FileKind::Png => "Export view as PNG",
            FileKind::Json => "Export deformed assembly as JSON",
        }
    }

    fn action(self, path: PathBuf) -> Action {
        match self {
            FileKind::Grammar => Action::OpenGrammar(path),
            FileKind::OpenSession => Action::OpenSession(path),
            FileKind::SaveSession => Action::SaveSession(path),
            FileKind::Png => Action::ExportPng(path),
            FileKind::Json => Action::ExportJson(path),
        }
    }
}

struct PathDialog {
    kind: FileKind,
    text: String,
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
    session_path: Option<PathBuf>,
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
}

/// A grammar with nothing in it: the model shown when the first compile fails.
fn empty_grammar(path: &str) -> Arc<CompiledGrammar> {
    Arc::new(CompiledGrammar {
        format_version: FORMAT_VERSION,
        source: path.to_string(),
        solver: SolverParams::default(),
        site_types: Vec::new(),
        pieces: Vec::new(),
        stretch_rules: Vec::new(),
        merge_rules: Vec::new(),
        cut_rules: Vec::new(),
        assembly: AssemblyData::default(),
    })
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
        app.open_grammar(path);
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
            session_path: None,
            dialog: None,
            confirm: None,
            quitting: false,
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
        }
    }

    /// Switches between sculpting and authoring; the work of both stays.
    pub fn set_mode(&mut self, mode: Mode) {
        if mode == Mode::Author && self.mode != Mode::Author {
            self.author_canvas.request_fit();
        }
        self.mode = mode;
    }

    /// Lets the file watcher wake the UI when the grammar changes on disk.
    pub fn set_waker(&mut self, ctx: egui::Context) {
        self.waker = Some(ctx);
        if let Some(path) = self.grammar_path.clone() {
            self.start_watch(&path);
        }
    }

    /// The grammar file being edited (`None`: the bundled castle).
    pub fn grammar_path(&self) -> Option<&Path> {
        self.grammar_path.as_deref()
    }

    fn display_path(&self) -> String {
        match &self.grammar_path {
            Some(p) => p.display().to_string(),
            // The bundled castle, or an authored grammar not written to a file.
            None if self.sculpt.grammar().source.is_empty() => CASTLE_PATH.to_string(),
            None => self.sculpt.grammar().source.clone(),
        }
    }

    /// Opens a grammar file: a new sculpt on it (even if it does not compile, so that hot
    /// reload picks up the fix), watched for changes.
    fn open_grammar(&mut self, path: &Path) {
        let shown = path.display().to_string();
        let source = match std::fs::read_to_string(path) {
            Ok(s) => Some(s),
            Err(e) => {
                self.problems = vec![Problem::whole_file(&shown, format!("cannot read: {e}"))];
                None
            }
        };
        self.grammar_path = Some(path.to_path_buf());
        self.session_path = None;
        match source {
            Some(s) => self.load_grammar_text(Some(path), &s, &shown),
            None => {
                self.sculpt = Sculpt::new(empty_grammar(&shown));
                self.stale = true;
            }
        }
        self.start_watch(path);
    }

    fn load_grammar_text(&mut self, path: Option<&Path>, source: &str, shown: &str) {
        self.grammar_path = path.map(Path::to_path_buf);
        match compile::compile(source, shown) {
            Ok(c) => {
                self.problems = c.warnings;
                self.stale = false;
                self.sculpt = Sculpt::new(c.grammar);
            }
            Err(problems) => {
                self.problems = problems;
                self.stale = true;
                self.sculpt = Sculpt::new(empty_grammar(shown));
            }
        }
        self.canvas.grammar_changed();
        self.canvas.request_fit();
    }

    fn start_watch(&mut self, path: &Path) {
        let waker = self.waker.clone();
        match FileWatch::new(path, move || {
            if let Some(ctx) = &waker {
                ctx.request_repaint();
            }
        }) {
            Ok(w) => self.watch = Some(w),
            Err(e) => {
                self.watch = None;
                self.message = Some(format!(
                    "hot reload is off: cannot watch {}: {e}",
                    path.display()
                ));
            }
        }
    }

    /// Recompiles the grammar file: a good compile replaces the model (keeping the view, as
    /// one undoable step); a bad one keeps the last good model and shows the errors.
    pub fn reload(&mut self) {
        let Some(path) = self.grammar_path.clone() else {
            return;
        };
        let shown = path.display().to_string();
        let result = std::fs::read_to_string(&path)
            .map_err(|e| vec![Problem::whole_file(&shown, format!("cannot read: {e}"))])
            .and_then(|s| compile::compile(&s, &shown));
        match result {
            Ok(c) => {
                self.problems = c.warnings;
                let first_good = self.stale && self.sculpt.data().parts.is_empty();
                self.stale = false;
                let kept = self.sculpt.replace_grammar(c.grammar);
                self.canvas.grammar_changed();
                if first_good {
                    self.canvas.request_fit();
                }
                self.message = Some(if kept {
                    format!("reloaded {shown}; sculpt kept")
                } else {
                    format!("reloaded {shown}; model rebuilt")
                });
            }
            Err(problems) => {
                self.problems = problems;
                self.stale = true;
                self.message = Some(format!(
                    "{shown} does not compile; keeping the last good model"
                ));
            }
        }
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
        if ctx.input(|i| i.viewport().close_requested()) && !self.quitting && self.sculpt.dirty {
            ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
            self.confirm = Some(Action::Quit);
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
                egui::ScrollArea::both().show(ui, |ui| match self.mode {
                    Mode::Sculpt => self.side_panels(ui),
                    Mode::Author => author_panel::show(
                        ui,
                        &self.author,
                        &mut self.author_canvas,
                        &mut self.author_form,
                        &mut self.author_commands,
                        &mut self.actions,
                    ),
                });
            });
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE)
            .show(ui, |ui| match self.mode {
                Mode::Sculpt => self.canvas.show(ui, &self.sculpt, &mut self.commands),
                Mode::Author => {
                    self.author_canvas
                        .show(ui, &self.author, &mut self.author_commands)
                }
            });
        self.dialogs(ui.ctx());
        self.apply();
    }

    fn shortcuts(&mut self, ui: &mut egui::Ui) {
        if ui.ctx().egui_wants_keyboard_input() {
            return;
        }
        let mut toggle = std::mem::take(&mut self.mode_key);
        ui.input_mut(|i| {
            let author = self.mode == Mode::Author;
            if i.consume_key(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z)
                || i.consume_key(Modifiers::COMMAND, Key::Y)
            {
                if author {
                    self.author_commands.push(AuthorCommand::Redo);
                } else {
                    self.commands.push(Command::Redo);
                }
            } else if i.consume_key(Modifiers::COMMAND, Key::Z) {
                if author {
                    self.author_commands.push(AuthorCommand::Undo);
                } else {
                    self.commands.push(Command::Undo);
                }
            }
            toggle |= i.consume_key(Modifiers::NONE, Key::Tab);
            if author && i.consume_key(Modifiers::NONE, Key::D) {
                self.author_canvas.tool = Tool::Draw;
            }
            if author && i.consume_key(Modifiers::NONE, Key::C) {
                self.author_canvas.tool = Tool::Cut;
            }
            if author && i.consume_key(Modifiers::NONE, Key::S) {
                self.author_canvas.tool = Tool::Site;
            }
            if i.consume_key(Modifiers::COMMAND, Key::S) {
                self.actions.push(match &self.session_path {
                    Some(p) => Action::SaveSession(p.clone()),
                    None => Action::Ask(FileKind::SaveSession),
                });
            }
            if i.consume_key(Modifiers::COMMAND, Key::O) {
                self.actions.push(Action::Ask(FileKind::Grammar));
            }
        });
        if toggle {
            self.set_mode(match self.mode {
                Mode::Sculpt => Mode::Author,
                Mode::Author => Mode::Sculpt,
            });
        }
    }

    fn menu(&mut self, ui: &mut egui::Ui) {
        egui::Panel::top("menu").show(ui, |ui| {
            ui.horizontal_wrapped(|ui| {
                let mut mode = self.mode;
                ui.selectable_value(&mut mode, Mode::Sculpt, "Sculpt")
                    .on_hover_text("Tab switches mode");
                ui.selectable_value(&mut mode, Mode::Author, "Author")
                    .on_hover_text("Tab switches mode");
                if mode != self.mode {
                    self.set_mode(mode);
                }
                ui.separator();
                if ui.button("Open grammar…").clicked() {
                    self.actions.push(Action::Ask(FileKind::Grammar));
                }
                if ui.button("Open session…").clicked() {
                    self.actions.push(Action::Ask(FileKind::OpenSession));
                }
                if ui.button("Save session").clicked() {
                    self.actions.push(match &self.session_path {
                        Some(p) => Action::SaveSession(p.clone()),
                        None => Action::Ask(FileKind::SaveSession),
                    });
                }
                if ui.button("Save session as…").clicked() {
                    self.actions.push(Action::Ask(FileKind::SaveSession));
                }
                if ui.button("Export PNG…").clicked() {
                    self.actions.push(Action::Ask(FileKind::Png));
                }
                if ui.button("Export JSON…").clicked() {
                    self.actions.push(Action::Ask(FileKind::Json));
                }
                ui.separator();
                let author = self.mode == Mode::Author;
                let (can_undo, can_redo) = if author {
                    (self.author.can_undo(), self.author.can_redo())
                } else {
                    (self.sculpt.can_undo(), self.sculpt.can_redo())
                };
                if ui
                    .add_enabled(can_undo, egui::Button::new("Undo"))
                    .clicked()
                {
                    if author {
                        self.author_commands.push(AuthorCommand::Undo);
                    } else {
                        self.commands.push(Command::Undo);
                    }
                }
                if ui
                    .add_enabled(can_redo, egui::Button::new("Redo"))
                    .clicked()
                {
                    if author {
                        self.author_commands.push(AuthorCommand::Redo);
                    } else {
                        self.commands.push(Command::Redo);
                    }
                }
                if !author && ui.button("Reset").clicked() {
                    self.commands.push(Command::Reset);
                }
                if ui.button("Fit (F)").clicked() {
                    if author {
                        self.author_canvas.request_fit();
                    } else {
                        self.canvas.request_fit();
                    }
                }
            });
        });
    }

    fn status_bar(&mut self, ui: &mut egui::Ui) {
        egui::Panel::bottom("status").show(ui, |ui| {
            ui.horizontal_wrapped(|ui| {
                let dirty = if self.sculpt.dirty { " (unsaved)" } else { "" };
                ui.label(format!("{}{dirty}", self.display_path()));
                ui.separator();
                let state = if let Some(e) = self.sculpt.error() {
                    format!("solver stopped: {e}")
                } else if self.sculpt.last_report().is_some_and(|r| !r.complete) {
                    "solving: frame over its time budget, continuing next frame".to_string()
                } else if self.sculpt.needs_work() {
                    "solving: not converged yet, continuing next frame".to_string()
                } else {
                    "settled".to_string()
                };
                ui.label(state);
                if let Some(r) = self.sculpt.last_report() {
                    ui.separator();
                    ui.label(format!("energy {:.4}, {:.1} ms", r.energy, r.ms));
                }
                if self.stale {
                    ui.separator();
                    ui.colored_label(egui::Color32::from_rgb(200, 40, 40), "grammar has errors");
                }
                if let Some(m) = &self.message {
                    ui.separator();
                    ui.label(m);
                }
            });
        });
    }

    fn side_panels(&mut self, ui: &mut egui::Ui) {
        let errors = self
            .problems
            .iter()
            .filter(|p| p.severity == Severity::Error)
            .count();
        egui::CollapsingHeader::new(format!("Diagnostics ({})", self.problems.len()))
            .default_open(true)
            .show(ui, |ui| {
                panels::diagnostics(ui, &self.problems, self.stale && errors > 0)
            });
        egui::CollapsingHeader::new("Inspector")
            .default_open(true)
            .show(ui, |ui| {
                panels::inspector(ui, &self.sculpt, self.canvas.hovered)
            });
        egui::CollapsingHeader::new("Solver")
            .default_open(true)
            .show(ui, |ui| panels::statistics(ui, &self.sculpt));
        egui::CollapsingHeader::new("Parameters")
            .default_open(true)
            .show(ui, |ui| {
                panels::parameters(ui, &self.sculpt, &mut self.commands)
            });
        egui::CollapsingHeader::new("Rule log")
            .default_open(true)
            .show(ui, |ui| panels::rule_log(ui, &self.sculpt));
    }

    fn dialogs(&mut self, ctx: &egui::Context) {
        if let Some(d) = &mut self.dialog {
            let mut done = None;
            let r = egui::Modal::new(egui::Id::unique("path dialog")).show(ctx, |ui| {
                ui.heading(d.kind.title());
                ui.label("Path:");
                let edit = ui.text_edit_singleline(&mut d.text);
                let enter = edit.lost_focus() && ui.input(|i| i.key_pressed(Key::Enter));
                edit.request_focus();
                ui.horizontal(|ui| {
                    if ui.button("OK").clicked() || enter {
                        done = Some(true);
                    }
                    if ui.button("Cancel").clicked() {
                        done = Some(false);
                    }
                });
            });
            if r.should_close() && done.is_none() {
                done = Some(false);
            }
            match done {
                Some(true) if !d.text.trim().is_empty() => {
                    let action = d.kind.action(PathBuf::from(d.text.trim()));
                    self.dialog = None;
                    self.actions.push(action);
                }
                Some(_) => self.dialog = None,
                None => {}
            }
        }
        if let Some(action) = self.confirm.clone() {
            let mut answer = None;
            egui::Modal::new(egui::Id::unique("confirm")).show(ctx, |ui| {
                ui.heading("Unsaved changes");
                let what = match &action {
                    Action::Quit => "quitting",
                    _ => "opening another file",
                };
                ui.label(format!(
                    "The sculpt has unsaved changes. Discard them before {what}?"
                ));
                ui.horizontal(|ui| {
                    if ui.button("Discard").clicked() {
                        answer = Some(true);
                    }
                    if ui.button("Cancel").clicked() {
                        answer = Some(false);
                    }
                });
            });
            match answer {
                Some(true) => {
                    self.confirm = None;
                    self.sculpt.dirty = false;
                    if action == Action::Quit {
                        self.quitting = true;
                        ctx.send_viewport_cmd(egui::ViewportCommand::Close);
                    } else {
                        self.actions.push(action);
                    }
                }
                Some(false) => self.confirm = None,
                None => {}
            }
        }
    }

    /// Applies the frame's commands and file actions.
    pub fn apply(&mut self) {
        for c in std::mem::take(&mut self.commands) {
            self.sculpt.apply(c);
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
    }

    /// Queues a command as if the UI had emitted it.
    pub fn command(&mut self, c: Command) {
        self.commands.push(c);
    }

    /// Queues an authoring command as if the UI had emitted it.
    pub fn author_command(&mut self, c: AuthorCommand) {
        self.author_commands.push(c);
    }

    /// Performs a file action now (tests and the UI's queue).
    pub fn perform(&mut self, action: Action) {
        let discards = matches!(
            action,
            Action::OpenGrammar(_) | Action::OpenSession(_) | Action::TryAuthored
        );
        if discards && self.sculpt.dirty {
            self.confirm = Some(action);
            return;
        }
        let result = match action {
            Action::Ask(kind) => {
                let text = match kind {
                    FileKind::SaveSession | FileKind::OpenSession => self
                        .session_path
                        .as_ref()
                        .map_or("sculpt.clay-session.json".to_string(), |p| {
                            p.display().to_string()
                        }),
                    FileKind::Grammar => self.display_path(),
                    FileKind::Png => "sculpt.png".to_string(),
                    FileKind::Json => "sculpt.assembly.json".to_string(),
                };
                self.dialog = Some(PathDialog { kind, text });
                Ok(None)
            }
            Action::OpenGrammar(p) => {
                self.open_grammar(&p);
                Ok(Some(format!("opened {}", p.display())))
            }
            Action::OpenSession(p) => self
                .open_session(&p)
                .map(|()| Some(format!("opened session {}", p.display()))),
            Action::SaveSession(p) => self
                .save_session(&p)
                .map(|()| Some(format!("saved {}", p.display()))),
            Action::ExportPng(p) => self
                .export_png(&p)
                .map(|()| Some(format!("exported {}", p.display()))),
            Action::ExportJson(p) => self
                .export_json(&p)
                .map(|()| Some(format!("exported {}", p.display()))),
            Action::Quit => {
                self.confirm = Some(Action::Quit);
                Ok(None)
            }
            Action::ImportSvg(p, scale) => self.author.import_svg(&p, scale).map(|()| {
                self.author_canvas.request_fit();
                Some(format!("imported {}", p.display()))
            }),
            Action::WriteGrammar(p) => self.author.write(&p).map(|()| {
                let verdict = if self.author.compiles {
                    "it compiles"
                } else {
                    "it does not compile yet"
                };
                Some(format!("wrote {}; {verdict}", p.display()))
            }),
            Action::TryAuthored => self.try_authored().map(Some),
            Action::Report(m) => Ok(Some(m)),
        };
        match result {
            Ok(Some(m)) => self.message = Some(m),
            Ok(None) => {}
            Err(e) => self.message = Some(format!("error: {e}")),
        }
    }

    /// The sculpt as a session.
    pub fn session(&self) -> Session {
        let grammar = match &self.grammar_path {
            Some(p) => std::path::absolute(p)
                .unwrap_or_else(|_| p.clone())
                .display()
                .to_string(),
            None => CASTLE_PATH.to_string(),
        };
        Session::new(
            grammar,
            self.sculpt.data().clone(),
            self.sculpt.pins(),
            Some(self.sculpt.settings()),
        )
    }

    /// Compiles the authored grammar and sculpts it (switching to sculpt mode). The grammar
    /// file is watched if the text was written to one; the authoring work stays.
    pub fn try_authored(&mut self) -> Result<String, String> {
        let text = match &self.author.result {
            Ok(c) => c.text.clone(),
            Err(e) => return Err(format!("nothing to try: {e}")),
        };
        let name = self.author.source_name();
        let compiled = compile::compile(&text, &name).map_err(|problems| {
            let first = problems.first().map_or(String::new(), |p| p.to_string());
            format!("the authored grammar does not compile: {first}")
        })?;
        let written = self
            .author
            .written
            .as_ref()
            .filter(|(_, t)| *t == text)
            .map(|(p, _)| p.clone());
        self.problems = compiled.warnings;
        self.stale = false;
        self.sculpt = Sculpt::new(compiled.grammar);
        self.grammar_path = written.clone();
        self.session_path = None;
        self.canvas.grammar_changed();
        self.canvas.request_fit();
        match written {
            Some(p) => self.start_watch(&p),
            None => self.watch = None,
        }
        self.mode = Mode::Sculpt;
        Ok(format!("sculpting {name}"))
    }

    /// Saves the sculpt atomically.
    pub fn save_session(&mut self, path: &Path) -> Result<(), String> {
        if self.grammar_path.is_none() && self.sculpt.grammar().source != CASTLE_PATH {
            return Err(
                "write the authored grammar to a file first (Author mode, Write grammar): a session names its grammar file"
                    .into(),
            );
        }
        session::write(path, &self.session()).map_err(|e| e.to_string())?;
        self.session_path = Some(path.to_path_buf());
        self.sculpt.dirty = false;
        Ok(())
    }

    /// Opens a session: compiles its grammar and restores the sculpt. On any error the current
    /// sculpt stays.
    pub fn open_session(&mut self, path: &Path) -> Result<(), String> {
        let s = session::read(path).map_err(|e| e.to_string())?;
        let grammar_path = PathBuf::from(&s.grammar);
        let (source, file) = match std::fs::read_to_string(&grammar_path) {
            Ok(text) => (text, Some(grammar_path.clone())),
            Err(_) if s.grammar == CASTLE_PATH => (CASTLE_SOURCE.to_string(), None),
            Err(e) => return Err(format!("the session's grammar {}: {e}", s.grammar)),
        };
        let compiled = compile::compile(&source, &s.grammar).map_err(|problems| {
            let first = problems.first().map_or(String::new(), |p| p.to_string());
            format!("the session's grammar does not compile: {first}")
        })?;
        let sculpt = Sculpt::from_saved(compiled.grammar, s.assembly, s.pins, s.settings)?;
        self.sculpt = sculpt;
        self.problems = compiled.warnings;
        self.stale = false;
        self.grammar_path = file.clone();
        self.session_path = Some(path.to_path_buf());
        self.canvas.grammar_changed();
        self.canvas.request_fit();
        match file {
            Some(f) => self.start_watch(&f),
            None => self.watch = None,
        }
        Ok(())
    }

    /// Renders the current view to PNG through the same renderer as `clayc render`.
    pub fn export_png(&self, path: &Path) -> Result<(), String> {
        let rect = self.canvas.rect;
        let width = (rect.width().round() as u32).max(16);
        let height = (rect.height().round() as u32).max(16);
        let cam = self.canvas.camera;
        let mut pins = Vec::new();
        for pin in self.sculpt.pins() {
            pins.extend(pin.vertices);
        }
        let options = clay::render::RenderOptions {
            width,
            height,
            view: Some(clay::render::View {
                scale: cam.scale,
                world_origin: cam.centre,
                pixel_origin: DVec2::new(width as f64 / 2.0, height as f64 / 2.0),
            }),
            overlays: clay::render::Overlays {
                pins,
                ..Default::default()
            },
            ..Default::default()
        };
        let png = clay::render::render_png(self.sculpt.grammar(), self.sculpt.data(), &options)
            .map_err(|e| e.to_string())?;
        session::write_atomic(path, &png).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// Writes the deformed assembly as JSON (the contract's `AssemblyData`).
    pub fn export_json(&self, path: &Path) -> Result<(), String> {
        let text = serde_json::to_string_pretty(self.sculpt.data()).map_err(|e| e.to_string())?;
        session::write_atomic(path, text.as_bytes()).map_err(|e| format!("{}: {e}", path.display()))
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
