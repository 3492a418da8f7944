//! The stable diagnostic codes of the compiler, one constant per kind of problem. The table in
//! docs/language.md lists them; codes are never reused for a different meaning.

pub use crate::input::NOT_UTF8;
pub use crate::parse::codes::{NON_FINITE, SYNTAX, TOO_DEEP};

/// The file cannot be read at all (missing, not readable, a directory): `clayc` reports it;
/// docs/language.md describes it below the table, as no fixture can show it.
pub const UNREADABLE: &str = "E004";
/// A name declared twice in the same scope.
pub const DUPLICATE: &str = "E010";
/// A name that refers to nothing (piece, site type, site, vertex, instance, parameter).
pub const UNKNOWN: &str = "E011";
/// A parameter or number outside its allowed range.
pub const OUT_OF_RANGE: &str = "E013";
/// The model would have more instances than the limit.
pub const TOO_MANY: &str = "E014";
/// A chain element index that is missing or out of range.
pub const BAD_ELEMENT: &str = "E015";
/// An alternative rest state whose vertices differ from its piece's.
pub const STATE_VERTICES: &str = "E020";
/// An alternative rest state whose restated edges differ from its piece's.
pub const STATE_EDGES: &str = "E021";
/// An edge whose two ends are at the same place.
pub const ZERO_EDGE: &str = "E022";
/// Two vertices of a rest state at the same place.
pub const COINCIDENT: &str = "E023";
/// A site `out` direction of zero length.
pub const ZERO_OUT: &str = "E025";
/// Proxy geometry with too few points, or a piece with no vertices.
pub const DEGENERATE: &str = "E026";
/// Skinned geometry in a piece that has no axis.
pub const NO_AXIS: &str = "E027";
/// Two sites whose types may not dock.
pub const INCOMPATIBLE: &str = "E030";
/// Two docked sites with different vertex counts.
pub const SITE_COUNT: &str = "E031";
/// Docked vertices that do not meet after placement.
pub const NOT_COINCIDENT: &str = "E032";
/// An instance the compiler cannot place.
pub const UNPLACED: &str = "E033";
/// A site docked more than once.
pub const DOCKED_TWICE: &str = "E034";
/// A site docked to itself.
pub const SELF_DOCK: &str = "E035";
/// A stretch piece (or axis) without two opposite sites.
pub const NOT_OPPOSITE: &str = "E040";
/// A stretch variant whose vertices (names or places), edges or sites (names, types,
/// vertices, directions) differ from the rule's piece.
pub const VARIANT_SHAPE: &str = "E041";
/// Variant frequencies that do not sum to 1.
pub const FREQUENCIES: &str = "E042";
/// A merge junction (or cut target) that lacks sites it must take over.
pub const JUNCTION_SITES: &str = "E043";
/// A merge junction (or cut piece) whose shared sites do not sit where the piece it replaces
/// has them.
pub const NOT_IN_PLACE: &str = "E044";
/// A piece named by two stretch rules.
pub const TWO_STRETCH: &str = "E045";
/// A chain with no `along` whose piece has no stretch rule.
pub const CHAIN_SITES: &str = "E046";
/// A stretch piece or variant that declares alternative rest states, which could never become active.
pub const ELEMENT_STATES: &str = "E047";
/// A derived rest state (`bend`, `mirror`) in a piece without an axis.
pub const DERIVE_NO_AXIS: &str = "E055";
/// A `bend` so tight that it folds the piece onto itself.
pub const BEND_FOLDS: &str = "E056";
/// A `mirror` of the state itself or of a state declared after it.
pub const MIRROR_ORDER: &str = "E057";
/// A `mirror` of a state that lists positions, on a piece not symmetric about its axis.
pub const NOT_SYMMETRIC: &str = "E058";

/// A division whose divisor is zero.
pub const DIVISION_BY_ZERO: &str = "E050";
/// A built-in function called with the wrong number of arguments.
pub const BAD_CALL: &str = "E051";
/// A constant used above its `let`.
pub const USED_BEFORE_LET: &str = "E052";

/// An imported file that cannot be read (missing, a folder, not readable, not a regular file).
pub const IMPORT_UNREADABLE: &str = "E060";
/// A file that imports itself, directly or through other files.
pub const IMPORT_CYCLE: &str = "E061";
/// A piece that extends itself, directly or through other pieces.
pub const EXTENDS_CYCLE: &str = "E062";
/// Reuse beyond a limit: too many or too large imports, or an `extends` chain too deep or
/// copying too much.
pub const TOO_MUCH_REUSE: &str = "E063";
/// A `mesh` asset that does not exist.
pub const MESH_MISSING: &str = "E064";
/// A `mesh` asset (or a file it names) that exists but cannot be read (a folder, no
/// permission, not a regular file).
pub const MESH_UNREADABLE: &str = "E065";
/// A `mesh` asset that is not a mesh Clay reads: an unknown extension, or a file that is not
/// valid glTF 2.0 or OBJ, or has no triangles, or refers to data it does not contain, or
/// whose `.mtl` has a colour line without three numbers.
pub const MESH_MALFORMED: &str = "E066";
/// A `mesh` asset beyond a limit: its file size, its vertices or its triangles.
pub const MESH_TOO_LARGE: &str = "E067";

/// A parameter override (`CompileOptions::params`) naming no parameter of the grammar.
pub const UNKNOWN_PARAM: &str = "E070";
/// A parameter override outside the parameter's range, or not a finite number.
pub const PARAM_OUT_OF_RANGE: &str = "E071";
/// A parameter whose default or range uses another parameter.
pub const PARAM_NOT_FIXED: &str = "E072";
/// A parameter value of the wrong type: an unknown type name, a default or an override that
/// does not fit its type, a `bool` or `choice` used as a number, an `if` on no `bool`.
pub const PARAM_TYPE: &str = "E073";

/// A piece that nothing uses.
pub const UNUSED_PIECE: &str = "W001";
/// A rule that can never fire.
pub const DEAD_RULE: &str = "W002";
/// A repeated edge.
pub const REPEATED_EDGE: &str = "W003";
/// `rotate` on an instance placed through its dock, where it has no effect.
pub const IGNORED_ROTATE: &str = "W004";
/// An empty grammar, or one with no `model` block: nothing to sculpt.
pub const NO_MODEL: &str = "W005";
/// A merge rule with the mover and target of an earlier one: the earlier one always wins.
pub const SHADOWED_MERGE: &str = "W006";
/// A `let` constant or `param` parameter that nothing uses.
pub const UNUSED_CONSTANT: &str = "W007";
