//! The Clay editor: sculpt a grammar's model live with the mouse. The state (sculpt, sessions,
//! camera) is separate from the drawing so it is tested without a window.
pub mod action;
pub mod app;
pub mod author;
pub mod author_canvas;
pub mod author_panel;
pub mod camera;
pub mod canvas;
pub mod compile;
pub mod files;
pub mod follow;
pub mod guard;
pub mod help;
pub mod iso;
pub mod overlay;
pub mod panels;
pub mod recovery;
pub mod sculpt;
pub mod session;
pub mod watch;

pub use app::EditorApp;
