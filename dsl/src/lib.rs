//! The clay grammar language: pest grammar, typed syntax tree with spans, compiler to rest-state
//! sets, diagnostics and the formatter.
//!
//! Data flows one way: text -> [`syntax`] tree ([`parse`]) -> [`compiled::CompiledGrammar`]
//! ([`compile`]). The public surface is this page: [`compiled`] (the serde contract every
//! other crate reads) and [`syntax`] (the tree, which authoring builds) are modules; the phases
//! are private and their entry points re-exported here, so every name has one path.

#![deny(clippy::print_stdout, clippy::print_stderr)]

// pest is used without its `std` feature, which would probe the native stack on every rule
// call (a sixth of `clayc check`'s time on a large grammar); the nesting scan in `parse/scan.rs`
// bounds the recursion before pest runs instead. Without `std`, `pest_derive` names `alloc`.
extern crate alloc;

pub mod analysis;
pub mod compiled;
pub mod settings;
pub mod syntax;

mod clip;
mod compile;
mod diagnostic;
mod format;
mod input;
mod line_index;
mod param;
mod parse;
mod source_map;
mod suggest;
mod validate;

pub use compile::{
    CompileOptions, Compiled, DOCK_TOLERANCE, FsLoader, Loader, MAX_COORDINATE, MAX_EXTENDS_DEPTH,
    MAX_IMPORT_BYTES, MAX_IMPORTS, MAX_INHERITED, MAX_INSTANCES, MAX_MESH_BYTES,
    MAX_MESH_TOTAL_BYTES, MAX_MESH_TRIANGLES, MAX_MESH_VERTICES, MAX_MODEL_INSTANCES, codes,
    compile, resolve_import,
};
pub use compiled::{AssemblyData, CompiledGrammar, MAX_MODEL_COORDINATE};
pub use diagnostic::{
    Diagnostic, Diagnostics, JsonDiagnostic, JsonLabel, JsonPos, Label, MAX_HUMAN_DIAGNOSTICS,
    Severity, omitted_line, render, to_json,
};
pub use format::{comment_spans, format, format_number, print_file};
pub use input::{
    MAX_DATA_BYTES, MAX_SOURCE_BYTES, decode_utf8, read_bounded, read_input, read_input_string,
    regular_file, utf8,
};
pub use line_index::{LineIndex, LinePos};
pub use parse::parse;
pub use source_map::{Located, SourceFile, SourceMap, line_col};
