//! The editor application: the open grammar file, the sculpt, the canvas and panels, file
//! actions (open, sessions, exports) with unsaved-change confirmation, and hot reload. The UI of
//! a frame collects [`Command`]s and [`Action`]s; they are applied after it.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use clay_dsl::compiled::{AssemblyData, CompiledGrammar, FORMAT_VERSION, SolverParams};
use egui::{Key, Modifiers};
use glam::DVec2;

use crate::action::Action;
use crate::author::{AuthorCommand, Authoring};
use crate::author_canvas::{AuthorCanvas, Tool};
use crate::author_panel::{self, AuthorForm};
use crate::canvas::Canvas;
use crate::compile::{self, CASTLE_PATH, CASTLE_SOURCE, Compiled, Problem, Severity};
use crate::files::{Desktop, FileKind, NativeDialog, Recent};
use crate::help;
use crate::overlay::ViewOverlays;
use crate::panels;
use crate::recovery::Recovery;
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

/// The window title's last part: `castle.clay • Clay`.
pub const TITLE: &str = "Clay";

/// What the editor is doing: sculpting a grammar's model, or authoring a grammar from a
/// drawing. Switching keeps both.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    Sculpt,
    Author,
}

/// The unsaved-changes prompt's answers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Answer {
    Save,
    Discard,
    Cancel,
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
    pub source_view: Option<panels::SourceView>,
    /// Following the text editor's cursor (`--follow`).
    pub follow: Option<crate::follow::Follow>,
}

/// The action a picked path is for.
fn file_action(kind: FileKind, path: PathBuf) -> Action {
    match kind {
        FileKind::Grammar => Action::OpenGrammar(path),
        FileKind::OpenSession => Action::OpenSession(path),
        FileKind::SaveSession => Action::SaveSession(path),
        FileKind::Png => Action::ExportPng(path),
        FileKind::Json => Action::ExportJson(path),
        FileKind::Model3d => Action::Export3d(path),
    }
}

/// A session read and checked against its grammar, not yet the editor's.
struct LoadedSession {
    sculpt: Sculpt,
    warnings: Vec<Problem>,
    /// The grammar's file (`None`: the bundled castle).
    grammar_file: Option<PathBuf>,
}

/// Reads a session and rebuilds its sculpt, touching nothing of the editor's.
fn load_session(path: &Path) -> Result<LoadedSession, String> {
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
    let sculpt = Sculpt::from_saved(compiled.grammar, s.assembly, s.pins, s.settings, s.log)?;
    Ok(LoadedSession {
        sculpt,
        warnings: compiled.warnings,
        grammar_file: file,
    })
}

/// Reads and compiles a grammar file without touching the editor's state.
fn check_grammar(path: &Path) -> Result<Compiled, Vec<Problem>> {
    let shown = path.display().to_string();
    let source = std::fs::read_to_string(path)
        .map_err(|e| vec![Problem::whole_file(&shown, format!("cannot read it: {e}"))])?;
    compile::compile(&source, &shown)
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
    }

    /// The window title: the file's name, `*` when the sculpt has unsaved changes, and `Clay`.
    pub fn title(&self) -> String {
        let shown = self.display_path();
        let name = Path::new(&shown)
            .file_name()
            .map_or(shown.clone(), |n| n.to_string_lossy().into_owned());
        let dirty = if self.sculpt.dirty { "*" } else { "" };
        format!("{name}{dirty} \u{2022} {TITLE}")
    }

    /// Lets the file watcher wake the UI when the grammar changes on disk.
    pub fn set_waker(&mut self, ctx: egui::Context) {
        self.waker = Some(ctx);
        if let Some(path) = self.grammar_path.clone() {
            self.start_watch(&path);
        }
    }

    /// What the text editor's cursor is on, in the model (`--follow`).
    pub fn followed(&self) -> crate::follow::Highlight {
        self.follow.as_ref().map_or_else(Default::default, |f| {
            f.followed(self.grammar_path.as_deref(), &self.imports, &self.sculpt)
        })
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

    /// Opens a grammar file. A file that cannot be read or does not compile is not opened:
    /// the current model stays and the file's problems are listed as the refused file's. Only
    /// an editor with no model yet takes a broken file, and watches it, so that hot reload
    /// picks up the fix.
    fn open_grammar(&mut self, path: &Path) -> Result<String, String> {
        let shown = path.display().to_string();
        match check_grammar(path) {
            Ok(compiled) => {
                self.refused = None;
                self.grammar_path = Some(path.to_path_buf());
                self.session_path = None;
                self.adopt(compiled);
                self.start_watch(path);
                self.remember(path, false);
                Ok(format!("opened {shown}"))
            }
            Err(problems) if self.sculpt.data().parts.is_empty() => {
                self.refused = None;
                self.problems = problems;
                self.stale = true;
                self.grammar_path = Some(path.to_path_buf());
                self.session_path = None;
                self.sculpt = Sculpt::new(empty_grammar(&shown));
                self.canvas.grammar_changed();
                self.start_watch(path);
                Err(format!(
                    "{shown} has problems (see Diagnostics); it loads as soon as it compiles"
                ))
            }
            Err(problems) => {
                let why = problems
                    .first()
                    .map_or("it does not compile".to_string(), |p| p.message.clone());
                let errors = problems
                    .iter()
                    .filter(|p| p.severity == Severity::Error)
                    .count();
                self.refused = Some((shown.clone(), problems));
                Err(format!(
                    "{shown} was not opened ({why}{}); the current model stays",
                    if errors > 1 {
                        format!(", and {} more errors", errors - 1)
                    } else {
                        String::new()
                    }
                ))
            }
        }
    }

    /// A good compile becomes the model: a new sculpt, the view fitted.
    fn adopt(&mut self, compiled: Compiled) {
        self.watch_imports(compiled.imports.clone());
        self.problems = compiled.warnings;
        self.stale = false;
        self.sculpt = Sculpt::new(compiled.grammar);
        self.canvas.grammar_changed();
        self.canvas.request_fit();
    }

    fn load_grammar_text(&mut self, path: Option<&Path>, source: &str, shown: &str) {
        self.grammar_path = path.map(Path::to_path_buf);
        match compile::compile(source, shown) {
            Ok(c) => self.adopt(c),
            Err(problems) => {
                self.imports.clear();
                self.problems = problems;
                self.stale = true;
                self.sculpt = Sculpt::new(empty_grammar(shown));
                self.canvas.grammar_changed();
                self.canvas.request_fit();
            }
        }
    }

    /// Puts a file first in the recent files, kept in the user's config folder.
    fn remember(&mut self, path: &Path, session: bool) {
        self.recent.add(path, session);
        if let Some(store) = self.desktop.recent_store.clone()
            && let Err(e) = self.recent.save(&store)
        {
            self.sculpt
                .note_outside_history(format!("could not remember recent files: {e}"));
        }
    }

    /// Hot reload also follows the grammar's imported files.
    fn watch_imports(&mut self, imports: Vec<String>) {
        self.imports = imports;
        if let Some(w) = &mut self.watch {
            w.also(&self.imports);
        }
    }

    fn start_watch(&mut self, path: &Path) {
        let waker = self.waker.clone();
        match FileWatch::new(path, move || {
            if let Some(ctx) = &waker {
                ctx.request_repaint();
            }
        }) {
            Ok(mut w) => {
                w.also(&self.imports);
                self.watch = Some(w);
            }
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
        match check_grammar(&path) {
            Ok(c) => {
                self.watch_imports(c.imports.clone());
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
                let first = problems.first().map_or(String::new(), |p| {
                    format!(" (line {}: {})", p.line, p.message)
                });
                self.problems = problems;
                self.stale = true;
                let what = if self.sculpt.data().parts.is_empty() {
                    "no model yet"
                } else {
                    "the last good model stays"
                };
                let m = format!("{shown} does not compile{first}; {what}");
                self.sculpt
                    .note_outside_history(format!("reload failed: {m}"));
                self.message = Some(m);
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
                Mode::Sculpt => self.sculpt_canvas(ui),
                Mode::Author => {
                    self.author_canvas
                        .show(ui, &self.author, &mut self.author_commands)
                }
            });
        self.dialogs(ui.ctx());
        self.apply();
    }

    /// The model's canvas. A panic while drawing (tessellating a proxy, say) is caught: the
    /// canvas shows what went wrong instead of the model until the model changes, and the
    /// editor, its sculpt and the file stay.
    fn sculpt_canvas(&mut self, ui: &mut egui::Ui) {
        let revision = self.sculpt.revision();
        if let Some((at, why)) = &self.draw_failed {
            if *at == revision {
                ui.centered_and_justified(|ui| {
                    ui.colored_label(
                        egui::Color32::from_rgb(200, 60, 40),
                        format!("the model cannot be drawn: {why}"),
                    )
                });
                return;
            }
            self.draw_failed = None;
        }
        let drawn = crate::guard::catching(|| {
            self.canvas
                .show(ui, &self.sculpt, &self.overlays, &mut self.commands);
            let (grammar, data) = (self.sculpt.grammar(), self.sculpt.data());
            crate::follow::paint(ui, &self.canvas, grammar, data, &self.followed());
        });
        if let Err(why) = drawn {
            let why = format!("internal error while drawing ({why})");
            self.message = Some(format!("{why}; the sculpt is kept: save it"));
            self.draw_failed = Some((revision, why));
        }
    }

    fn shortcuts(&mut self, ui: &mut egui::Ui) {
        if ui.ctx().egui_wants_keyboard_input() {
            return;
        }
        let mut toggle = std::mem::take(&mut self.mode_key);
        let mut redo = None;
        ui.input_mut(|i| {
            let author = self.mode == Mode::Author;
            if i.consume_key(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z)
                || i.consume_key(Modifiers::COMMAND, Key::Y)
            {
                redo = Some(true);
            } else if i.consume_key(Modifiers::COMMAND, Key::Z) {
                redo = Some(false);
            }
            if i.consume_key(Modifiers::NONE, Key::F1)
                || i.consume_key(Modifiers::SHIFT, Key::Questionmark)
                || i.consume_key(Modifiers::NONE, Key::Questionmark)
            {
                self.help_open = !self.help_open;
            }
            if self.help_open && i.consume_key(Modifiers::NONE, Key::Escape) {
                self.help_open = false;
            }
            if i.consume_key(Modifiers::COMMAND, Key::Q) {
                self.actions.push(Action::Quit);
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
        if let Some(redo) = redo {
            self.undo(self.mode == Mode::Author, redo);
        }
        if toggle {
            self.set_mode(match self.mode {
                Mode::Sculpt => Mode::Author,
                Mode::Author => Mode::Sculpt,
            });
        }
    }

    fn menu(&mut self, ui: &mut egui::Ui) {
        egui::Panel::top("menu").show(ui, |ui| {
            egui::MenuBar::new().ui(ui, |ui| {
                ui.menu_button("File", |ui| self.file_menu(ui));
                ui.menu_button("Edit", |ui| self.edit_menu(ui));
                ui.menu_button("View", |ui| self.view_menu(ui));
                ui.menu_button("Help", |ui| {
                    if ui.button("Gestures and keys (F1)").clicked() {
                        self.help_open = true;
                    }
                });
                ui.separator();
                let mut mode = self.mode;
                ui.selectable_value(&mut mode, Mode::Sculpt, "Sculpt")
                    .on_hover_text("Sculpt the grammar's model (Tab switches mode)");
                ui.selectable_value(&mut mode, Mode::Author, "Author")
                    .on_hover_text("Make a grammar from a drawing (Tab switches mode)");
                if mode != self.mode {
                    self.set_mode(mode);
                }
                ui.separator();
                self.undo_buttons(ui);
                if ui
                    .button("Fit")
                    .on_hover_text("Fit the model into the view (F)")
                    .clicked()
                {
                    self.fit();
                }
                if ui
                    .button("?")
                    .on_hover_text("Every gesture and key (F1 or ?)")
                    .clicked()
                {
                    self.help_open = !self.help_open;
                }
            });
        });
    }

    fn file_menu(&mut self, ui: &mut egui::Ui) {
        if ui
            .button("Open grammar…")
            .on_hover_text("Ctrl+O: a .clay file, or a compiled .json")
            .clicked()
        {
            self.actions.push(Action::Ask(FileKind::Grammar));
        }
        ui.menu_button("Open recent", |ui| {
            if self.recent.files.is_empty() {
                ui.label("Nothing opened yet.");
            }
            for f in self.recent.files.clone() {
                let what = if f.session { "session" } else { "grammar" };
                let button = egui::Button::new(format!("{} ({what})", f.path.display()));
                if ui
                    .add_enabled(f.path.exists(), button)
                    .on_disabled_hover_text("no longer there")
                    .clicked()
                {
                    self.actions.push(if f.session {
                        Action::OpenSession(f.path)
                    } else {
                        Action::OpenGrammar(f.path)
                    });
                }
            }
        });
        ui.separator();
        if ui
            .button("Open session…")
            .on_hover_text("A saved sculpt")
            .clicked()
        {
            self.actions.push(Action::Ask(FileKind::OpenSession));
        }
        if ui.button("Save session").on_hover_text("Ctrl+S").clicked() {
            self.actions.push(match &self.session_path {
                Some(p) => Action::SaveSession(p.clone()),
                None => Action::Ask(FileKind::SaveSession),
            });
        }
        if ui.button("Save session as…").clicked() {
            self.actions.push(Action::Ask(FileKind::SaveSession));
        }
        ui.separator();
        if ui
            .button("Export PNG…")
            .on_hover_text("The view as `clayc render` draws it")
            .clicked()
        {
            self.actions.push(Action::Ask(FileKind::Png));
        }
        if ui
            .button("Export JSON…")
            .on_hover_text("The deformed assembly (the compiled format's `assembly`)")
            .clicked()
        {
            self.actions.push(Action::Ask(FileKind::Json));
        }
        if ui
            .button("Export 3D model…")
            .on_hover_text("glTF (.glb, .gltf) or OBJ: heights from `extrude` (docs/export.md)")
            .clicked()
        {
            self.actions.push(Action::Ask(FileKind::Model3d));
        }
        ui.separator();
        if ui.button("Quit").on_hover_text("Ctrl+Q").clicked() {
            self.actions.push(Action::Quit);
        }
    }

    fn edit_menu(&mut self, ui: &mut egui::Ui) {
        self.undo_buttons(ui);
        if self.mode == Mode::Sculpt
            && ui
                .button("Reset")
                .on_hover_text("Back to the grammar's initial model (undoable)")
                .clicked()
        {
            self.commands.push(Command::Reset);
        }
    }

    fn view_menu(&mut self, ui: &mut egui::Ui) {
        let o = &mut self.overlays;
        ui.checkbox(&mut o.strain, "Strain")
            .on_hover_text("Colour every part edge by how far it is stretched or squeezed");
        ui.checkbox(&mut o.states, "Rest states")
            .on_hover_text("Name the active rest state of every part that has alternatives");
        ui.checkbox(&mut o.sites, "Docking sites")
            .on_hover_text("Sites coloured by type; open sites point outwards");
        ui.checkbox(&mut o.handles, "Handles and pins")
            .on_hover_text("The grabbed part's vertices as rings, pinned ones as squares");
        ui.checkbox(&mut o.part_graph, "Part outlines")
            .on_hover_text("The edges and vertices the solver works on");
        ui.checkbox(&mut self.canvas.iso, "Isometric 3D")
            .on_hover_text(
                "I: the model in 3D, as `clayc render --view iso` draws it; sculpting is off",
            );
        ui.separator();
        if ui.button("Fit").on_hover_text("F").clicked() {
            self.fit();
        }
    }

    fn undo_buttons(&mut self, ui: &mut egui::Ui) {
        let author = self.mode == Mode::Author;
        let (can_undo, can_redo) = if author {
            (self.author.can_undo(), self.author.can_redo())
        } else {
            (self.sculpt.can_undo(), self.sculpt.can_redo())
        };
        let undo = ui
            .add_enabled(can_undo, egui::Button::new("Undo"))
            .on_hover_text("Ctrl+Z: the last gesture, with the rules it fired");
        if undo.clicked() {
            self.undo(author, false);
        }
        let redo = ui
            .add_enabled(can_redo, egui::Button::new("Redo"))
            .on_hover_text("Ctrl+Shift+Z or Ctrl+Y");
        if redo.clicked() {
            self.undo(author, true);
        }
    }

    fn undo(&mut self, author: bool, redo: bool) {
        match (author, redo) {
            (true, false) => self.author_commands.push(AuthorCommand::Undo),
            (true, true) => self.author_commands.push(AuthorCommand::Redo),
            (false, false) => self.commands.push(Command::Undo),
            (false, true) => self.commands.push(Command::Redo),
        }
    }

    fn fit(&mut self) {
        if self.mode == Mode::Author {
            self.author_canvas.request_fit();
        } else {
            self.canvas.request_fit();
        }
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
                } else if self.sculpt.at_rest() {
                    "at rest".to_string()
                } else {
                    "still, under strain".to_string()
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
        let count = self.problems.len() + self.refused.as_ref().map_or(0, |r| r.1.len());
        let mut clicked = None;
        egui::CollapsingHeader::new(format!("Diagnostics ({count})"))
            .default_open(true)
            .show(ui, |ui| {
                if let Some((file, problems)) = &self.refused {
                    let banner = format!("{file} was not opened: the current model stays.");
                    clicked = panels::diagnostics(ui, problems, Some(&banner)).cloned();
                    ui.separator();
                }
                let banner = (self.stale && errors > 0).then(|| {
                    if self.sculpt.data().parts.is_empty() {
                        "The file does not compile: no model yet; it loads once it compiles."
                    } else {
                        "The file does not compile: the last good model stays live."
                    }
                });
                if let Some(p) = panels::diagnostics(ui, &self.problems, banner) {
                    clicked = Some(p.clone());
                }
            });
        if let Some(p) = clicked {
            self.show_source(&p);
        }
        if let Some(view) = &self.source_view {
            egui::CollapsingHeader::new("Source")
                .default_open(true)
                .show(ui, |ui| panels::source(ui, view));
        }
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
        self.path_dialog(ctx);
        self.unsaved_prompt(ctx);
        self.recovery_prompt(ctx);
        help::show(ctx, &mut self.help_open);
        if self.quitting && self.confirm.is_none() {
            // a clean exit: nothing to recover
            if let Some(r) = &mut self.recovery {
                r.clear();
            }
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
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

    /// Writes the unsaved sculpt to the recovery file when it is due (`Recovery::keep`).
    fn keep_recovery(&mut self) {
        let Some(mut r) = self.recovery.take() else {
            return;
        };
        let stamp = (self.sculpt.history(), self.sculpt.revision());
        let unsaved = self.sculpt.dirty && !self.quitting;
        let savable = self.grammar_path.is_some() || self.sculpt.grammar().source == CASTLE_PATH;
        if let Some(m) = r.keep(stamp, unsaved, || savable.then(|| self.session())) {
            self.message = Some(m);
        }
        self.recovery = Some(r);
    }

    /// Offers to restore the work a crashed editor left (Restore or Discard).
    fn recovery_prompt(&mut self, ctx: &egui::Context) {
        let Some(offer) = self.recovery.as_ref().and_then(Recovery::offer).cloned() else {
            return;
        };
        if self.confirm.is_some() {
            return;
        }
        egui::Modal::new(egui::Id::unique("recovery prompt")).show(ctx, |ui| {
            ui.heading("Restore unsaved work?");
            let when = offer
                .written
                .and_then(|t| t.elapsed().ok())
                .map_or(String::new(), |d| {
                    format!(" {} min ago", (d.as_secs() + 30) / 60)
                });
            ui.label(format!(
                "Clay closed without saving the sculpt of {} (last kept{when}).",
                offer.grammar
            ));
            // the buttons first, at a fixed place, whatever the message's length
            ui.horizontal(|ui| {
                if ui.button("Restore").clicked() {
                    self.actions.push(Action::RestoreRecovery);
                }
                if ui
                    .button("Discard")
                    .on_hover_text("forgets that work")
                    .clicked()
                {
                    self.actions.push(Action::DiscardRecovery);
                }
            });
        });
    }

    /// Restores the sculpt in the recovery file: unsaved, with no session file of its own.
    fn restore_recovery(&mut self) -> Result<Option<String>, String> {
        let Some(path) = self.recovery.as_ref().map(|r| r.path().to_path_buf()) else {
            return Ok(None);
        };
        let restored = self.open_session(&path);
        if let Some(r) = &mut self.recovery {
            r.answered();
        }
        restored?;
        self.session_path = None;
        self.sculpt.dirty = true;
        Ok(Some("restored the unsaved sculpt".to_string()))
    }

    /// The typed-path dialog (where the desktop has no file dialog), with the recent files.
    fn path_dialog(&mut self, ctx: &egui::Context) {
        let Some(d) = &mut self.dialog else {
            return;
        };
        let mut done = None;
        let sessions = match d.kind {
            FileKind::Grammar => Some(false),
            FileKind::OpenSession => Some(true),
            _ => None,
        };
        let recent: Vec<PathBuf> = self
            .recent
            .files
            .iter()
            .filter(|f| Some(f.session) == sessions)
            .map(|f| f.path.clone())
            .collect();
        let r = egui::Modal::new(egui::Id::unique("path dialog")).show(ctx, |ui| {
            ui.heading(d.kind.title());
            ui.label("Path (relative to the folder the editor was started in):");
            let edit = ui.add(egui::TextEdit::singleline(&mut d.text).desired_width(420.0));
            let enter = edit.lost_focus() && ui.input(|i| i.key_pressed(Key::Enter));
            edit.request_focus();
            if !recent.is_empty() {
                ui.label("Recent:");
                for p in &recent {
                    let shown = p.display().to_string();
                    if ui
                        .add_enabled(p.exists(), egui::Button::new(&shown))
                        .on_disabled_hover_text("no longer there")
                        .clicked()
                    {
                        d.text = shown;
                        done = Some(true);
                    }
                }
            }
            ui.horizontal(|ui| {
                if ui.button("OK").on_hover_text("Enter").clicked() || enter {
                    done = Some(true);
                }
                if ui.button("Cancel").on_hover_text("Esc").clicked() {
                    done = Some(false);
                }
            });
        });
        if r.should_close() && done.is_none() {
            done = Some(false);
        }
        match done {
            Some(true) if !d.text.trim().is_empty() => {
                let action = file_action(d.kind, PathBuf::from(d.text.trim()));
                self.dialog = None;
                self.actions.push(action);
            }
            Some(_) => {
                self.dialog = None;
                self.after_save = None;
            }
            None => {}
        }
    }

    /// Save, Discard or Cancel before an action that would lose the sculpt's changes.
    fn unsaved_prompt(&mut self, ctx: &egui::Context) {
        let Some(action) = self.confirm.clone() else {
            return;
        };
        let mut answer = None;
        egui::Modal::new(egui::Id::unique("unsaved prompt")).show(ctx, |ui| {
            ui.heading("Unsaved changes");
            let what = match &action {
                Action::Quit => "quitting",
                Action::TryAuthored => "sculpting the authored grammar",
                _ => "opening another file",
            };
            ui.label(format!(
                "The sculpt has unsaved changes. Save them before {what}?"
            ));
            ui.horizontal(|ui| {
                let save = match &self.session_path {
                    Some(p) => format!("saves the session to {}", p.display()),
                    None => "asks where to save the session".to_string(),
                };
                if ui.button("Save").on_hover_text(save).clicked() {
                    answer = Some(Answer::Save);
                }
                if ui
                    .button("Discard")
                    .on_hover_text("goes on without saving")
                    .clicked()
                {
                    answer = Some(Answer::Discard);
                }
                if ui.button("Cancel").on_hover_text("Esc").clicked() {
                    answer = Some(Answer::Cancel);
                }
            });
            if ui.input(|i| i.key_pressed(Key::Escape)) {
                answer = Some(Answer::Cancel);
            }
        });
        let Some(answer) = answer else {
            return;
        };
        self.confirm = None;
        let quit = matches!(action, Action::Quit);
        match answer {
            Answer::Cancel => {}
            Answer::Discard => {
                self.sculpt.dirty = false;
                if quit {
                    self.quitting = true;
                } else {
                    self.actions.push(action);
                }
            }
            Answer::Save => {
                self.after_save = Some(action);
                self.actions.push(match &self.session_path {
                    Some(p) => Action::SaveSession(p.clone()),
                    None => Action::Ask(FileKind::SaveSession),
                });
            }
        }
    }

    /// Shows a problem's line in the source view (the file read again: the text is the one on
    /// disk now, which is what the user will edit).
    pub fn show_source(&mut self, p: &Problem) {
        let text = match std::fs::read_to_string(&p.file) {
            Ok(t) => t,
            Err(_) if p.file == CASTLE_PATH => CASTLE_SOURCE.to_string(),
            Err(e) => {
                self.message = Some(format!("cannot show {}: {e}", p.file));
                return;
            }
        };
        self.source_view = Some(panels::SourceView {
            file: p.file.clone(),
            text,
            line: p.line,
            col: p.col,
            end_col: p.end_col,
        });
        self.message = Some(format!("{}:{}:{}", p.file, p.line, p.col));
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

    /// Performs a file action now (tests and the UI's queue). An action that would replace
    /// the sculpt is checked first (the file read and compiled), so a mistyped path or a broken
    /// file is reported without asking to discard anything; with unsaved changes it then asks
    /// Save, Discard or Cancel.
    pub fn perform(&mut self, action: Action) {
        let discards = matches!(
            action,
            Action::OpenGrammar(_) | Action::OpenSession(_) | Action::TryAuthored
        );
        if discards && self.sculpt.dirty {
            match self.precheck(&action) {
                Ok(()) => self.confirm = Some(action),
                Err(e) => self.fail(e),
            }
            return;
        }
        let result = match action {
            Action::Ask(kind) => {
                self.ask(kind);
                Ok(None)
            }
            Action::OpenGrammar(p) => self.open_grammar(&p).map(Some),
            Action::OpenSession(p) => self.open_session(&p).map(|()| {
                self.remember(&p, true);
                Some(format!("opened session {}", p.display()))
            }),
            Action::SaveSession(p) => self.save_session(&p).map(|()| {
                self.remember(&p, true);
                if let Some(next) = self.after_save.take() {
                    self.actions.push(next);
                }
                Some(format!("saved {}", p.display()))
            }),
            Action::ExportPng(p) => self
                .export_png(&p)
                .map(|()| Some(format!("exported {}", p.display()))),
            Action::ExportJson(p) => self
                .export_json(&p)
                .map(|()| Some(format!("exported {}", p.display()))),
            Action::Export3d(p) => self
                .export_3d(&p)
                .map(|()| Some(format!("exported {}", p.display()))),
            Action::Quit => {
                if self.sculpt.dirty {
                    self.confirm = Some(Action::Quit);
                } else {
                    self.quitting = true;
                }
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
            Action::RestoreRecovery => self.restore_recovery(),
            Action::DiscardRecovery => {
                if let Some(r) = &mut self.recovery {
                    r.clear();
                }
                Ok(Some("discarded the unsaved work".to_string()))
            }
        };
        match result {
            Ok(Some(m)) => self.message = Some(m),
            Ok(None) => {}
            Err(e) => self.fail(e),
        }
    }

    /// A file action failed: said in the status bar and kept in the log.
    fn fail(&mut self, e: String) {
        // A Save from the unsaved-changes prompt that failed must not go on to discard.
        self.after_save = None;
        self.sculpt.note_outside_history(e.clone());
        self.message = Some(format!("error: {e}"));
    }

    /// Whether an action that replaces the sculpt would succeed, without doing it.
    fn precheck(&mut self, action: &Action) -> Result<(), String> {
        match action {
            Action::OpenGrammar(p) => check_grammar(p).map(drop).map_err(|problems| {
                let shown = p.display().to_string();
                let why = problems
                    .first()
                    .map_or(String::new(), |p| format!(" ({})", p.message));
                self.refused = Some((shown.clone(), problems));
                format!("{shown} was not opened{why}; the current model stays")
            }),
            Action::OpenSession(p) => load_session(p).map(drop),
            Action::TryAuthored => self.authored().map(drop),
            _ => Ok(()),
        }
    }

    /// Asks for a path: the desktop's file dialog where there is one, else a typed path.
    fn ask(&mut self, kind: FileKind) {
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
            FileKind::Model3d => "sculpt.glb".to_string(),
        };
        if self.desktop.native_dialogs {
            self.native = Some(NativeDialog::open(kind, Path::new(&text)));
        } else {
            self.dialog = Some(PathDialog { kind, text });
        }
    }

    /// Takes the native dialog's answer once it has one.
    fn poll_native_dialog(&mut self, ctx: &egui::Context) {
        let Some(d) = &self.native else {
            return;
        };
        match d.poll() {
            None => ctx.request_repaint_after(Duration::from_millis(100)),
            Some(picked) => {
                let kind = d.kind;
                self.native = None;
                match picked {
                    Some(p) => self.actions.push(file_action(kind, p)),
                    // Cancelled: a Save the prompt asked for is not made, so nothing goes on.
                    None => self.after_save = None,
                }
            }
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
        let mut session = Session::new(
            grammar,
            self.sculpt.data().clone(),
            self.sculpt.pins(),
            Some(self.sculpt.settings()),
        );
        session.log = self.sculpt.log().to_vec();
        session
    }

    /// The authored grammar compiled, its name, and the file it was written to (if the text
    /// there is the same).
    fn authored(&self) -> Result<(Compiled, String, Option<PathBuf>), String> {
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
        Ok((compiled, name, written))
    }

    /// Compiles the authored grammar and sculpts it (switching to sculpt mode). The grammar
    /// file is watched if the text was written to one; the authoring work stays.
    pub fn try_authored(&mut self) -> Result<String, String> {
        let (compiled, name, written) = self.authored()?;
        self.adopt(compiled);
        self.grammar_path = written.clone();
        self.session_path = None;
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

    /// Opens a session: compiles its grammar and restores the sculpt (and its rule log). On
    /// any error the current sculpt stays.
    pub fn open_session(&mut self, path: &Path) -> Result<(), String> {
        let loaded = load_session(path)?;
        self.sculpt = loaded.sculpt;
        self.problems = loaded.warnings;
        self.stale = false;
        self.refused = None;
        self.grammar_path = loaded.grammar_file.clone();
        self.session_path = Some(path.to_path_buf());
        self.canvas.grammar_changed();
        self.canvas.request_fit();
        match loaded.grammar_file {
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
        clay::files::write_atomic(path, &png).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// Writes the deformed assembly as JSON (the contract's `AssemblyData`).
    pub fn export_json(&self, path: &Path) -> Result<(), String> {
        let text = serde_json::to_string_pretty(self.sculpt.data()).map_err(|e| e.to_string())?;
        clay::files::write_atomic(path, text.as_bytes())
            .map_err(|e| format!("{}: {e}", path.display()))
    }

    /// Writes the sculpted model as 3D meshes with `clayc export`'s code; the format comes from
    /// the extension (`.glb`, `.gltf`, `.obj`, whose `.mtl` is written beside it).
    pub fn export_3d(&self, path: &Path) -> Result<(), String> {
        use clay::export::{gltf, obj, scene};
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let scene = scene(
            self.sculpt.grammar(),
            self.sculpt.data(),
            &Default::default(),
        );
        let write = |p: &Path, bytes: &[u8]| {
            clay::files::write_atomic(p, bytes).map_err(|e| format!("{}: {e}", p.display()))
        };
        match ext.as_deref() {
            Some("glb") => write(path, &gltf::to_glb(&scene)?),
            Some("gltf") => write(path, &gltf::to_gltf(&scene)?),
            Some("obj") => {
                let mtl = path.with_extension("mtl");
                let name = mtl
                    .file_name()
                    .map_or("model.mtl".into(), |n| n.to_string_lossy().into_owned());
                let (obj_text, mtl_text) = obj::to_obj(&scene, &name);
                write(&mtl, mtl_text.as_bytes())?;
                write(path, obj_text.as_bytes())
            }
            _ => Err(format!(
                "{}: name the file .glb, .gltf or .obj to say the format",
                path.display()
            )),
        }
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
