//! The modal dialogs: the typed path (where the desktop has no file dialog), the unsaved-changes
//! prompt (Save, Discard, Cancel) and the crash-recovery prompt (Restore, Discard).

use std::path::PathBuf;

use egui::Key;

use crate::action::Action;
use crate::files::FileKind;
use crate::help;
use crate::recovery::Recovery;

use super::EditorApp;

/// The unsaved-changes prompt's answers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Answer {
    Save,
    Discard,
    Cancel,
}

impl EditorApp {
    pub(super) fn dialogs(&mut self, ctx: &egui::Context) {
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

    /// Offers to restore the work a crashed editor left (Restore or Discard).
    pub(super) fn recovery_prompt(&mut self, ctx: &egui::Context) {
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

    /// The typed-path dialog (where the desktop has no file dialog), with the recent files.
    pub(super) fn path_dialog(&mut self, ctx: &egui::Context) {
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
            let label = ui.label("Path (relative to the folder the editor was started in):");
            let edit = ui
                .add(egui::TextEdit::singleline(&mut d.text).desired_width(420.0))
                .labelled_by(label.id);
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
                let action = Action::for_path(d.kind, PathBuf::from(d.text.trim()));
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
    pub(super) fn unsaved_prompt(&mut self, ctx: &egui::Context) {
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
                self.sculpt.mark_saved();
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
}
