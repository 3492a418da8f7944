//! The Clay editor: sculpt a grammar's model live with the mouse. The state (sculpt, sessions,
//! camera) is separate from the drawing so it is tested without a window.
//!
//! Laid out by mode: `sculpt` (sculpting mode: the model and its canvas and panels) and
//! `author` (authoring mode: the work and its canvas and panel); `app` is the window that holds
//! both and switches between them. The rest is shared by both modes: `action` (the file
//! actions), `camera`, `compile` and `diagnostics` (the compiler's problems and their panel),
//! `files`, `guard`, `help`, `recovery`, `session` and `watch`.
pub mod action;
pub mod app;
pub mod author;
pub mod camera;
pub mod compile;
pub mod diagnostics;
pub mod files;
pub mod guard;
pub mod help;
pub mod prose;
pub mod recovery;
pub mod sculpt;
pub mod session;
pub mod watch;

pub use app::EditorApp;
