//! The analysis of one text as data (`Analysis`: its line index, tree, symbols, imports and
//! diagnostics) and the language's keywords: what every query file reads, so they import this
//! file and not `mod.rs`, where the queries' entry points (`impl Analysis`) live.

use std::collections::HashMap;

use super::imports::Imported;
use super::symbols::Symbols;
use crate::diagnostic::Diagnostics;
use crate::line_index::LineIndex;
use crate::syntax::File;

/// Keywords of the language (contextual: a name may spell one). A rename to one is refused.
pub const KEYWORDS: &[&str] = &[
    "let", "solver", "site", "type", "docks", "piece", "vertex", "edges", "out", "axis", "polygon",
    "polyline", "rigid", "skinned", "fill", "width", "hole", "state", "stretch", "from", "to",
    "min", "max", "variants", "merge", "onto", "into", "within", "cut", "model", "chain", "x",
    "along", "at", "rotate", "dock", "last", "import", "extends", "bend", "mirror", "extrude",
    "above", "mesh", "param", "in", "if", "else", "choice", "true", "false",
];

/// One text, analysed.
#[derive(Clone, Debug)]
pub struct Analysis {
    pub(super) index: LineIndex,
    /// The analysed file's path, normalised as import paths are.
    pub(super) path: String,
    pub(super) imported: Imported,
    pub(super) tree: Option<File>,
    /// The text up to here is described by `tree` (the whole text when it parses).
    pub(super) parsed_to: usize,
    pub(super) symbols: Symbols,
    pub(super) diagnostics: Diagnostics,
    /// Folded values of the constants (for hovers).
    pub(super) values: HashMap<String, f64>,
}
