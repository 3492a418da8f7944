//! Test helpers and the rules' internals that the integration tests drive one by one, behind
//! the feature `testing` (the crate's own unit tests see them too). Not part of the stable
//! surface: the editor, the CLI and the bindings use them only for benches and tests.

#[cfg(feature = "testing")]
pub mod gallery;

pub use crate::rules::{cut, merge, replace, stretch};
