//! The compiler's state: `Compiler` (the grammar so far, its diagnostics, where things were
//! declared) with the tables its passes keep (constants and parameters, inheritance, mesh
//! assets), and `fmt` for numbers in messages. Every pass file is an `impl Compiler` block
//! (or functions over it) that imports this file, and `mod.rs` (the entry points, the
//! passes' order and the compiler's methods every pass calls) imports them all, so no pass
//! imports `mod.rs`. The tables' methods stay in their passes' files.

use std::collections::{HashMap, HashSet};
use std::sync::Arc;

use super::mesh_files::AssetPart;
use crate::compiled::*;
use crate::diagnostic::Diagnostics;
use crate::syntax::{Ident, Span};

/// Where things were declared, for secondary labels.
#[derive(Clone, Debug, Default)]
pub(crate) struct PieceSpans {
    pub name: Span,
    pub vertices: Vec<Span>,
    pub sites: Vec<Span>,
    /// Where each of the piece's edges was written.
    pub edges: Vec<Span>,
    /// `state NAME` of each alternative rest state that was compiled, in order.
    pub states: Vec<Span>,
    /// False when the piece had errors: later passes skip geometric checks on it.
    pub sound: bool,
    /// Sites declared with errors (already reported): a later use of one is not "unknown".
    pub failed_sites: Vec<String>,
    /// A vertex, edge or site written in the piece was dropped for an error reported there (an
    /// unknown vertex or site type, say): the piece is not the shape its author wrote, so no
    /// comparison of its shape with another's (a variant's, E041; a restated edge list's,
    /// E021) is reported on top of that error.
    pub partial: bool,
    /// A piece extending one that failed (extends.rs): nothing is reported about it.
    pub poisoned: bool,
}

pub(crate) struct Compiler {
    pub path: String,
    pub diags: Diagnostics,
    pub solver: SolverParams,
    pub site_types: Vec<SiteType>,
    pub site_type_spans: Vec<Span>,
    /// Each site type's index by name: a lookup per site, not a scan of every type.
    pub site_type_index: HashMap<String, usize>,
    pub pieces: Vec<Piece>,
    pub piece_spans: Vec<PieceSpans>,
    pub piece_index: HashMap<String, usize>,
    pub stretch_rules: Vec<StretchRule>,
    pub stretch_spans: Vec<Span>,
    pub merge_rules: Vec<MergeRule>,
    pub merge_spans: Vec<Span>,
    pub cut_rules: Vec<CutRule>,
    pub cut_spans: Vec<Span>,
    /// The first merge rule of each (mover, target, `within` bits): finds a shadowed rule
    /// (W006) without a scan of the earlier rules.
    pub merge_first: HashMap<(SiteRef, SiteRef, Option<u64>), usize>,
    /// The cut rule of each junction site (`cut_rules` index).
    pub cut_index: HashMap<SiteRef, usize>,
    /// Pieces named by a stretch rule (written, even if the rule had errors).
    pub stretch_named: Vec<bool>,
    /// Set when a `dock` statement had errors: unplaced instances are then not reported.
    pub dock_failed: bool,
    /// Pieces declared with `extends` (extends.rs).
    pub inheritance: Inheritance,
    pub grammar: Option<CompiledGrammar>,
    /// The `let` constants, read by every expression.
    pub consts: Constants,
    /// The decoded `mesh` assets, by the global start of their path string (meshes.rs).
    pub meshes: Meshes,
    /// Known names the "did you mean" search may still compare against in this compilation
    /// ([`super::limits::MAX_SUGGESTION_WORK`] at the start).
    pub suggestion_budget: usize,
}

/// Formats a number for messages: short, no trailing zeros.
pub(crate) fn fmt(x: f64) -> String {
    let r = (x * 1e4).round() / 1e4;
    let r = if r == 0.0 { 0.0 } else { r };
    format!("{r}")
}

// The tables of constants.rs.

/// What declared a constant.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    Let,
    Param,
}

/// A parameter a value depends on: its name and the name in its `param`.
#[derive(Clone, Debug)]
pub(crate) struct Dependency {
    pub(super) param: String,
    pub(super) decl: Span,
}

/// One `let` or `param`.
#[derive(Clone, Debug)]
pub(crate) struct Constant {
    /// `None` when its expression failed (reported there): the constant is poisoned.
    pub(super) value: Option<f64>,
    /// The name in its declaration.
    pub(super) span: Span,
    /// Uses at or after this byte see it (the end of its declaration).
    pub(super) visible_from: usize,
    pub(super) used: bool,
    pub(super) kind: Kind,
    /// A parameter's type (`None` for a `let`).
    pub(super) ty: Option<ParamKind>,
    /// The parameter its value depends on (a parameter depends on itself), if any.
    pub(super) depends: Option<Dependency>,
}

/// A use of a parameter, directly or through a `let`, seen while folding.
#[derive(Clone, Debug)]
pub(crate) struct Touch {
    pub(super) dep: Dependency,
    /// The name used, where it was used.
    pub(super) used: Ident,
}

/// The `let` constants and `param` parameters of a file, the parameters' overrides, and which
/// expressions were already reported.
#[derive(Debug, Default)]
pub(crate) struct Constants {
    pub(super) table: HashMap<String, Constant>,
    /// Every `let` and `param` name with its span and kind, known before any is evaluated,
    /// so that a use before the declaration is told apart from an unknown name.
    pub(super) declared: HashMap<String, (Span, Kind)>,
    /// Spans of expressions already evaluated with an error: a pass that reads an expression
    /// again stays silent.
    pub(super) failed: HashSet<(usize, usize)>,
    /// Constants already reported as used before their `let`.
    pub(super) early: HashSet<String>,
    /// The values given for parameters, by name, in the order given (the last one counts).
    pub overrides: Vec<(String, ParamValue)>,
    /// The parameters that compiled, in declaration order, for the compiled grammar.
    pub params: Vec<Param>,
    /// Each `choice` parameter's strings as written, to check that they name pieces.
    pub(super) choices: Vec<(String, Vec<crate::syntax::StringLit>)>,
    /// The first parameter the expression being folded depends on.
    pub(super) touched: Option<Touch>,
}

// The tables of extends.rs.

/// What the compiler keeps about a piece that extends another.
#[derive(Clone, Debug)]
pub(crate) struct Child {
    /// The child's own declaration: its statements lie inside, the inherited ones outside.
    pub own: Span,
    pub base: String,
    /// 1 for a piece extending a plain piece, 2 for its child, ...
    pub depth: usize,
    /// The pieces it inherits from, nearest first, with their declarations.
    pub ancestors: Vec<(String, Span)>,
    /// The base is unknown, has errors, or is in a cycle: the child stays silent.
    pub poisoned: bool,
    /// Errors of the child itself were reported while resolving (the piece is not sound).
    pub failed: bool,
}

#[derive(Debug, Default)]
pub(crate) struct Inheritance {
    pub children: HashMap<String, Child>,
    /// Each child's diagnostics, held back until its base is known to be sound.
    pub(super) pending: Vec<(String, Diagnostics)>,
}

// The table of meshes.rs.

/// The decoded assets, by the global start of the `mesh` statement's path string (a piece
/// copied by `extends` shares its base's statements and so its asset).
#[derive(Clone, Debug, Default)]
pub(crate) struct Meshes {
    pub(super) by_path_start: HashMap<usize, Arc<[AssetPart]>>,
}
