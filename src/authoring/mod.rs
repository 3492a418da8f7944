//! Authoring (issue 7): turn a drawing into a readable `.clay` grammar. The steps are plain
//! functions on plain data, so the CLI (`clayc author`) and the editor's authoring mode share
//! them:
//!
//! 1. [`drawing_from_svg`] (or a [`Drawing`] built in code): polylines in metres, y up;
//! 2. [`Graph::build`]: vertices snapped within a tolerance, edges, T-junctions split;
//! 3. [`Graph::cut`] at each cut point: the cut section's vertices are duplicated, one copy
//!    per side, and the pair becomes a contact (two docking sites);
//! 4. [`Graph::regions`]: the regions between cuts (or, with no cut, every closed path)
//!    and the [`Contact`]s where regions touch; an outline that crosses or touches
//!    itself is an error naming the path and the place, a closed path with no area and a copy
//!    drawn on top of another are left out with a note;
//! 5. [`find_pieces`]: regions equal up to a rigid motion become one piece with several
//!    instances; contacts become typed docking sites, each docked once, and docked only where
//!    docking keeps the instances where they are drawn;
//! 6. [`Design::fit_docks`]: the model placed as the compiler places it, and a dock whose
//!    vertices would not meet left out with a note;
//! 7. [`Design::to_syntax`]: the grammar as a syntax tree, printed by
//!    [`clay_dsl::print_file`].
//!
//! [`author`] runs them all; the grammar they write checks clean (issue 37), and
//! [`check_authored`] is `clayc author`'s last check before writing one.

mod drawing;
pub(crate) mod graph;
mod grid;
pub(crate) mod pieces;
mod placement;
pub(crate) mod svg;
pub(crate) mod work;
mod write;

use glam::DVec2;

// The authoring surface: one public path per name, `clay::authoring::X`.
pub use drawing::{AuthorError, Drawing, Polyline};
pub use graph::{Contact, CutSection, Graph, Loop, MIN_TOLERANCE, Region, Split};
pub use pieces::{
    Design, DockDesign, InstanceDesign, PieceDesign, SiteDesign, StretchChoice, find_pieces,
};
pub use svg::{drawing_from_svg, line_of_id};
pub use work::{
    Computed, MergeChoice, SiteName, StateChoice, VariantChoice, Work, check_name, compute,
    docked_sites, find_site, site_names, variant_map,
};

/// Everything authoring needs besides the drawing.
#[derive(Clone, Debug, PartialEq)]
pub struct AuthorOptions {
    /// Points closer than this (metres) are one vertex; a vertex this close to an edge splits it.
    pub snap: f64,
    /// Regions whose vertices match within this distance (metres) after a rigid motion are
    /// instances of one piece.
    pub congruence: f64,
    /// Cut points (metres, y up).
    pub cuts: Vec<DVec2>,
    /// Make a piece stretchable.
    pub stretch: Option<StretchChoice>,
    /// A comment line for the top of the file (without `//`), e.g. where the drawing came from.
    pub header: Option<String>,
}

impl Default for AuthorOptions {
    fn default() -> Self {
        Self {
            snap: 1e-3,
            congruence: 1e-3,
            cuts: Vec::new(),
            stretch: None,
            header: None,
        }
    }
}

/// The result of [`author`]: the design (pieces, instances, docks) and the grammar text.
#[derive(Clone, Debug)]
pub struct Authored {
    pub design: Design,
    pub text: String,
}

/// Runs every authoring step on a drawing.
pub fn author(drawing: &Drawing, options: &AuthorOptions) -> Result<Authored, AuthorError> {
    for (name, v) in [
        ("snap tolerance", options.snap),
        ("congruence tolerance", options.congruence),
    ] {
        graph::check_tolerance(name, v)?;
    }
    let mut graph = Graph::build(drawing, options.snap)?;
    let cut_contacts = options
        .cuts
        .iter()
        .map(|&p| graph.cut(p, options.snap))
        .collect::<Result<Vec<_>, _>>()?;
    let split = if cut_contacts.is_empty() {
        graph.loop_regions()?
    } else {
        graph.regions(&cut_contacts)?
    };
    let mut design =
        pieces::find_pieces(&graph, &split.regions, &split.contacts, options.congruence)?;
    design.notes.splice(0..0, split.notes);
    if let Some(choice) = &options.stretch {
        design.make_stretchable(choice)?;
    }
    design.fit_docks();
    let tree = design.to_syntax();
    let mut text = String::new();
    if let Some(h) = &options.header {
        for line in h.lines() {
            text += &format!("// {line}\n");
        }
    }
    text += &clay_dsl::print_file(&tree);
    Ok(Authored { design, text })
}

/// The last line of defence before an authored grammar is written: compiles `text` and
/// refuses it if the compiler finds an error. Every cause of such an error found so far is
/// fixed where the grammar is made (issue 37); this stops one not yet found from reaching a
/// file as a grammar that fails `clayc check`. The message lists the first few diagnostics
/// (code, line, message) and says that this is authoring's fault, not the drawing's.
pub fn check_authored(text: &str, path: &str) -> Result<(), AuthorError> {
    const SHOWN: usize = 5;
    let Err(diagnostics) = clay_dsl::compile(text, path, &clay_dsl::CompileOptions::default())
    else {
        return Ok(());
    };
    let errors: Vec<&clay_dsl::Diagnostic> = diagnostics
        .iter()
        .filter(|d| d.severity == clay_dsl::Severity::Error)
        .collect();
    let mut message = format!(
        "the grammar authored from this drawing does not check ({} error(s)), so it is not written; this is a fault of `clayc author`, please report it with the drawing:",
        errors.len()
    );
    for d in errors.iter().take(SHOWN) {
        let at = diagnostics.sources.locate(text, path, d.primary.span);
        let (line, col) = clay_dsl::line_col(at.text, at.start);
        message += &format!("\n  {path}:{line}:{col}: error[{}]: {}", d.code, d.message);
    }
    if errors.len() > SHOWN {
        message += &format!("\n  and {} more", errors.len() - SHOWN);
    }
    Err(AuthorError(message))
}
