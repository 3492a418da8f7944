//! The grammar's problems as the editor shows them, in both modes' side panels: each as rustc
//! shows it (headline, source line with the span underlined, related places, hints), and the
//! source view a click on one opens (the file's text around the problem's line).

use egui::{Color32, RichText};

use crate::compile::{Problem, Severity};

const ERROR: Color32 = Color32::from_rgb(200, 40, 40);
const WARNING: Color32 = Color32::from_rgb(180, 120, 0);
const NOTE: Color32 = Color32::from_rgb(40, 90, 170);

/// Diagnostics as rustc shows them: `file:line:col: error[code]: message`, the source line
/// with the span underlined and labelled, related places, and `help:` hints. `banner` says
/// what became of the model. Returns the problem clicked (to show in the source view).
pub fn diagnostics<'a>(
    ui: &mut egui::Ui,
    problems: &'a [Problem],
    banner: Option<&str>,
) -> Option<&'a Problem> {
    if let Some(b) = banner {
        ui.label(RichText::new(b).color(ERROR));
    }
    if problems.is_empty() {
        ui.label("No problems.");
        return None;
    }
    let mut clicked = None;
    for p in problems {
        if problem(ui, p) {
            clicked = Some(p);
        }
    }
    clicked
}

/// One problem; returns whether its headline was clicked.
fn problem(ui: &mut egui::Ui, p: &Problem) -> bool {
    let colour = match p.severity {
        Severity::Error => ERROR,
        Severity::Warning => WARNING,
    };
    let headline = ui
        .add(
            egui::Label::new(RichText::new(p.to_string()).color(colour).monospace())
                .sense(egui::Sense::click()),
        )
        .on_hover_text("Click to show the line in the Source view");
    if !p.snippet.is_empty() {
        let gutter = p.line.to_string().len();
        let text = format!(
            "{:>gutter$} | {}\n{:>gutter$} | {} {}",
            p.line,
            p.snippet,
            "",
            p.underline(),
            p.label
        );
        ui.label(RichText::new(text).monospace().size(11.0));
    }
    for (line, col, message) in &p.related {
        ui.label(
            RichText::new(format!("note: line {line}:{col}: {message}"))
                .color(NOTE)
                .monospace()
                .size(11.0),
        );
    }
    for h in &p.hints {
        ui.label(RichText::new(format!("help: {h}")).monospace().size(11.0));
    }
    ui.add_space(4.0);
    headline.clicked()
}

/// A read-only view of a grammar's text around one line, the span underlined: the line of a
/// listed problem, shown while that problem is listed.
#[derive(Clone, Debug, PartialEq)]
pub struct SourceView {
    /// The problem shown.
    pub problem: Problem,
    pub file: String,
    pub text: String,
    /// The selected line (1-based) and the span on it (columns, 1-based, end exclusive).
    pub line: usize,
    pub col: usize,
    pub end_col: usize,
}

/// Lines shown around the selected one.
const CONTEXT_LINES: usize = 6;

/// Shows the source view: the file's lines around the selected one, that line highlighted.
pub fn source(ui: &mut egui::Ui, view: &SourceView) {
    ui.label(RichText::new(format!("{}:{}:{}", view.file, view.line, view.col)).strong());
    let lines: Vec<&str> = view.text.lines().collect();
    let first = view.line.saturating_sub(CONTEXT_LINES + 1);
    let last = (view.line + CONTEXT_LINES).min(lines.len());
    let gutter = last.to_string().len();
    for (i, line) in lines.iter().enumerate().take(last).skip(first) {
        let n = i + 1;
        let text = RichText::new(format!("{n:>gutter$} | {line}"))
            .monospace()
            .size(11.0);
        if n == view.line {
            ui.label(text.background_color(Color32::from_rgb(255, 236, 160)));
            let width = view.end_col.saturating_sub(view.col).max(1);
            let under = format!(
                "{:>gutter$} | {}{}",
                "",
                " ".repeat(view.col.saturating_sub(1)),
                "^".repeat(width)
            );
            ui.label(RichText::new(under).monospace().size(11.0).color(ERROR));
        } else {
            ui.label(text);
        }
    }
}
