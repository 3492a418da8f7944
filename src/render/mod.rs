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
pub use draw::{
    Canvas, Overlays, RenderOptions, STRAIN_LEGEND, View, bounds, draw_overlays, site_type_colour,
};
pub use pick::part_at;
pub use pose::{WorldMesh, pose_assembly, pose_assembly_into};
pub use raster::{MAX_SIDE, RenderError, render_png};
pub use sheet::{sheet_png, sheet_svg};
pub use svg::render_svg;
pub use tessellate::{Mesh, Solid, TessellationCache, tessellate_polygon};
// Names only the tests and benches use, re-exported as `clay::testing::X`.
#[cfg(any(test, feature = "testing"))]
pub use {
    contour::{CONTOUR_MIN_TRIANGLES, contours},
    draw::{BACKGROUND, STRAIN_FULL, strain_colour},
    pose::{SiteFrame, Skin, pose_instance, pose_piece},
    raster::{PixmapCanvas, render_pixmap},
    sheet::sheet_pixmap,
    tessellate::{tessellate_polyline, tessellate_proxy},
};
