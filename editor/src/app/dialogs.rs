//! The modal dialogs: the typed path (where the desktop has no file dialog), the unsaved-changes
//! prompt (Save, Discard, Cancel) and the crash-recovery prompt (Restore, Discard).

use std::path::PathBuf;

use egui::Key;

use crate::action::Action;
use crate::files::FileKind;
use crate::help;
use crate::recovery::Recovery;

use super::EditorApp;

/// A prompt's width, its message's height and its buttons' size, in points: fixed, so every
/// button is at the same place whatever the message says (a click meant for Discard never
/// lands on Save).
const PROMPT_WIDTH: f32 = 400.0;
const MESSAGE_HEIGHT: f32 = 54.0;
const BUTTON: egui::Vec2 = egui::vec2(90.0, 24.0);

/// A prompt's content: its heading, its message wrapped in a box of fixed size, and a row of
/// buttons (label, hover text) of one size below it. Returns the button clicked.
fn prompt(
    ui: &mut egui::Ui,
    heading: &str,
    message: &str,
    buttons: &[(&str, &str)],
) -> Option<usize> {
    ui.set_width(PROMPT_WIDTH);
    ui.heading(heading);
    // Painted into a rect of its own size: however many lines it takes, nothing below moves.
    let size = egui::vec2(PROMPT_WIDTH, MESSAGE_HEIGHT);
    let (rect, response) = ui.allocate_exact_size(size, egui::Sense::hover());
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Label, true, message));
    let colour = ui.visuals().text_color();
    let font = egui::TextStyle::Body.resolve(ui.style());
    let galley = ui
        .painter()
        .layout(message.to_string(), font, colour, PROMPT_WIDTH);
    ui.painter()
        .with_clip_rect(rect)
        .galley(rect.min, galley, colour);

    let mut clicked = None;
    ui.horizontal(|ui| {
        for (i, (label, hover)) in buttons.iter().enumerate() {
            if ui
                .add_sized(BUTTON, egui::Button::new(*label))
                .on_hover_text(*hover)
                .clicked()
            {
                clicked = Some(i);
            }
        }
    });
    clicked
}

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
        let when = offer
            .written
            .and_then(|t| t.elapsed().ok())
            .map_or(String::new(), |d| {
                format!(" {} min ago", (d.as_secs() + 30) / 60)
            });
        let message = format!(
            "Clay closed without saving the sculpt of {} (last kept{when}).",
            offer.grammar
        );
        let mut answer = None;
        egui::Modal::new(egui::Id::unique("recovery prompt")).show(ctx, |ui| {
            answer = prompt(
                ui,
                "Restore unsaved work?",
                &message,
                &[
                    ("Restore", "opens that sculpt as unsaved work"),
                    ("Discard", "forgets that work"),
                ],
            );
        });
        match answer {
            Some(0) => self.actions.push(Action::RestoreRecovery),
            Some(1) => self.actions.push(Action::DiscardRecovery),
            _ => {}
        }
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
            let typed = PathBuf::from(d.text.trim());
            let asked = d.replace.as_ref() == Some(&typed);
            if asked {
                ui.colored_label(
                    ui.visuals().warn_fg_color,
                    format!("{} exists. Replace it?", typed.display()),
                );
            }
            ui.horizontal(|ui| {
                let ok = if asked { "Replace" } else { "OK" };
                if ui.button(ok).on_hover_text("Enter").clicked() || enter {
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
        // A Save to a file that exists waits for Replace (the second OK).
        let path = PathBuf::from(d.text.trim());
        if done == Some(true)
            && d.kind.writes()
            && path.is_file()
            && d.replace.as_ref() != Some(&path)
        {
            d.replace = Some(path);
            done = None;
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
        let what = match &action {
            Action::Quit => "quitting",
            Action::TryAuthored => "sculpting the authored grammar",
            _ => "opening another file",
        };
        let message = format!("The sculpt has unsaved changes. Save them before {what}?");
        let save = match &self.session_path {
            Some(p) => format!("saves the session to {}", p.display()),
            None => "asks where to save the session".to_string(),
        };
        egui::Modal::new(egui::Id::unique("unsaved prompt")).show(ctx, |ui| {
            let buttons = [
                ("Save", save.as_str()),
                ("Discard", "goes on without saving"),
                ("Cancel", "Esc"),
            ];
            answer = match prompt(ui, "Unsaved changes", &message, &buttons) {
                Some(0) => Some(Answer::Save),
                Some(1) => Some(Answer::Discard),
                Some(_) => Some(Answer::Cancel),
                None => None,
            };
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
