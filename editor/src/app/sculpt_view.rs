//! Sculpt mode's part of the window: the model's canvas (a panic while drawing caught) and the
//! side panels (diagnostics, source, inspector, solver, parameters, grammar
//! parameters, rule log), laid out from `crate::sculpt`'s canvas and panels over the app's
//! state (its problems, source view and `--follow` highlight), which is why it is the app's.

use crate::compile::{CASTLE_PATH, CASTLE_SOURCE, Problem, Severity};
use crate::diagnostics::{self, SourceView};
use crate::sculpt::{follow, panels};

use super::EditorApp;

impl EditorApp {
    /// The model's canvas. A panic while drawing (tessellating a proxy, say) is caught: the
    /// canvas shows what went wrong instead of the model until the model changes, and the
    /// editor, its sculpt and the file stay.
    pub(super) fn sculpt_canvas(&mut self, ui: &mut egui::Ui) {
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
            follow::paint(ui, &self.canvas, grammar, data, &self.followed());
        });
        if let Err(why) = drawn {
            let why = format!("internal error while drawing ({why})");
            self.message = Some(format!("{why}; the sculpt is kept: save it"));
            self.draw_failed = Some((revision, why));
        }
    }

    pub(super) fn side_panels(&mut self, ui: &mut egui::Ui) {
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
                    clicked = diagnostics::diagnostics(ui, problems, Some(&banner)).cloned();
                    ui.separator();
                }
                let banner = (self.stale && errors > 0).then(|| {
                    if self.sculpt.data().parts.is_empty() {
                        "The file does not compile: no model yet; it loads once it compiles."
                    } else {
                        "The file does not compile: the last good model stays live."
                    }
                });
                if let Some(p) = diagnostics::diagnostics(ui, &self.problems, banner) {
                    clicked = Some(p.clone());
                }
            });
        if let Some(p) = clicked {
            self.show_source(&p);
        }
        if let Some(view) = &self.source_view {
            egui::CollapsingHeader::new("Source")
                .default_open(true)
                .show(ui, |ui| diagnostics::source(ui, view));
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
        if !self.sculpt.grammar().params.is_empty() {
            egui::CollapsingHeader::new("Grammar parameters")
                .default_open(true)
                .show(ui, |ui| {
                    panels::grammar_parameters(
                        ui,
                        &self.sculpt.grammar().params,
                        &mut self.param_changes,
                    )
                });
        }
        egui::CollapsingHeader::new("Rule log")
            .default_open(true)
            .show(ui, |ui| panels::rule_log(ui, &self.sculpt));
    }

    /// Shows a problem's line in the source view (the file read again: the text is the one on
    /// disk now, which is what the user will edit).
    pub fn show_source(&mut self, p: &Problem) {
        let text = match clay_dsl::read_input_string(
            std::path::Path::new(&p.file),
            clay_dsl::MAX_SOURCE_BYTES,
        ) {
            Ok(t) => t,
            Err(_) if p.file == CASTLE_PATH => CASTLE_SOURCE.to_string(),
            Err(e) => {
                self.message = Some(format!("cannot show {}: {e}", p.file));
                return;
            }
        };
        self.source_view = Some(SourceView {
            problem: p.clone(),
            file: p.file.clone(),
            text,
            line: p.line,
            col: p.col,
            end_col: p.end_col,
        });
        self.message = Some(format!("{}:{}:{}", p.file, p.line, p.col));
    }

    /// Closes the source view once its problem is no longer listed (the file was fixed, or
    /// another one opened): it never shows a line that is no longer a problem.
    pub(super) fn drop_stale_source(&mut self) {
        let Some(view) = &self.source_view else {
            return;
        };
        let refused = self.refused.as_ref().map_or(&[][..], |(_, p)| &p[..]);
        if !self.problems.contains(&view.problem) && !refused.contains(&view.problem) {
            self.source_view = None;
        }
    }
}
