//! Pictures of assemblies (paper 5.2, proxy geometry and skinning): tessellation of each piece's
//! proxy geometry, posing it into the world, and drawing it with tiny-skia (PNG) or as SVG.
//!
//! Data flows one way: [`tessellate`] (once per piece and rest state, cached) -> [`pose`]
//! (every frame: plain world-space triangles, [`WorldMesh`]) -> [`draw`] (overlays, labels) onto
//! a [`Canvas`] ([`raster`] or [`svg`]); large meshes are filled by their [`contour`]s. The
//! editor draws the same [`WorldMesh`]es with egui.

pub mod contour;
pub mod draw;
pub mod pick;
pub mod pose;
pub mod raster;
pub mod sheet;
pub mod svg;
pub mod tessellate;
pub mod text;

pub use draw::{
    Canvas, Overlays, RenderOptions, View, edge_strains, site_type_colour, strain_colour,
};
pub use pose::{
    RigidMotion, SiteFrame, Skin, WorldMesh, pose_assembly, pose_instance, pose_piece,
    rigid_motion, site_out,
};
pub use raster::{RenderError, render_pixmap, render_png};
pub use sheet::{sheet_pixmap, sheet_png, sheet_svg};
pub use svg::render_svg;
pub use tessellate::{
    Mesh, Solid, TessellationCache, tessellate_polygon, tessellate_polyline, tessellate_proxy,
};
