//! The side panels: the grammar's diagnostics, the inspector of the part under the cursor, the
//! solver statistics, the live parameter sliders and the rule log. They read state and emit
//! [`Command`]s; they change nothing themselves.

use egui::{Color32, RichText};

use crate::compile::{Problem, Severity};
use crate::sculpt::{Command, Sculpt};

/// Diagnostics of the grammar file: `file:line:col: message`, errors in red.
pub fn diagnostics(ui: &mut egui::Ui, problems: &[Problem], stale: bool) {
    if stale {
        ui.label(
            RichText::new("The file does not compile: the last good model stays live.")
                .color(Color32::from_rgb(200, 40, 40)),
        );
    }
    if problems.is_empty() {
        ui.label("No problems.");
        return;
    }
    for p in problems {
        let colour = match p.severity {
            Severity::Error => Color32::from_rgb(200, 40, 40),
            Severity::Warning => Color32::from_rgb(180, 120, 0),
        };
        ui.label(RichText::new(p.to_string()).color(colour).monospace());
    }
}

/// Why the part under the cursor is in the state it is in.
pub fn inspector(ui: &mut egui::Ui, sculpt: &Sculpt, part: Option<usize>) {
    let Some(report) = part.and_then(|p| sculpt.inspect(p)) else {
        ui.label("Hover a part to inspect it.");
        return;
    };
    ui.label(format!(
        "part {}: {} ({}){}",
        report.part,
        report.piece,
        report.covers,
        if report.pinned { ", pinned" } else { "" }
    ));
    let active_name = report
        .states
        .get(report.active)
        .map_or("?", |s| s.0.as_str());
    ui.label(format!("active state: {active_name}"));
    if report.states.len() > 1 {
        ui.label(format!(
            "another state becomes active below distance {:.4} (hysteresis {:.2})",
            report.switch_below, report.hysteresis
        ));
    }
    egui::Grid::new("states").striped(true).show(ui, |ui| {
        ui.label("state");
        ui.label("distance");
        ui.end_row();
        for (i, (name, d)) in report.states.iter().enumerate() {
            let text = if i == report.active {
                RichText::new(format!("{name} (active)")).strong()
            } else {
                RichText::new(name)
            };
            ui.label(text);
            ui.label(format!("{d:.4}"));
            ui.end_row();
        }
    });
}

/// Solver statistics of the last frame.
pub fn statistics(ui: &mut egui::Ui, sculpt: &Sculpt) {
    let data = sculpt.data();
    ui.label(format!(
        "{} parts, {} vertices, {} connections",
        data.parts.len(),
        data.positions.len(),
        data.docks.len()
    ));
    ui.label(format!(
        "solver frames: {} total, {} in the last UI frame",
        sculpt.frame(),
        sculpt.frames_last_step
    ));
    match sculpt.last_report() {
        Some(r) => {
            ui.label(format!(
                "iterations: {} pass 1 + {} least squares",
                r.pass1_iterations, r.l2_iterations
            ));
            ui.label(format!("energy: {:.6}", r.energy));
            ui.label(format!("frame time: {:.2} ms", r.ms));
            ui.label(if r.converged {
                "converged"
            } else if !r.complete {
                "stopped at the time budget; continues next frame"
            } else {
                "not converged"
            });
        }
        None => {
            ui.label("no frame solved yet");
        }
    }
    if let Some(e) = sculpt.error() {
        ui.label(RichText::new(format!("solver error: {e}")).color(Color32::from_rgb(200, 40, 40)));
    }
}

/// The solver and rule parameters, applied live.
pub fn parameters(ui: &mut egui::Ui, sculpt: &Sculpt, commands: &mut Vec<Command>) {
    let mut s = sculpt.settings();
    let before = s;
    ui.add(egui::Slider::new(&mut s.hysteresis, 0.0..=0.9).text("hysteresis"));
    ui.add(egui::Slider::new(&mut s.norm, 0.1..=2.0).text("p (norm)"));
    ui.add(
        egui::Slider::new(&mut s.merge_distance, 0.0..=5.0)
            .text("merge distance (m)")
            .logarithmic(false),
    );
    if s != before {
        commands.push(Command::Settings(s));
    }
}

/// The rule log, newest first.
pub fn rule_log(ui: &mut egui::Ui, sculpt: &Sculpt) {
    if sculpt.log().is_empty() {
        ui.label("Nothing has fired yet.");
        return;
    }
    egui::ScrollArea::vertical()
        .max_height(220.0)
        .show(ui, |ui| {
            for e in sculpt.log().iter().rev() {
                let at =
                    e.at.map_or(String::new(), |p| format!(" at ({:.2}, {:.2})", p.x, p.y));
                ui.label(format!("frame {}: {}{at}", e.frame, e.message));
            }
        });
}
