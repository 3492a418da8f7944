//! Authoring mode. This module is its state: the author's work (`clay::authoring::Work`: the
//! drawing, its cuts and the rule declarations) with its undo history, the grammar the library
//! computes from it (`clay::authoring::compute`, the same steps as `clayc author`) with the
//! compiler's diagnostics, and what the last command has to say. Every change is an
//! [`AuthorCommand`]; changes to the work are undoable as whole steps.
//!
//! The mode's view is in the children: `canvas` (the drawing and the design drawn, the draw,
//! cut and site tools) and `panel` (the side panel). They import this module; it imports
//! neither.

use std::path::{Path, PathBuf};

use clay::{
    authoring::Computed, authoring::Design, authoring::Drawing, authoring::MergeChoice,
    authoring::Polyline, authoring::SiteName, authoring::StateChoice, authoring::StretchChoice,
    authoring::VariantChoice, authoring::Work, authoring::check_name, authoring::compute,
    authoring::docked_sites, authoring::find_site, authoring::site_names, authoring::variant_map,
};
use glam::DVec2;

use crate::compile::{self, Problem};

pub mod canvas;
pub mod panel;

/// Name the authored grammar is compiled under before it has been written to a file.
pub const UNSAVED_NAME: &str = "authored.clay";

/// A change to the authoring state.
#[derive(Clone, Debug, PartialEq)]
pub enum AuthorCommand {
    /// Replace the drawing (an SVG import): cuts and declarations start over.
    SetDrawing(Drawing),
    /// Add a stroke drawn on the canvas.
    AddPolyline(Polyline),
    /// Cut the drawing at a point (refused, with a message, if the library cannot cut there).
    Cut {
        point: DVec2,
    },
    /// Remove cut number `index`.
    RemoveCut {
        index: usize,
    },
    /// Rename a site type: `from` is the generated name.
    RenameSiteType {
        from: String,
        to: String,
    },
    /// Rename a piece: `from` is the generated name. The declarations naming the piece follow.
    RenamePiece {
        from: String,
        to: String,
    },
    /// Say why a click did nothing (the canvas sends it): shown in the panel and status bar.
    Report(String),
    /// Make a piece stretchable (or none).
    SetStretch(Option<StretchChoice>),
    /// Declare a merge rule (refused unless its sites exist).
    AddMerge(MergeChoice),
    RemoveMerge {
        index: usize,
    },
    /// Give a site a type (an existing one or a new name). The sites docked with it, directly
    /// or through other docks, get it too: the written types dock only with themselves.
    SetSiteType {
        site: SiteName,
        site_type: String,
    },
    /// Set the stretch rule's variants (empty: none). Frequencies are normalised to sum to 1;
    /// refused unless a stretch is declared and every variant has the stretch piece's shape.
    SetVariants(Vec<VariantChoice>),
    /// Add an alternative rest state to a piece (refused unless it has one finite position per
    /// vertex, no two at one place, and a new name).
    AddState(StateChoice),
    RemoveState {
        index: usize,
    },
    SetTolerance(f64),
    /// Start over with an empty drawing.
    Clear,
    Undo,
    Redo,
}

/// Authoring mode.
pub struct Authoring {
    work: Work,
    undo: Vec<Work>,
    redo: Vec<Work>,
    /// The design of the current work, or why there is none.
    pub result: Result<Computed, String>,
    /// Compiler diagnostics of `text` (empty: it compiles clean).
    pub problems: Vec<Problem>,
    /// Whether the compiler accepted the text.
    pub compiles: bool,
    /// Where the grammar was last written, and the text written there.
    pub written: Option<(PathBuf, String)>,
    /// The outcome of the last command or file action, for the panel.
    pub message: Option<String>,
    /// What the last command has to say, until the app moves it to its status bar.
    status: Option<String>,
}

impl Default for Authoring {
    fn default() -> Self {
        Self::new(Work::default())
    }
}

impl Authoring {
    /// Authoring on some work (e.g. a drawing loaded in a test).
    pub fn new(work: Work) -> Self {
        let mut a = Self {
            work,
            undo: Vec::new(),
            redo: Vec::new(),
            result: Err(String::new()),
            problems: Vec::new(),
            compiles: false,
            written: None,
            message: None,
            status: None,
        };
        a.recompute();
        a
    }

    pub fn work(&self) -> &Work {
        &self.work
    }

    pub fn design(&self) -> Option<&Design> {
        self.result.as_ref().ok().map(|c| &c.design)
    }

    /// The grammar text of the current design.
    pub fn text(&self) -> Option<&str> {
        self.result.as_ref().ok().map(|c| c.text.as_str())
    }

    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// Where the text would be compiled from: the file it was written to, if it is unchanged.
    pub fn source_name(&self) -> String {
        match (&self.written, self.text()) {
            (Some((p, t)), Some(text)) if t == text => p.display().to_string(),
            _ => UNSAVED_NAME.to_string(),
        }
    }

    fn recompute(&mut self) {
        self.result = compute(&self.work);
        match &self.result {
            Ok(c) => match compile::compile(&c.text, &self.source_name(), &[]) {
                Ok(ok) => {
                    self.problems = ok.warnings;
                    self.compiles = true;
                }
                Err(problems) => {
                    self.problems = problems;
                    self.compiles = false;
                }
            },
            Err(_) => {
                self.problems.clear();
                self.compiles = false;
            }
        }
    }

    /// Says something about the last command: in the panel and, through the app, the status
    /// bar.
    fn say(&mut self, m: String) {
        self.status = Some(m.clone());
        self.message = Some(m);
    }

    /// What the last commands had to say for the status bar, once (the app takes it after
    /// applying each command).
    pub fn take_status(&mut self) -> Option<String> {
        self.status.take()
    }

    /// Replaces the work as one undoable step, if the new work has a design (or the old one
    /// had none either); otherwise keeps it and says why.
    fn change(&mut self, new: Work, what: &str) {
        if new == self.work {
            return;
        }
        let result = compute(&new);
        if let Err(e) = &result
            && self.result.is_ok()
        {
            self.say(format!("cannot {what}: {e}"));
            return;
        }
        let old = std::mem::replace(&mut self.work, new);
        self.undo.push(old);
        self.redo.clear();
        self.recompute();
        self.message = None;
    }

    /// Applies one command.
    pub fn apply(&mut self, command: AuthorCommand) {
        let mut w = self.work.clone();
        match command {
            AuthorCommand::Undo => {
                if let Some(prev) = self.undo.pop() {
                    self.redo.push(std::mem::replace(&mut self.work, prev));
                    self.recompute();
                }
            }
            AuthorCommand::Redo => {
                if let Some(next) = self.redo.pop() {
                    self.undo.push(std::mem::replace(&mut self.work, next));
                    self.recompute();
                }
            }
            AuthorCommand::SetDrawing(d) => {
                w = Work {
                    drawing: d,
                    tolerance: w.tolerance,
                    ..Work::default()
                };
                // A drawing that does not give a design still replaces the old one.
                let old = std::mem::replace(&mut self.work, w);
                self.undo.push(old);
                self.redo.clear();
                self.recompute();
            }
            AuthorCommand::AddPolyline(p) => {
                let n = if p.closed { 3 } else { 2 };
                if p.points.len() < n || p.points.iter().any(|q| !q.is_finite()) {
                    self.say(format!("a stroke needs at least {n} points"));
                    return;
                }
                self.status = Some(format!(
                    "added a{} stroke of {} points",
                    if p.closed { " closed" } else { "n open" },
                    p.points.len()
                ));
                w.drawing.polylines.push(p);
                let old = std::mem::replace(&mut self.work, w);
                self.undo.push(old);
                self.redo.clear();
                self.recompute();
            }
            AuthorCommand::Cut { point } => {
                w.cuts.push(point);
                self.change(w, "cut there");
                if self.message.is_none() {
                    self.status = Some(format!("cut at {}", coords(point)));
                }
            }
            AuthorCommand::RemoveCut { index } => {
                if index < w.cuts.len() {
                    let at = w.cuts.remove(index);
                    self.change(w, "remove that cut");
                    if self.message.is_none() {
                        self.status = Some(format!("removed the cut at {}", coords(at)));
                    }
                }
            }
            AuthorCommand::Report(m) => self.say(m),
            AuthorCommand::SetTolerance(t) => {
                if !(t.is_finite() && t > 0.0) {
                    self.say("the tolerance must be a positive number".into());
                    return;
                }
                w.tolerance = t;
                self.change(w, "use that tolerance");
            }
            AuthorCommand::Clear => {
                let old = std::mem::replace(
                    &mut self.work,
                    Work {
                        tolerance: w.tolerance,
                        ..Work::default()
                    },
                );
                if old != self.work {
                    self.undo.push(old);
                    self.redo.clear();
                }
                self.recompute();
            }
            // The rule declarations: names, types, stretch, variants, merges, states.
            declaration => self.declare(w, declaration),
        }
    }

    /// Applies a rule declaration (every command that changes names, site types, the
    /// stretch rule, variants, merges or rest states) to the work `w`.
    fn declare(&mut self, mut w: Work, command: AuthorCommand) {
        match command {
            AuthorCommand::RenamePiece { from, to } => self.rename_piece(w, &from, to.trim()),
            AuthorCommand::RenameSiteType { from, to } => {
                let to = to.trim().to_string();
                if let Err(e) = check_name(&to) {
                    self.say(e);
                    return;
                }
                let shown = self
                    .result
                    .as_ref()
                    .map(|c| c.design.site_types.clone())
                    .unwrap_or_default();
                let current = w.site_names.get(&from).unwrap_or(&from);
                if *current != to && shown.contains(&to) {
                    self.say(format!("there is already a site type `{to}`"));
                    return;
                }
                if to == from {
                    w.site_names.remove(&from);
                } else {
                    w.site_names.insert(from, to);
                }
                self.change(w, "rename");
            }
            AuthorCommand::SetSiteType { site, site_type } => {
                let site_type = site_type.trim().to_string();
                if let Err(e) = check_name(&site_type) {
                    self.say(e);
                    return;
                }
                let Some(design) = self.design() else {
                    return;
                };
                let Some(start) = find_site(design, &site) else {
                    self.say(format!("there is no site {site}"));
                    return;
                };
                let along: Vec<SiteName> = docked_sites(design, start)
                    .into_iter()
                    .map(|(p, s)| SiteName {
                        piece: design.pieces[p].name.clone(),
                        site: design.pieces[p].sites[s].name.clone(),
                    })
                    .collect();
                for s in &along {
                    w.site_types.insert(s.clone(), site_type.clone());
                }
                let changed = w != self.work;
                self.change(w, "set that site type");
                if changed && along.len() > 1 && self.message.is_none() {
                    let others: Vec<String> = along[1..].iter().map(|s| s.to_string()).collect();
                    self.say(format!(
                        "{} docks with {}: they get the type `{site_type}` too",
                        along[0],
                        others.join(", ")
                    ));
                }
            }
            other => self.declare_rule(w, other),
        }
    }

    /// Applies a rule declaration proper: the stretch rule, its variants, merges and rest
    /// states.
    fn declare_rule(&mut self, mut w: Work, command: AuthorCommand) {
        match command {
            AuthorCommand::SetStretch(choice) => {
                if let (Some(c), Ok(computed)) = (&choice, &self.result) {
                    // Check it here so a wrong pick is refused instead of becoming a note.
                    let mut d = computed.design.clone();
                    if let Err(e) = d.make_stretchable(c) {
                        self.say(e.to_string());
                        return;
                    }
                }
                w.stretch = choice;
                self.change(w, "make that stretchable");
            }
            AuthorCommand::AddMerge(m) => {
                let names = self.design().map(site_names).unwrap_or_default();
                let sites = [Some(&m.mover), Some(&m.target), m.junction.as_ref()];
                if let Some(missing) = sites.into_iter().flatten().find(|s| !names.contains(s)) {
                    self.say(format!("there is no site {missing}"));
                    return;
                }
                if m.mover == m.target {
                    self.say("a site cannot merge onto itself".into());
                    return;
                }
                if w.merges.contains(&m) {
                    return;
                }
                w.merges.push(m);
                self.change(w, "add that merge rule");
            }
            AuthorCommand::RemoveMerge { index } if index < w.merges.len() => {
                w.merges.remove(index);
                self.change(w, "remove that merge rule");
            }
            AuthorCommand::SetVariants(mut variants) => {
                if variants.is_empty() {
                    w.variants.clear();
                    self.change(w, "remove the variants");
                    return;
                }
                let Some(design) = self.design() else {
                    return;
                };
                let Some(sp) = design.pieces.iter().position(|p| p.stretch.is_some()) else {
                    self.say("variants need a stretchable piece: declare one first".into());
                    return;
                };
                for (k, v) in variants.iter().enumerate() {
                    if !(v.frequency.is_finite() && v.frequency > 0.0) {
                        self.say(format!(
                            "the frequency of `{}` must be a positive number",
                            v.piece
                        ));
                        return;
                    }
                    if variants[..k].iter().any(|x| x.piece == v.piece) {
                        self.say(format!("`{}` is listed twice", v.piece));
                        return;
                    }
                    let problem = match design.pieces.iter().position(|p| p.name == v.piece) {
                        None => Some(format!("there is no piece `{}`", v.piece)),
                        Some(vi) => variant_map(design, sp, vi).err(),
                    };
                    if let Some(p) = problem {
                        self.say(format!("`{}` cannot be a variant: {p}", v.piece));
                        return;
                    }
                }
                let sum: f64 = variants.iter().map(|v| v.frequency).sum();
                for v in &mut variants {
                    v.frequency /= sum;
                }
                w.variants = variants;
                self.change(w, "set the variants");
            }
            AuthorCommand::AddState(st) => {
                if let Err(e) = self.check_state(&st) {
                    self.say(e);
                    return;
                }
                w.states.push(st);
                self.change(w, "add that rest state");
            }
            AuthorCommand::RemoveState { index } if index < w.states.len() => {
                w.states.remove(index);
                self.change(w, "remove that rest state");
            }
            // Undo, redo and the drawing's commands are `apply`'s.
            _ => {}
        }
    }

    /// Renames a piece (`from` is its generated name) if `to` is a name no other piece has;
    /// the declarations that name the piece follow it.
    fn rename_piece(&mut self, mut w: Work, from: &str, to: &str) {
        let Ok(c) = &self.result else {
            return;
        };
        let Some(index) = c.generated_piece_names.iter().position(|g| g == from) else {
            self.say(format!("there is no piece `{from}`"));
            return;
        };
        let old = c.design.pieces[index].name.clone();
        if let Err(e) = check_name(to) {
            self.say(format!("cannot rename `{old}`: {e}"));
            return;
        }
        if to == "base" {
            self.say(format!(
                "cannot rename `{old}`: `base` is the name of the drawn rest state"
            ));
            return;
        }
        if c.design
            .pieces
            .iter()
            .any(|p| p.name == to && p.name != old)
        {
            self.say(format!(
                "cannot rename `{old}`: there is already a piece `{to}`"
            ));
            return;
        }
        if to == from {
            w.piece_names.remove(from);
        } else {
            w.piece_names.insert(from.to_string(), to.to_string());
        }
        let follow = |n: &mut String| {
            if *n == old {
                *n = to.to_string();
            }
        };
        for m in &mut w.merges {
            follow(&mut m.mover.piece);
            follow(&mut m.target.piece);
            if let Some(j) = &mut m.junction {
                follow(&mut j.piece);
            }
        }
        w.site_types = std::mem::take(&mut w.site_types)
            .into_iter()
            .map(|(mut k, v)| {
                follow(&mut k.piece);
                (k, v)
            })
            .collect();
        for v in &mut w.variants {
            follow(&mut v.piece);
        }
        for st in &mut w.states {
            follow(&mut st.piece);
        }
        self.change(w, "rename that piece");
        if self.message.is_none() && old != to {
            self.status = Some(format!("renamed piece `{old}` to `{to}`"));
        }
    }

    /// Why a posed state cannot be added to its piece.
    fn check_state(&self, st: &StateChoice) -> Result<(), String> {
        check_name(&st.name)?;
        if st.name == "base" {
            return Err("`base` is the name of the drawn rest state: pick another".into());
        }
        let design = self.design().ok_or("there is no design yet")?;
        let piece = design
            .pieces
            .iter()
            .find(|p| p.name == st.piece)
            .ok_or_else(|| format!("there is no piece `{}`", st.piece))?;
        if st.positions.len() != piece.positions.len() {
            return Err(format!(
                "`{}` has {} vertices, the state gives {}",
                st.piece,
                piece.positions.len(),
                st.positions.len()
            ));
        }
        if st.positions == piece.positions {
            return Err("the posed copy is the base state: move a vertex first".into());
        }
        if st.positions.iter().any(|p| !p.is_finite()) {
            return Err("a vertex position is not a finite number".into());
        }
        for (i, a) in st.positions.iter().enumerate() {
            if st.positions[..i]
                .iter()
                .any(|b| (*a - *b).length() < self.work.tolerance)
            {
                return Err(format!(
                    "two vertices of the state are at {}: move one",
                    coords(*a)
                ));
            }
        }
        if self
            .work
            .states
            .iter()
            .any(|s| s.piece == st.piece && s.name == st.name)
        {
            return Err(format!("`{}` already has a state `{}`", st.piece, st.name));
        }
        Ok(())
    }

    /// Reads an SVG drawing (`scale` metres per SVG unit) and makes it the drawing.
    pub fn import_svg(&mut self, path: &Path, scale: f64) -> Result<(), String> {
        if !(scale.is_finite() && scale > 0.0) {
            return Err(format!(
                "the scale must be a positive number, found {scale}"
            ));
        }
        let text = clay_dsl::read_input_string(path, clay_dsl::MAX_SOURCE_BYTES)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        let drawing = clay::authoring::drawing_from_svg(&text, scale)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        self.apply(AuthorCommand::SetDrawing(drawing));
        Ok(())
    }

    /// Writes the grammar text atomically, then compiles it under that path so the
    /// diagnostics name the file.
    pub fn write(&mut self, path: &Path) -> Result<(), String> {
        let text = match &self.result {
            Ok(c) => c.text.clone(),
            Err(e) => return Err(format!("no grammar to write: {e}")),
        };
        clay::write_atomic(path, text.as_bytes())
            .map_err(|e| format!("{}: {e}", path.display()))?;
        self.written = Some((path.to_path_buf(), text));
        self.recompute();
        Ok(())
    }
}

/// A coordinate in metres for messages and labels: at most four decimals (a tenth of a
/// millimetre), no trailing zeros, so `3.4000000000000004` reads `3.4`.
pub fn short(x: f64) -> String {
    let s = format!("{x:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

/// A point in metres as `(x, y)`, each coordinate [`short`].
pub fn coords(p: DVec2) -> String {
    format!("({}, {})", short(p.x), short(p.y))
}
