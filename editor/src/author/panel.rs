//! Authoring mode's side panel: the tool and snap grid, SVG import, the pieces (names
//! editable) with their instance counts and sites, site type names and the picked site's type,
//! the stretch declaration and its variants, merge rules, posed rest states, and writing and
//! trying the grammar with its diagnostics. It reads state and emits commands and actions only
//! (besides the canvas's pose and picked site, which are view state).

use std::collections::BTreeMap;
use std::path::PathBuf;

use clay::{
    authoring::MergeChoice, authoring::StateChoice, authoring::StretchChoice,
    authoring::VariantChoice, authoring::find_site, authoring::site_names,
};
use egui::{Color32, RichText};

use crate::action::Action;
use crate::diagnostics;
use crate::files::FileKind;

use super::canvas::{AuthorCanvas, Tool, piece_colour, site_colour};
use super::{AuthorCommand, Authoring};

/// Text the user is typing in the panel, kept between frames.
pub struct AuthorForm {
    pub svg_path: String,
    pub scale: String,
    pub tolerance: String,
    /// Site type name being edited, by generated name.
    names: BTreeMap<String, String>,
    /// Piece name being edited, by generated name.
    piece_names: BTreeMap<String, String>,
    /// Stretch sites being picked, by piece.
    picks: BTreeMap<usize, (usize, usize)>,
    /// Merge rule being put together: mover, target, junction (indices into the design's
    /// `piece.site` list; `None` junction: dock directly).
    merge: (usize, usize, Option<usize>),
    /// Type name typed for the picked site.
    pub site_type: String,
    /// Variant frequencies being typed, by piece name (absent: not a variant).
    pub variants: BTreeMap<String, String>,
    /// Name for the rest state being posed.
    pub state_name: String,
}

impl Default for AuthorForm {
    fn default() -> Self {
        Self {
            svg_path: "tests/fixtures/authoring/wall.svg".into(),
            scale: "0.01".into(),
            tolerance: "0.001".into(),
            names: BTreeMap::new(),
            piece_names: BTreeMap::new(),
            picks: BTreeMap::new(),
            merge: (0, 1, None),
            site_type: String::new(),
            variants: BTreeMap::new(),
            state_name: "posed".into(),
        }
    }
}

fn swatch(ui: &mut egui::Ui, colour: Color32) {
    let (r, painter) = ui.allocate_painter(egui::Vec2::splat(12.0), egui::Sense::hover());
    painter.rect_filled(r.rect, 2.0, colour);
}

/// The whole authoring panel.
pub fn show(
    ui: &mut egui::Ui,
    author: &Authoring,
    canvas: &mut AuthorCanvas,
    form: &mut AuthorForm,
    commands: &mut Vec<AuthorCommand>,
    actions: &mut Vec<Action>,
) {
    message_slot(ui, author.message.as_deref());
    egui::CollapsingHeader::new("Drawing")
        .default_open(true)
        .show(ui, |ui| {
            drawing(ui, author, canvas, form, commands, actions)
        });
    let design = match &author.result {
        Ok(c) => &c.design,
        Err(e) => {
            crate::prose::label(ui, e);
            return;
        }
    };
    egui::CollapsingHeader::new(format!("Pieces ({})", design.pieces.len()))
        .default_open(true)
        .show(ui, |ui| pieces(ui, author, canvas, form, commands));
    egui::CollapsingHeader::new(format!("Site types ({})", design.site_types.len()))
        .default_open(true)
        .show(ui, |ui| {
            site_types(ui, author, form, commands);
            site_type_of_site(ui, author, canvas, form, commands);
        });
    // Every section is always there (a command never adds one above a control): Variants
    // says what it waits for until a piece is stretchable.
    egui::CollapsingHeader::new(format!("Variants ({})", author.work().variants.len()))
        .default_open(false)
        .show(ui, |ui| variants(ui, author, form, commands));
    egui::CollapsingHeader::new(format!("Rest states ({})", author.work().states.len()))
        .default_open(canvas.pose.is_some())
        .show(ui, |ui| rest_states(ui, author, canvas, form, commands));
    egui::CollapsingHeader::new(format!("Merge rules ({})", author.work().merges.len()))
        .default_open(false)
        .show(ui, |ui| merges(ui, author, form, commands));
    egui::CollapsingHeader::new(format!("Notes ({})", design.notes.len()))
        .default_open(false)
        .show(ui, |ui| {
            if design.notes.is_empty() {
                ui.label("Nothing to note.");
            }
            for n in &design.notes {
                crate::prose::coloured_label(ui, Color32::from_rgb(180, 120, 0), n);
            }
        });
    egui::CollapsingHeader::new("Grammar")
        .default_open(true)
        .show(ui, |ui| grammar(ui, author, actions));
}

fn drawing(
    ui: &mut egui::Ui,
    author: &Authoring,
    canvas: &mut AuthorCanvas,
    form: &mut AuthorForm,
    commands: &mut Vec<AuthorCommand>,
    actions: &mut Vec<Action>,
) {
    ui.horizontal(|ui| {
        ui.label("Tool:");
        ui.selectable_value(&mut canvas.tool, Tool::Draw, "Draw (D)");
        ui.selectable_value(&mut canvas.tool, Tool::Cut, "Cut (C)");
        ui.selectable_value(&mut canvas.tool, Tool::Site, "Pick site");
    });
    ui.horizontal(|ui| {
        let l = ui.label("Grid (m):");
        ui.add(
            egui::DragValue::new(&mut canvas.grid)
                .speed(0.01)
                .range(0.001..=100.0),
        )
        .labelled_by(l.id)
        .on_hover_text(
            "snap grid step: drawn points snap to grid points, cuts to where an edge crosses \
             a grid line (a drawn vertex under the pointer wins)",
        );
        let l = ui.label("Tolerance (m):");
        let r = ui
            .add(egui::TextEdit::singleline(&mut form.tolerance).desired_width(60.0))
            .labelled_by(l.id);
        if r.lost_focus() {
            match form.tolerance.trim().parse::<f64>() {
                Ok(t) if t != author.work().tolerance => {
                    commands.push(AuthorCommand::SetTolerance(t))
                }
                Ok(_) => {}
                Err(_) => form.tolerance = author.work().tolerance.to_string(),
            }
        }
    });
    let w = author.work();
    ui.label(format!(
        "{} strokes, {} cuts{}",
        w.drawing.polylines.len(),
        w.cuts.len(),
        if canvas.pending.is_empty() {
            String::new()
        } else {
            format!(", drawing ({} points)", canvas.pending.len())
        }
    ));
    ui.horizontal(|ui| {
        let l = ui.label("SVG:");
        ui.add(egui::TextEdit::singleline(&mut form.svg_path).desired_width(170.0))
            .labelled_by(l.id);
    });
    ui.horizontal(|ui| {
        let l = ui.label("metres per unit:");
        ui.add(egui::TextEdit::singleline(&mut form.scale).desired_width(60.0))
            .labelled_by(l.id);
        if ui.button("Import SVG").clicked() {
            match form.scale.trim().parse::<f64>() {
                Ok(scale) => actions.push(Action::ImportSvg(
                    PathBuf::from(form.svg_path.trim()),
                    scale,
                )),
                Err(_) => actions.push(Action::Report(format!(
                    "the scale `{}` is not a number",
                    form.scale.trim()
                ))),
            }
        }
    });
    if ui.button("Clear drawing").clicked() {
        commands.push(AuthorCommand::Clear);
    }
}

// Long because: the Pieces panel's widgets in display order.
fn pieces(
    ui: &mut egui::Ui,
    author: &Authoring,
    canvas: &mut AuthorCanvas,
    form: &mut AuthorForm,
    commands: &mut Vec<AuthorCommand>,
) {
    let Some(design) = author.design() else {
        return;
    };
    let mut counts = vec![0usize; design.pieces.len()];
    for i in &design.instances {
        if let Some(c) = counts.get_mut(i.piece) {
            *c += 1;
        }
    }
    let generated = author
        .result
        .as_ref()
        .map(|c| c.generated_piece_names.clone())
        .unwrap_or_default();
    for (pi, piece) in design.pieces.iter().enumerate() {
        ui.horizontal_wrapped(|ui| {
            swatch(ui, piece_colour(piece));
            if let Some(g) = generated.get(pi) {
                piece_name(ui, g, &piece.name, form, commands);
            } else {
                ui.strong(&piece.name);
            }
            ui.label(format!(
                "× {} instance{}",
                counts[pi],
                if counts[pi] == 1 { "" } else { "s" }
            ));
        });
        ui.indent(("sites", pi), |ui| {
            for s in &piece.sites {
                ui.horizontal(|ui| {
                    swatch(ui, site_colour(s.site_type));
                    let t = design
                        .site_types
                        .get(s.site_type)
                        .map_or("?", String::as_str);
                    let picked = canvas
                        .selected_site
                        .as_ref()
                        .is_some_and(|x| x.piece == piece.name && x.site == s.name);
                    if ui
                        .selectable_label(picked, format!("{}: {t}", s.name))
                        .on_hover_text("pick this site to set its type")
                        .clicked()
                    {
                        canvas.selected_site = Some(clay::authoring::SiteName {
                            piece: piece.name.clone(),
                            site: s.name.clone(),
                        });
                    }
                });
            }
            if piece.sites.len() >= 2 {
                let pick = form
                    .picks
                    .entry(pi)
                    .or_insert(piece.stretch.map_or((0, 1), |[a, b]| (a, b)));
                // Two rows that fit the panel: the sites, then the button and what the piece
                // does now, which changes beside the button, never above it.
                ui.horizontal(|ui| {
                    for (label, value) in [("from", &mut pick.0), ("to", &mut pick.1)] {
                        let l = ui.label(label);
                        egui::ComboBox::from_id_salt((label, pi))
                            .width(80.0)
                            .selected_text(piece.sites.get(*value).map_or("?", |s| &s.name))
                            .show_ui(ui, |ui| {
                                for (si, s) in piece.sites.iter().enumerate() {
                                    ui.selectable_value(value, si, &s.name);
                                }
                            })
                            .response
                            .labelled_by(l.id);
                    }
                });
                ui.horizontal(|ui| {
                    if ui.button("Stretchable").clicked() {
                        commands.push(AuthorCommand::SetStretch(Some(StretchChoice::Sites {
                            piece: pi,
                            from: pick.0,
                            to: pick.1,
                        })));
                    }
                    let now = match piece.stretch {
                        Some([from, to]) => {
                            let name =
                                |s: usize| piece.sites.get(s).map_or("?", |s| s.name.as_str());
                            format!("stretches {} -> {}", name(from), name(to))
                        }
                        None => "not stretchable".to_string(),
                    };
                    ui.add(egui::Label::new(now).truncate());
                });
            }
        });
    }
    ui.horizontal(|ui| {
        if ui.button("Stretch: auto").clicked() {
            commands.push(AuthorCommand::SetStretch(Some(StretchChoice::Auto)));
        }
        if ui
            .add_enabled(
                author.work().stretch.is_some(),
                egui::Button::new("No stretch"),
            )
            .clicked()
        {
            commands.push(AuthorCommand::SetStretch(None));
        }
    });
}

/// A piece's name as an editable field: Enter (or leaving the field) renames it; a refused
/// name reverts, and the panel and status bar say why.
fn piece_name(
    ui: &mut egui::Ui,
    generated: &str,
    shown: &str,
    form: &mut AuthorForm,
    commands: &mut Vec<AuthorCommand>,
) {
    let buffer = form
        .piece_names
        .entry(generated.to_string())
        .or_insert_with(|| shown.to_string());
    let r = ui
        .add(egui::TextEdit::singleline(buffer).desired_width(110.0))
        .on_hover_text("piece name, written into the grammar: edit, then Enter");
    r.widget_info(|| {
        egui::WidgetInfo::labeled(egui::Role::TextInput, true, format!("piece {generated}"))
    });
    if r.lost_focus() {
        if *buffer != shown {
            commands.push(AuthorCommand::RenamePiece {
                from: generated.to_string(),
                to: buffer.clone(),
            });
        }
        form.piece_names.remove(generated);
    } else if !r.has_focus() && *buffer != shown {
        // Undo or redo changed the name under the field.
        *buffer = shown.to_string();
    }
}

fn merges(
    ui: &mut egui::Ui,
    author: &Authoring,
    form: &mut AuthorForm,
    commands: &mut Vec<AuthorCommand>,
) {
    for (i, m) in author.work().merges.iter().enumerate() {
        ui.horizontal(|ui| {
            ui.label(RichText::new(m.to_string()).monospace());
            if ui.small_button("remove").clicked() {
                commands.push(AuthorCommand::RemoveMerge { index: i });
            }
        });
    }
    let Some(design) = author.design() else {
        return;
    };
    let names = site_names(design);
    if names.len() < 2 {
        ui.label("A merge needs two docking sites.");
        return;
    }
    let shown = |i: Option<usize>| {
        i.and_then(|i| names.get(i))
            .map_or("(dock directly)".to_string(), |s| s.to_string())
    };
    let (mover, target, junction) = &mut form.merge;
    egui::Grid::new("merge pick").show(ui, |ui| {
        for (label, value) in [("merge", &mut *mover), ("onto", &mut *target)] {
            let l = ui.label(label);
            egui::ComboBox::from_id_salt(label)
                .selected_text(shown(Some(*value)))
                .show_ui(ui, |ui| {
                    for (i, n) in names.iter().enumerate() {
                        ui.selectable_value(value, i, n.to_string());
                    }
                })
                .response
                .labelled_by(l.id);
            ui.end_row();
        }
        let l = ui.label("into");
        egui::ComboBox::from_id_salt("into")
            .selected_text(shown(*junction))
            .show_ui(ui, |ui| {
                ui.selectable_value(junction, None, shown(None));
                for (i, n) in names.iter().enumerate() {
                    ui.selectable_value(junction, Some(i), n.to_string());
                }
            })
            .response
            .labelled_by(l.id);
        ui.end_row();
    });
    if ui.button("Add merge rule").clicked()
        && let (Some(m), Some(t)) = (names.get(*mover), names.get(*target))
    {
        commands.push(AuthorCommand::AddMerge(MergeChoice {
            mover: m.clone(),
            target: t.clone(),
            junction: junction.and_then(|j| names.get(j).cloned()),
        }));
    }
}

fn site_types(
    ui: &mut egui::Ui,
    author: &Authoring,
    form: &mut AuthorForm,
    commands: &mut Vec<AuthorCommand>,
) {
    let Ok(c) = &author.result else {
        return;
    };
    for (ti, generated) in c.generated_site_types.iter().enumerate() {
        let shown = c.design.site_types.get(ti).cloned().unwrap_or_default();
        ui.horizontal(|ui| {
            swatch(ui, site_colour(ti));
            let buffer = form
                .names
                .entry(generated.clone())
                .or_insert_with(|| shown.clone());
            let r = ui
                .add(egui::TextEdit::singleline(buffer).desired_width(140.0))
                .on_hover_text("site type name: edit, then Enter");
            r.widget_info(|| {
                egui::WidgetInfo::labeled(
                    egui::Role::TextInput,
                    true,
                    format!("site type {generated}"),
                )
            });
            if r.lost_focus() {
                if *buffer != shown {
                    commands.push(AuthorCommand::RenameSiteType {
                        from: generated.clone(),
                        to: buffer.clone(),
                    });
                }
                // Show what the work holds; a refused rename reverts.
                form.names.remove(generated);
            } else if !r.has_focus() && *buffer != shown {
                // Undo or redo changed the name under the field.
                *buffer = shown.clone();
            }
        });
    }
}

/// The picked site's type: an existing type or a new name.
fn site_type_of_site(
    ui: &mut egui::Ui,
    author: &Authoring,
    canvas: &AuthorCanvas,
    form: &mut AuthorForm,
    commands: &mut Vec<AuthorCommand>,
) {
    let Some(design) = author.design() else {
        return;
    };
    ui.separator();
    let Some(site) = &canvas.selected_site else {
        ui.label("Pick a site (in the list above, or with the Pick site tool) to set its type.");
        return;
    };
    let Some((p, s)) = find_site(design, site) else {
        ui.label(format!("{site} is gone"));
        return;
    };
    let current = design.pieces[p].sites[s].site_type;
    ui.horizontal(|ui| {
        swatch(ui, site_colour(current));
        let l = ui.strong(site.to_string());
        egui::ComboBox::from_id_salt("site type of site")
            .selected_text(design.site_types.get(current).map_or("?", String::as_str))
            .show_ui(ui, |ui| {
                for (ti, t) in design.site_types.iter().enumerate() {
                    if ui.selectable_label(ti == current, t).clicked() && ti != current {
                        commands.push(AuthorCommand::SetSiteType {
                            site: site.clone(),
                            site_type: t.clone(),
                        });
                    }
                }
            })
            .response
            .labelled_by(l.id);
    });
    ui.horizontal(|ui| {
        let l = ui.label("new type:");
        ui.add(egui::TextEdit::singleline(&mut form.site_type).desired_width(100.0))
            .labelled_by(l.id);
        if ui.button("Set type").clicked() {
            commands.push(if form.site_type.trim().is_empty() {
                AuthorCommand::Report("type the new site type's name first".into())
            } else {
                AuthorCommand::SetSiteType {
                    site: site.clone(),
                    site_type: form.site_type.trim().to_string(),
                }
            });
        }
    });
}

/// The stretch rule's variants: pieces with the stretch piece's graph, with frequencies.
fn variants(
    ui: &mut egui::Ui,
    author: &Authoring,
    form: &mut AuthorForm,
    commands: &mut Vec<AuthorCommand>,
) {
    let Some(design) = author.design() else {
        return;
    };
    let Some(sp) = design.pieces.iter().position(|p| p.stretch.is_some()) else {
        ui.label("Mark a piece stretchable first: variants are other pieces its chains insert.");
        return;
    };
    for v in &author.work().variants {
        ui.label(RichText::new(format!("{} {:.4}", v.piece, v.frequency)).monospace());
    }
    ui.label("Pieces with the same vertices, edges and sites; frequencies are normalised:");
    for (pi, piece) in design.pieces.iter().enumerate() {
        let fits = pi == sp || clay::authoring::variant_map(design, sp, pi).is_ok();
        ui.horizontal(|ui| {
            let mut on = form.variants.contains_key(&piece.name);
            let r = ui.add_enabled(
                fits,
                egui::Checkbox::new(&mut on, format!("variant {}", piece.name)),
            );
            if r.changed() {
                if on {
                    form.variants.insert(piece.name.clone(), "1".into());
                } else {
                    form.variants.remove(&piece.name);
                }
            }
            if let Some(f) = form.variants.get_mut(&piece.name) {
                ui.add(egui::TextEdit::singleline(f).desired_width(50.0))
                    .on_hover_text("target frequency");
            }
            if !fits {
                ui.label("(other shape)");
            }
        });
    }
    ui.horizontal(|ui| {
        if ui.button("Set variants").clicked() {
            let mut list = Vec::new();
            for (piece, f) in &form.variants {
                match f.trim().parse::<f64>() {
                    Ok(frequency) => list.push(VariantChoice {
                        piece: piece.clone(),
                        frequency,
                    }),
                    Err(_) => {
                        // A frequency that is no number: the command refuses it with a message.
                        list.push(VariantChoice {
                            piece: piece.clone(),
                            frequency: f64::NAN,
                        })
                    }
                }
            }
            // The stretch piece first, as it is the rule's piece.
            list.sort_by_key(|v| v.piece != design.pieces[sp].name);
            commands.push(AuthorCommand::SetVariants(list));
        }
        if ui
            .add_enabled(
                !author.work().variants.is_empty(),
                egui::Button::new("No variants"),
            )
            .clicked()
        {
            commands.push(AuthorCommand::SetVariants(Vec::new()));
        }
    });
}

/// Alternative rest states: pose a copy of a piece on the canvas, then keep it.
fn rest_states(
    ui: &mut egui::Ui,
    author: &Authoring,
    canvas: &mut AuthorCanvas,
    form: &mut AuthorForm,
    commands: &mut Vec<AuthorCommand>,
) {
    if let Some(p) = &canvas.pose
        && author
            .work()
            .states
            .iter()
            .any(|s| s.piece == p.piece && s.positions == p.positions)
    {
        canvas.pose = None;
    }
    for (i, st) in author.work().states.iter().enumerate() {
        ui.horizontal(|ui| {
            ui.label(RichText::new(format!("{}: state {}", st.piece, st.name)).monospace());
            if ui.small_button("remove").clicked() {
                commands.push(AuthorCommand::RemoveState { index: i });
            }
        });
    }
    let Some(design) = author.design() else {
        return;
    };
    match &canvas.pose {
        None => {
            ui.horizontal_wrapped(|ui| {
                for (pi, p) in design.pieces.iter().enumerate() {
                    if ui
                        .button(format!("New rest state of {}", p.name))
                        .on_hover_text("pose a copy: drag its vertices on the canvas")
                        .clicked()
                    {
                        canvas.start_pose(author, pi);
                    }
                }
            });
        }
        Some(pose) => {
            ui.label(format!(
                "Posing {}: drag its green vertices (they snap to the grid).",
                pose.piece
            ));
            let mut keep = None;
            let mut drop = false;
            ui.horizontal(|ui| {
                let l = ui.label("name:");
                ui.add(egui::TextEdit::singleline(&mut form.state_name).desired_width(90.0))
                    .labelled_by(l.id);
                if ui.button("Keep state").clicked() {
                    keep = Some(StateChoice {
                        piece: pose.piece.clone(),
                        name: form.state_name.trim().to_string(),
                        positions: pose.positions.clone(),
                    });
                }
                drop = ui.button("Drop pose").clicked();
            });
            if let Some(st) = keep {
                // The pose stays until the state is in the work, so a refused one (the
                // command's message says why) can be fixed.
                commands.push(AuthorCommand::AddState(st));
            }
            if drop {
                canvas.pose = None;
            }
        }
    }
}

fn grammar(ui: &mut egui::Ui, author: &Authoring, actions: &mut Vec<Action>) {
    // Nothing is written where the user did not choose: the first write asks for the file.
    let file = author.written.as_ref().map(|(p, _)| p);
    ui.horizontal(|ui| {
        ui.label("File:");
        let shown = file.map_or("not written yet".to_string(), |p| p.display().to_string());
        ui.add(egui::Label::new(shown).truncate());
    });
    ui.horizontal(|ui| {
        let write = ui
            .button("Write grammar")
            .on_hover_text("write the grammar to its file (asks which the first time)");
        if write.clicked() {
            actions.push(match file {
                Some(p) => Action::WriteGrammar(p.clone()),
                None => Action::Ask(FileKind::WriteGrammar),
            });
        }
        if ui
            .button("Write as…")
            .on_hover_text("write the grammar to another file")
            .clicked()
        {
            actions.push(Action::Ask(FileKind::WriteGrammar));
        }
        if ui
            .add_enabled(author.compiles, egui::Button::new("Try it"))
            .on_hover_text("compile and sculpt the grammar")
            .on_disabled_hover_text("the grammar does not compile yet: see its diagnostics")
            .clicked()
        {
            actions.push(Action::TryAuthored);
        }
    });
    let state = match (&author.written, author.text()) {
        (Some((_, t)), Some(text)) if t == text => "written",
        (Some(_), _) => "changed since it was written",
        (None, _) => "",
    };
    ui.label(state);
    if author.text().is_some() && !author.compiles {
        ui.label(
            RichText::new("The grammar does not compile.").color(Color32::from_rgb(200, 40, 40)),
        );
    }
    diagnostics::diagnostics(ui, &author.problems, None);
    if let Some(text) = author.text() {
        egui::CollapsingHeader::new("Text")
            .default_open(false)
            .show(ui, |ui| {
                // A scroll bar of its own below the text (not floating over it or the header).
                ui.spacing_mut().scroll = egui::style::ScrollStyle::solid();
                egui::ScrollArea::horizontal()
                    .id_salt("grammar text")
                    .show(ui, |ui| {
                        ui.add(egui::Label::new(RichText::new(text).monospace()).extend());
                    });
            });
    }
}

/// The last command's message in a slot of one line that is always there (empty or not), so
/// that a message never pushes the controls below it; the whole text on hover.
fn message_slot(ui: &mut egui::Ui, message: Option<&str>) {
    let height = ui.text_style_height(&egui::TextStyle::Body);
    let size = egui::vec2(ui.available_width(), height);
    let (rect, _) = ui.allocate_exact_size(size, egui::Sense::hover());
    if let Some(m) = message {
        let text = RichText::new(m).color(Color32::from_rgb(200, 40, 40));
        ui.put(rect, egui::Label::new(text).truncate())
            .on_hover_text(m);
    }
}
