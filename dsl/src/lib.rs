//! The clay grammar language: pest grammar, typed syntax tree with spans, compiler to rest-state
//! sets, and diagnostics.
//!
//! Data flows one way: text -> [`syntax`] tree -> [`compiled::CompiledGrammar`].

pub mod compiled;

pub use compiled::{AssemblyData, CompiledGrammar};
pub mod diagnostic;
pub mod parse;
pub mod syntax;
