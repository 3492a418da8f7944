//! Clay: live assemblies, the mutable elastic solver, rules and rendering.
pub mod assembly;
pub mod solver;
pub mod render;
