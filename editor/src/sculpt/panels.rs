//! Sculpt mode's side panels: the inspector of the part under the cursor, the solver
//! statistics, the live parameter sliders, the grammar's parameters and the rule log (the
//! diagnostics above them are both modes', `crate::diagnostics`). They read state and emit
//! [`Command`]s; they change nothing themselves.

use clay_dsl::compiled::{ParamKind, ParamValue};
use egui::{Color32, RichText};

use super::{Command, Sculpt};

/// Why the part under the cursor is in the state it is in.
pub fn inspector(ui: &mut egui::Ui, sculpt: &Sculpt, part: Option<usize>) {
    let Some(report) = part.and_then(|p| sculpt.inspect(p)) else {
        ui.label("Hover a part to inspect it.");
        return;
    };
    crate::prose::label(
        ui,
        &format!(
            "{} ({}){}",
            report.covers,
            report.piece,
            if report.pinned { ", pinned" } else { "" }
        ),
    )
    .on_hover_text(format!("part {} of the solver", report.why.part));
    if report.covers.contains('#') {
        names_note(ui);
    }
    let active_name = report
        .why
        .states
        .get(report.why.active)
        .map_or("?", |s| s.0.as_str());
    if report.why.at_rest {
        crate::prose::label(ui, &format!("rests as `{active_name}`"));
    } else {
        crate::prose::label(ui, &format!("in `{active_name}`, strained (not at rest)"));
    }
    if let Some((_, length)) = report.why.candidate {
        ui.label(format!("its two elements span {length:.2} elements"));
    }
    let turns = report.why.turns.as_ref();
    if let Some((turn, _)) = turns {
        let first = report.why.states.first().map_or("?", |s| s.0.as_str());
        crate::prose::label(
            ui,
            &format!("judged by the turn between its sites: {turn:.1} degrees from `{first}`'s"),
        );
    }
    if report.why.states.len() > 1 {
        let best_other = report
            .why
            .states
            .iter()
            .enumerate()
            .filter(|(i, _)| {
                *i != report.why.active && report.why.available.get(*i) != Some(&false)
            })
            .min_by(|a, b| a.1.1.total_cmp(&b.1.1));
        if let Some((_, (name, d))) = best_other {
            let active_misfit = report
                .why
                .states
                .get(report.why.active)
                .map_or(0.0, |s| s.1);
            crate::prose::label(
                ui,
                &format!(
                    "`{name}` would take over once its misfit is below {:.4}, {:.0}% under \
                 `{active_name}`'s {active_misfit:.4} (the hysteresis); `{name}`'s is {d:.4} now",
                    report.why.switch_below,
                    100.0 * report.why.hysteresis
                ),
            );
        }
        for (i, (name, _)) in report.why.states.iter().enumerate() {
            if report.why.available.get(i) == Some(&false) {
                crate::prose::label(
                    ui,
                    &format!(
                        "`{name}` is ruled out now: the chain's length or its `min`/`max` does \
                     not call for it"
                    ),
                );
            }
        }
    }
    egui::Grid::new("states").striped(true).show(ui, |ui| {
        ui.label("rest state");
        if turns.is_some() {
            ui.label("turn (degrees)")
                .on_hover_text("the state's turn between its sites, from the first state's");
            ui.label("misfit (rad²)")
                .on_hover_text("the difference between the state's turn and the pose's, squared");
        } else {
            ui.label("misfit (m²)").on_hover_text(
                "shape-space distance from the current pose, squared, after the best rotation",
            );
        }
        ui.end_row();
        for (i, (name, d)) in report.why.states.iter().enumerate() {
            let text = if i == report.why.active {
                RichText::new(format!("{name} (active)")).strong()
            } else {
                RichText::new(name)
            };
            ui.label(text);
            if let Some((_, of_state)) = turns {
                let turn = of_state.get(i).filter(|t| t.is_finite());
                ui.label(turn.map_or("-".to_string(), |t| format!("{t:.1}")));
            }
            ui.label(format!("{d:.4}"));
            ui.end_row();
        }
    });
}

/// What the two kinds of instance names mean, where both are shown: the grammar names a
/// chain's elements by their place (`wall[3]`), a rule names an element it inserts by its new
/// instance id (`wall#12`), which says nothing of where it sits in the chain.
pub const NAMES_NOTE: &str = "`wall[3]`: element 3 (from 0) of the chain `wall` as the grammar \
     placed it; `wall#12`: an element a rule inserted later, named by its instance id 12, not \
     by its place in the chain.";

fn names_note(ui: &mut egui::Ui) {
    let job = crate::prose::styled(NAMES_NOTE, ui.style(), |r| r.small().weak());
    ui.label(job);
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
    ui.add(egui::Slider::new(&mut s.hysteresis, 0.0..=0.9).text("hysteresis"))
        .on_hover_text(
            "How much better another rest state must fit before a part switches to it \
             (0.15: 15% better); higher stops parts flickering between states",
        );
    ui.add(egui::Slider::new(&mut s.norm, 0.1..=2.0).text("norm exponent p"))
        .on_hover_text(
            "The sparsity of the deformation: below 1 one part bends and snaps to a new state \
             while the others stay at rest; 2 spreads it over all (least squares)",
        );
    ui.add(
        egui::Slider::new(&mut s.merge_distance, 0.0..=5.0)
            .text("merge distance (m)")
            .logarithmic(false),
    )
    .on_hover_text("Open sites closer than this weld (the grammar's merge rules)");
    if s != before {
        commands.push(Command::Settings(s));
    }
}

/// What the Grammar parameters panel asks for: a value for one of the grammar's parameters
/// (`param NAME = ...`), or its default back. The app recompiles the grammar with it after
/// the frame, keeping the sculpt where the structure allows, as hot reload does.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamChange {
    Set(String, ParamValue),
    Reset(String),
}

/// The grammar's parameters, each with a widget of its type: a slider per ranged number (an
/// integer slider for an `int`, a number field without a range), a checkbox per `bool`, a
/// combo box per `choice`; its default shown and a button back to it. A number is emitted
/// once the slider is released or the field committed, not on every pointer move: each
/// value recompiles.
pub fn grammar_parameters(
    ui: &mut egui::Ui,
    params: &[clay_dsl::compiled::Param],
    changes: &mut Vec<ParamChange>,
) {
    // The reset button first, the widget (with the name) after it, the default under it: at
    // 1280 px the side panel cut off a reset button placed last (issue 48).
    egui::Grid::new("grammar parameters")
        .num_columns(2)
        .show(ui, |ui| {
            for p in params {
                let reset = ui
                    .add_enabled(p.value != p.default, egui::Button::new("reset").small())
                    .on_hover_text(format!("Back to the default, {}", p.default))
                    .on_disabled_hover_text(format!("At the default, {}", p.default));
                if reset.clicked() {
                    changes.push(ParamChange::Reset(p.name.clone()));
                }
                let set = match &p.kind {
                    ParamKind::Bool => bool_widget(ui, p),
                    ParamKind::Choice { choices } => choice_widget(ui, p, choices),
                    _ => number_widget(ui, p),
                };
                if let Some(v) = set.filter(|v| *v != p.value) {
                    changes.push(ParamChange::Set(p.name.clone(), v));
                }
                ui.end_row();
                ui.label("");
                ui.label(
                    RichText::new(format!("default {}", p.default))
                        .weak()
                        .small(),
                );
                ui.end_row();
            }
        });
}

/// The hover text of a parameter's widget.
fn param_hover(p: &clay_dsl::compiled::Param) -> String {
    format!(
        "param {}: {} of the grammar{}, default {}: a change recompiles it, keeping the \
         sculpt where the structure allows",
        p.name,
        p.kind.word(),
        p.range
            .map_or(String::new(), |[lo, hi]| format!(", in {lo}..{hi}")),
        p.default
    )
}

/// A checkbox; the value when it was clicked.
fn bool_widget(ui: &mut egui::Ui, p: &clay_dsl::compiled::Param) -> Option<ParamValue> {
    let mut on = p.value.bool().unwrap_or(false);
    let r = ui.checkbox(&mut on, &p.name).on_hover_text(param_hover(p));
    r.changed().then_some(ParamValue::Bool(on))
}

/// A combo box of the choices; the one picked.
fn choice_widget(
    ui: &mut egui::Ui,
    p: &clay_dsl::compiled::Param,
    choices: &[String],
) -> Option<ParamValue> {
    let current = p.value.text().unwrap_or("").to_string();
    let mut picked = current.clone();
    egui::ComboBox::from_label(&p.name)
        .selected_text(&current)
        .show_ui(ui, |ui| {
            for c in choices {
                ui.selectable_value(&mut picked, c.clone(), c);
            }
        })
        .response
        .on_hover_text(param_hover(p));
    (picked != current).then_some(ParamValue::Text(picked))
}

/// A slider (a number field without a range), whole-numbered for an `int` or `seed` (and for
/// a number whose default and range are whole); the value once released or committed.
fn number_widget(ui: &mut egui::Ui, p: &clay_dsl::compiled::Param) -> Option<ParamValue> {
    let id = egui::Id::unique(("grammar parameter", &p.name));
    let value = p.value.number().unwrap_or(0.0);
    let mut v = ui.data(|d| d.get_temp::<f64>(id)).unwrap_or(value);
    let whole = |x: f64| x.fract() == 0.0;
    let integral = p.kind.is_whole()
        || (p.default.number().is_some_and(whole)
            && p.range.is_none_or(|[lo, hi]| whole(lo) && whole(hi)));
    let r = match p.range {
        Some([lo, hi]) => {
            let mut slider = egui::Slider::new(&mut v, lo..=hi)
                .text(&p.name)
                .update_while_editing(false);
            if integral {
                slider = slider.step_by(1.0).integer();
            }
            ui.add(slider)
        }
        None => {
            ui.horizontal(|ui| {
                let mut field = egui::DragValue::new(&mut v)
                    .speed(if integral { 1.0 } else { 0.01 })
                    .update_while_editing(false);
                if integral {
                    field = field.fixed_decimals(0);
                }
                if p.kind == ParamKind::Seed {
                    field = field.range(0.0..=f64::MAX);
                }
                let r = ui.add(field);
                ui.label(&p.name);
                r
            })
            .inner
        }
    };
    let r = r.on_hover_text(param_hover(p));
    let released =
        r.drag_stopped() || r.clicked() || (r.changed() && !r.is_pointer_button_down_on());
    if released {
        ui.data_mut(|d| d.remove::<f64>(id));
        // A typed fraction in an integer field is rounded, as the slider does.
        let v = if integral { v.round() } else { v };
        return (v.is_finite() && v != value).then_some(ParamValue::Number(v));
    } else if r.changed() || r.is_pointer_button_down_on() {
        ui.data_mut(|d| d.insert_temp(id, v));
    } else {
        ui.data_mut(|d| d.remove::<f64>(id));
    }
    None
}

/// The rule log, newest first: what the rules did, in the words of the grammar's names. It
/// follows undo and redo (an undone gesture's lines go with it).
pub fn rule_log(ui: &mut egui::Ui, sculpt: &Sculpt) {
    if sculpt.log().is_empty() {
        ui.label("Nothing has fired yet.");
        return;
    }
    if sculpt.log().iter().any(|e| e.message.contains('#')) {
        names_note(ui);
    }
    egui::ScrollArea::vertical()
        .id_salt("rule log")
        .max_height(220.0)
        .show(ui, |ui| {
            for e in sculpt.log().iter().rev() {
                let text = format!("frame {}: {}", e.frame, e.message);
                if e.outside {
                    crate::prose::coloured_label(ui, Color32::from_rgb(200, 40, 40), &text);
                } else {
                    crate::prose::label(ui, &text);
                }
            }
        });
}
