//! Clay: live assemblies, the mutable elastic solver, rules and rendering.
pub mod assembly;
pub mod fit;
pub mod solver;
pub mod rules;
pub mod render;
pub mod synthetic;
pub mod script;
pub mod summary;
pub mod authoring;
