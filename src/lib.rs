//! Clay: live assemblies, the mutable elastic solver, rules and rendering.
//!
//! The surface is flat, as `typst-syntax`'s is: every module is private and each public name
//! has one path, `clay::Name`. Two families keep a namespace because their names read as
//! parts of a whole: [`authoring`] (an SVG drawing made into a grammar) and [`session_file`]
//! (the editor's saved session). Test helpers and the rules' internals that tests reach for
//! are in `clay::testing`, behind the feature `testing`.
//!
//! A frame flows one way: an [`Assembly`] (a compiled grammar's live model) is sculpted by a
//! [`Session`] (gestures, the [`Solver`], the [`Rules`]), drawn by [`render_png`] and its
//! kin, and exported by [`scene`] with [`to_glb`], [`to_gltf`] and [`to_obj`].

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

pub use assembly::{Assembly, Compass, Handle, HandleId, HandleKind, HeldInstance};
pub use export::gltf::{to_glb, to_gltf};
pub use export::iso::iso_pixmap;
pub use export::obj::to_obj;
pub use export::{
    ChainPlace, ExportFileError, ExportFormat, ExportOptions, MAX_NAME_BYTES, MAX_THICKNESS, Node,
    Primitive, SHARE_TOLERANCE, SHARE_TOLERANCE_PER_METRE, Scene, SharedMesh, encode_export,
    mtl_path, scene, srgb_to_linear, write_export,
};
pub use files::write_atomic;
pub use plane::{nearest_on_segment, polygon_area};
pub use render::{
    BACKGROUND, CONTOUR_MIN_TRIANGLES, Canvas, MAX_SIDE, Mesh, Overlays, PixmapCanvas, RenderError,
    RenderOptions, STRAIN_FULL, STRAIN_LEGEND, SiteFrame, Skin, Solid, TessellationCache, View,
    WorldMesh, bounds, contours, draw_overlays, part_at, pose_assembly, pose_assembly_into,
    pose_instance, pose_piece, render_pixmap, render_png, render_svg, sheet_pixmap, sheet_png,
    sheet_svg, site_type_colour, strain_colour, tessellate_polygon, tessellate_polyline,
    tessellate_proxy,
};
pub use rules::stretch::MAX_GROWTH;
pub use rules::{Rewrite, RuleEvent, RuleKind, Rules, site_centre, site_out};
pub use script::{MAX_FRAMES, Motion, Script, ScriptError, Selector, Step};
pub use session::{
    Frame, Grab, PartReport, ReplayError, SETTING_NAMES, Session, apply_setting, configure, pin,
    pin_at, pin_of, replay, toggle_pin, unpin,
};
pub use solver::{
    Between, Components, FrameReport, PhaseTimes, Solver, SolverConfig, SolverError, SolverKind,
    StateSwitch, bbox, bbox_diagonal, edge_strain, edge_strains, elastic_energy, max_edge_strain,
};
pub use summary::{FrameMs, Summary, connected_components};

/// The session file the editor saves and `clayc run|render|export --session` replays: the
/// grammar's path, its parameters, the solver's settings, the pins and the log of gestures.
pub mod session_file {
    pub use crate::session::file::{
        LogEntry, Pin, SESSION_FORMAT, SESSION_VERSION, SavedSession, SessionError, Settings,
        parse, read, write,
    };
}
