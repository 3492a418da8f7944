//! The clay grammar language: pest grammar, typed syntax tree with spans, compiler to rest-state
//! sets, diagnostics and the formatter.
//!
//! Data flows one way: text -> [`syntax`] tree ([`parse`]) -> [`compiled::CompiledGrammar`]
//! ([`compile`]). The public surface is this page: [`compiled`] (the serde contract every
//! other crate reads) and [`syntax`] (the tree, which authoring builds) are modules; the phases
//! are private and their entry points re-exported here, so every name has one path.

#![deny(clippy::print_stdout, clippy::print_stderr)]

pub mod compiled;
pub mod syntax;

mod compile;
mod diagnostic;
mod format;
mod parse;
mod suggest;

pub use compile::{Compiled, MAX_COORDINATE, codes, compile, compile_bytes};
pub use compiled::{AssemblyData, CompiledGrammar};
pub use diagnostic::{
    Diagnostic, Diagnostics, JsonDiagnostic, JsonLabel, JsonPos, Label, LineIndex, Severity,
    emit_to_stderr, line_col, render, to_json,
};
pub use format::{comment_spans, format, format_number, print_file};
pub use parse::parse;
