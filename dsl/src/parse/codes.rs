//! Stable diagnostic codes emitted by the parser.

/// The text does not follow the grammar.
pub const SYNTAX: &str = "E001";
/// Brackets or block comments nested deeper than 256 (the parser's `MAX_NESTING`).
pub const TOO_DEEP: &str = "E002";
/// A number literal too large for a 64-bit float.
pub const NON_FINITE: &str = "E012";
