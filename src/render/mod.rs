//! Pictures of assemblies (paper 5.2, proxy geometry and skinning): tessellation of each piece's
//! proxy geometry, posing it into the world, and drawing it with tiny-skia (PNG) or as SVG.
//!
//! Data flows one way: `tessellate.rs` (once per piece and rest state, cached) -> `pose.rs`
//! (every frame: plain world-space triangles, [`WorldMesh`]) -> `draw.rs` (overlays, labels) onto
//! a [`Canvas`] (`raster.rs` or `svg.rs`); large meshes are filled by their [`contours`]. The
//! editor draws the same [`WorldMesh`]es with egui.

pub(crate) mod contour;
pub(crate) mod draw;
pub(crate) mod pick;
pub(crate) mod pose;
pub(crate) mod raster;
pub(crate) mod sheet;
pub(crate) mod svg;
pub(crate) mod tessellate;
pub(crate) mod text;

// The rendering surface, re-exported once more at the crate's root as `clay::X`.
pub use contour::{CONTOUR_MIN_TRIANGLES, contours};
pub use draw::{
    BACKGROUND, Canvas, Overlays, RenderOptions, STRAIN_FULL, STRAIN_LEGEND, View, bounds,
    draw_overlays, site_type_colour, strain_colour,
};
pub use pick::part_at;
pub use pose::{
    SiteFrame, Skin, WorldMesh, pose_assembly, pose_assembly_into, pose_instance, pose_piece,
};
pub use raster::{MAX_SIDE, PixmapCanvas, RenderError, render_pixmap, render_png};
pub use sheet::{sheet_pixmap, sheet_png, sheet_svg};
pub use svg::render_svg;
pub use tessellate::{
    Mesh, Solid, TessellationCache, tessellate_polygon, tessellate_polyline, tessellate_proxy,
};
