//! The clay grammar language: pest grammar, typed syntax tree with spans, compiler to rest-state
//! sets, and diagnostics.
//!
//! Data flows one way: text -> [`syntax`] tree -> [`compiled::CompiledGrammar`].

pub mod compiled;

pub use compiled::{AssemblyData, CompiledGrammar};
pub mod compile;
pub mod diagnostic;
pub mod format;
pub mod parse;
mod suggest;
pub mod syntax;

pub use compile::{Compiled, compile, compile_bytes};
pub use diagnostic::{Diagnostic, Diagnostics, Severity, line_col, render, to_json};
