//! Clay: live assemblies, the mutable elastic solver, rules and rendering.

// The library returns data; printing is the binaries' job (diagnostics at the CLI's edge).
#![deny(clippy::print_stdout, clippy::print_stderr)]

pub mod assembly;
pub mod authoring;
pub mod export;
pub mod files;
pub mod fit;
#[cfg(feature = "testing")]
pub mod gallery;
pub mod plane;
pub mod render;
pub mod rules;
pub mod script;
pub mod session;
pub mod solver;
pub mod summary;
#[cfg(any(test, feature = "testing"))]
pub mod synthetic;
