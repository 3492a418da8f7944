//! Authoring mode's state: the drawing, its cut points and the author's rule declarations
//! (site type names, the stretchable piece), the design recomputed from them through
//! `clay::authoring`, and the grammar text with its diagnostics. Every change is an
//! [`AuthorCommand`]; changes to the work are undoable as whole steps.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use clay::authoring::graph::{Graph, Region};
use clay::authoring::{self, Design, Drawing, Polyline, StretchChoice};
use glam::DVec2;

use crate::compile::{self, Problem};
use crate::session;

/// Name the authored grammar is compiled under before it has been written to a file.
pub const UNSAVED_NAME: &str = "authored.clay";

/// The author's work: everything undo and redo restore.
#[derive(Clone, Debug, PartialEq)]
pub struct Work {
    pub drawing: Drawing,
    /// Cut points (metres, y up), in the order they were made.
    pub cuts: Vec<DVec2>,
    /// Site type renames: generated name -> the author's name. Keyed by the generated name so
    /// a rename survives the design being recomputed after a new cut or stroke.
    pub site_names: BTreeMap<String, String>,
    pub stretch: Option<StretchChoice>,
    /// Merge rules, by piece and site names (the library's design has none: the editor adds
    /// them to the syntax tree before printing).
    pub merges: Vec<MergeChoice>,
    /// Points closer than this (metres) are one vertex; also the congruence tolerance.
    pub tolerance: f64,
}

impl Default for Work {
    fn default() -> Self {
        Self {
            drawing: Drawing::default(),
            cuts: Vec::new(),
            site_names: BTreeMap::new(),
            stretch: None,
            merges: Vec::new(),
            tolerance: 1e-3,
        }
    }
}

/// A site of a piece, by names: `piece.site`.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct SiteName {
    pub piece: String,
    pub site: String,
}

impl std::fmt::Display for SiteName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}.{}", self.piece, self.site)
    }
}

/// `merge mover onto target [into junction]` (docs/language.md).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MergeChoice {
    pub mover: SiteName,
    pub target: SiteName,
    pub junction: Option<SiteName>,
}

impl std::fmt::Display for MergeChoice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "merge {} onto {}", self.mover, self.target)?;
        if let Some(j) = &self.junction {
            write!(f, " into {j}")?;
        }
        Ok(())
    }
}

/// Every `piece.site` of a design.
pub fn site_names(design: &Design) -> Vec<SiteName> {
    design
        .pieces
        .iter()
        .flat_map(|p| {
            p.sites.iter().map(|s| SiteName {
                piece: p.name.clone(),
                site: s.name.clone(),
            })
        })
        .collect()
}

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
    /// Make a piece stretchable (or none).
    SetStretch(Option<StretchChoice>),
    /// Declare a merge rule (refused unless its sites exist).
    AddMerge(MergeChoice),
    RemoveMerge {
        index: usize,
    },
    SetTolerance(f64),
    /// Start over with an empty drawing.
    Clear,
    Undo,
    Redo,
}

/// The design computed from the work, with the graph it was computed on (for drawing).
#[derive(Clone, Debug)]
pub struct Computed {
    pub graph: Graph,
    pub regions: Vec<Region>,
    pub design: Design,
    /// Generated site type names, parallel to `design.site_types` (which holds the shown ones).
    pub generated_site_types: Vec<String>,
    pub text: String,
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
}

impl Default for Authoring {
    fn default() -> Self {
        Self::new(Work::default())
    }
}

fn valid_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// Runs the library's steps on the work. A stretch choice that no longer fits the design (the
/// drawing or cuts changed under it) is dropped with a note rather than losing the design.
pub fn compute(work: &Work) -> Result<Computed, String> {
    if work.drawing.polylines.is_empty() {
        return Err("nothing drawn yet: import an SVG or draw on the canvas".into());
    }
    let tol = work.tolerance;
    let mut graph = Graph::build(&work.drawing, tol).map_err(|e| e.to_string())?;
    let sections = work
        .cuts
        .iter()
        .map(|&p| graph.cut(p, tol))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| e.to_string())?;
    let (regions, contacts) = if sections.is_empty() {
        graph.loop_regions()
    } else {
        graph.regions(&sections)
    }
    .map_err(|e| e.to_string())?;
    let mut design = authoring::pieces::find_pieces(&graph, &regions, &contacts, tol)
        .map_err(|e| e.to_string())?;
    if let Some(choice) = &work.stretch
        && let Err(e) = design.make_stretchable(choice)
    {
        design
            .notes
            .push(format!("the stretch declaration no longer applies: {e}"));
    }
    let generated_site_types = design.site_types.clone();
    for t in &mut design.site_types {
        if let Some(n) = work.site_names.get(t) {
            t.clone_from(n);
        }
    }
    let mut tree = design.to_syntax();
    let names = site_names(&design);
    let at = tree
        .items
        .iter()
        .position(|i| matches!(i, clay_dsl::syntax::Item::Model(_)))
        .unwrap_or(tree.items.len());
    let mut merges = Vec::new();
    for m in &work.merges {
        let sites = std::iter::once(&m.mover)
            .chain(Some(&m.target))
            .chain(m.junction.as_ref());
        match sites.clone().find(|s| !names.contains(s)) {
            Some(missing) => design.notes.push(format!(
                "`{m}` no longer applies: there is no site {missing}"
            )),
            None => merges.push(clay_dsl::syntax::Item::Merge(merge_decl(m))),
        }
    }
    tree.items.splice(at..at, merges);
    let text = clay_dsl::format::print_file(&tree);
    Ok(Computed {
        graph,
        regions,
        design,
        generated_site_types,
        text,
    })
}

fn site_path(s: &SiteName) -> clay_dsl::syntax::SitePath {
    use clay_dsl::syntax::{Ident, SitePath, Span};
    let ident = |name: &str| Ident {
        name: name.to_string(),
        span: Span::default(),
    };
    SitePath {
        piece: ident(&s.piece),
        site: ident(&s.site),
        span: Span::default(),
    }
}

fn merge_decl(m: &MergeChoice) -> clay_dsl::syntax::MergeDecl {
    clay_dsl::syntax::MergeDecl {
        mover: site_path(&m.mover),
        target: site_path(&m.target),
        junction: m.junction.as_ref().map(site_path),
        within: None,
        span: clay_dsl::syntax::Span::default(),
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
            Ok(c) => match compile::compile(&c.text, &self.source_name()) {
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
            self.message = Some(format!("cannot {what}: {e}"));
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
                    self.message = Some(format!("a stroke needs at least {n} points"));
                    return;
                }
                w.drawing.polylines.push(p);
                let old = std::mem::replace(&mut self.work, w);
                self.undo.push(old);
                self.redo.clear();
                self.recompute();
            }
            AuthorCommand::Cut { point } => {
                w.cuts.push(point);
                self.change(w, "cut there");
            }
            AuthorCommand::RemoveCut { index } => {
                if index < w.cuts.len() {
                    w.cuts.remove(index);
                    self.change(w, "remove that cut");
                }
            }
            AuthorCommand::RenameSiteType { from, to } => {
                let to = to.trim().to_string();
                if !valid_identifier(&to) {
                    self.message = Some(format!(
                        "`{to}` is not a name: use letters, digits and _, not starting with a digit"
                    ));
                    return;
                }
                let shown = self
                    .result
                    .as_ref()
                    .map(|c| c.design.site_types.clone())
                    .unwrap_or_default();
                let current = w.site_names.get(&from).unwrap_or(&from);
                if *current != to && shown.contains(&to) {
                    self.message = Some(format!("there is already a site type `{to}`"));
                    return;
                }
                if to == from {
                    w.site_names.remove(&from);
                } else {
                    w.site_names.insert(from, to);
                }
                self.change(w, "rename");
            }
            AuthorCommand::SetStretch(choice) => {
                if let (Some(c), Ok(computed)) = (&choice, &self.result) {
                    // Check it here so a wrong pick is refused instead of becoming a note.
                    let mut d = computed.design.clone();
                    if let Err(e) = d.make_stretchable(c) {
                        self.message = Some(e.to_string());
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
                    self.message = Some(format!("there is no site {missing}"));
                    return;
                }
                if m.mover == m.target {
                    self.message = Some("a site cannot merge onto itself".into());
                    return;
                }
                if w.merges.contains(&m) {
                    return;
                }
                w.merges.push(m);
                self.change(w, "add that merge rule");
            }
            AuthorCommand::RemoveMerge { index } => {
                if index < w.merges.len() {
                    w.merges.remove(index);
                    self.change(w, "remove that merge rule");
                }
            }
            AuthorCommand::SetTolerance(t) => {
                if !(t.is_finite() && t > 0.0) {
                    self.message = Some("the tolerance must be a positive number".into());
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
        }
    }

    /// Reads an SVG drawing (`scale` metres per SVG unit) and makes it the drawing.
    pub fn import_svg(&mut self, path: &Path, scale: f64) -> Result<(), String> {
        if !(scale.is_finite() && scale > 0.0) {
            return Err(format!(
                "the scale must be a positive number, found {scale}"
            ));
        }
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let drawing = authoring::svg::drawing_from_svg(&text, scale)
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
        session::write_atomic(path, text.as_bytes())
            .map_err(|e| format!("{}: {e}", path.display()))?;
        self.written = Some((path.to_path_buf(), text));
        self.recompute();
        Ok(())
    }
}
