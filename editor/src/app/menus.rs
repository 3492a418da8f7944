//! The window's chrome: the menu bar (File, Edit, View, Help, mode, undo, Fit), the keyboard
//! shortcuts, and the status bar. They emit commands and actions; nothing is applied here.

use egui::{Key, Modifiers};

use crate::action::Action;
use crate::author::AuthorCommand;
use crate::author::canvas::Tool;
use crate::files::FileKind;
use crate::sculpt::Command;

use super::{EditorApp, Mode};

impl EditorApp {
    pub(super) fn shortcuts(&mut self, ui: &mut egui::Ui) {
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

    pub(super) fn menu(&mut self, ui: &mut egui::Ui) {
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

    pub(super) fn file_menu(&mut self, ui: &mut egui::Ui) {
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
        if ui
            .button("Save gestures as script…")
            .on_hover_text(
                "The gestures since the grammar's initial model, for `clayc run --script`",
            )
            .clicked()
        {
            self.actions.push(Action::Ask(FileKind::GestureScript));
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
            .on_hover_text(
                "glTF (.glb, .gltf), OBJ or USD (.usda): heights from `extrude` (docs/export.md)",
            )
            .clicked()
        {
            self.actions.push(Action::Ask(FileKind::Model3d));
        }
        ui.separator();
        if ui.button("Quit").on_hover_text("Ctrl+Q").clicked() {
            self.actions.push(Action::Quit);
        }
    }

    pub(super) fn edit_menu(&mut self, ui: &mut egui::Ui) {
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

    pub(super) fn view_menu(&mut self, ui: &mut egui::Ui) {
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

    pub(super) fn undo_buttons(&mut self, ui: &mut egui::Ui) {
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

    pub(super) fn undo(&mut self, author: bool, redo: bool) {
        match (author, redo) {
            (true, false) => self.author_commands.push(AuthorCommand::Undo),
            (true, true) => self.author_commands.push(AuthorCommand::Redo),
            (false, false) => self.commands.push(Command::Undo),
            (false, true) => self.commands.push(Command::Redo),
        }
    }

    pub(super) fn fit(&mut self) {
        if self.mode == Mode::Author {
            self.author_canvas.request_fit();
        } else {
            self.canvas.request_fit();
        }
    }

    pub(super) fn status_bar(&mut self, ui: &mut egui::Ui) {
        // One line: the message last, cut to the width left (the whole of it on hover).
        egui::Panel::bottom("status").show(ui, |ui| {
            ui.horizontal(|ui| {
                let dirty = if self.sculpt.dirty() {
                    " (unsaved)"
                } else {
                    ""
                };
                ui.label(format!("{}{dirty}", self.display_path()));
                if let Some(p) = self.params_status() {
                    ui.separator();
                    ui.label(p);
                }
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
                // for as long as unsaved work is not kept: a crash would lose it
                if let Some(why) = self.recovery.as_ref().and_then(|r| r.failure()) {
                    ui.separator();
                    ui.colored_label(egui::Color32::from_rgb(200, 40, 40), why);
                }
                if let Some(m) = &self.message {
                    ui.separator();
                    crate::prose::line_label(ui, m);
                }
            });
        });
    }
}
