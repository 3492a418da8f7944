//! Clay: live assemblies, the mutable elastic solver, rules and rendering.
//!
//! The surface is flat, as `typst-syntax`'s is: every module is private and each public name
//! has one path, `clay::Name`. Two families keep a namespace because their names read as
//! parts of a whole: [`authoring`] (an SVG drawing made into a grammar) and [`session_file`]
//! (the editor's saved session). The top level is what the shipped editor, `clayc` and the
//! Python module use, with the types their signatures name; test helpers, the rules' internals
//! and every other name only tests and benches use are in `clay::testing`, behind the feature
//! `testing`.
//!
//! A frame flows one way: an [`Assembly`] (a compiled grammar's live model) is sculpted by a
//! [`Session`] (gestures, the [`Solver`], the rules), drawn by [`render_png`] and its kin,
//! and exported by [`scene`] and [`write_export`] (or [`encode_export`]: glTF, GLB, OBJ).

// The library returns data; printing is the binaries' job (diagnostics at the CLI's edge).
#![deny(clippy::print_stdout, clippy::print_stderr)]
#![warn(unnameable_types)]

mod assembly;
pub mod authoring;
mod export;
mod figure;
mod files;
mod fit;
mod plane;
mod render;
mod rules;
mod script;
mod session;
mod solver;
mod summary;
pub mod synthetic;
#[cfg(any(test, feature = "testing"))]
pub mod testing;

pub use assembly::{Assembly, Compass, Handle, HandleKind};
pub use export::iso::iso_pixmap;
pub use export::{
    ChainPlace, ExportFileError, ExportFormat, ExportOptions, Node, Primitive, Scene, SharedMesh,
    chain_places, encode_export, material_name, mtl_path, scene, write_export,
};
pub use files::write_atomic;
pub use fit::carried_targets;
pub use plane::nearest_on_segment;
pub use render::{
    Canvas, MAX_SIDE, Mesh, Overlays, RenderError, RenderOptions, STRAIN_LEGEND, Solid,
    TessellationCache, View, WorldMesh, bounds, draw_overlays, part_at, pose_assembly_into,
    render_png, render_svg, sheet_png, sheet_svg, site_type_colour, tessellate_polygon,
};
pub use rules::{RuleEvent, RuleKind};
pub use script::{MAX_FRAMES, Motion, Script, ScriptError, Selector, Step};
pub use session::{
    Frame, Grab, PartReport, ReplayError, SETTING_NAMES, Session, configure, pin_at, pin_of,
    replay, toggle_pin,
};
pub use solver::{
    FrameReport, Judged, PhaseTimes, Solver, SolverConfig, SolverError, SolverKind, StateSwitch,
    Stop,
};
pub use summary::{FrameMs, Summary};

/// The session file the editor saves and `clayc run|render|export --session` replays: the
/// grammar's path, its parameters, the solver's settings, the pins and the log of gestures.
pub mod session_file {
    pub use crate::session::file::{
        LogEntry, Pin, SESSION_FORMAT, SESSION_VERSION, SavedSession, SessionError, Settings,
        parse, read, write,
    };
}
