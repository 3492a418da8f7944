//! Test helpers and the names of the library that only its tests and benches use, behind the
//! feature `testing` (the crate's own unit tests see them too). Not part of the stable
//! surface: the shipped editor, `clayc` and the Python module use none of them (the top level,
//! `clay::X`, is what they use and the types its signatures name), so a newcomer reads that
//! surface once and finds here what the tests reach for:
//! - the rules one by one (`cut`, `merge`, `replace`, `stretch`, [`Rules`], [`Rewrite`],
//!   [`site_centre`], [`site_out`], [`MAX_GROWTH`]), which the session otherwise runs;
//! - the measures the tests assert with ([`bbox`], [`bbox_diagonal`], [`edge_strain`],
//!   [`edge_strains`], [`elastic_energy`], [`max_edge_strain`], [`Components`],
//!   [`connected_components`], [`polygon_area`]);
//! - rendering's and the export's parts the shipped code reaches only through `render_png`,
//!   `pose_assembly_into` and `write_export` (posing, tessellation, the pixmap canvas, the
//!   writers `to_glb`, `to_gltf`, `to_obj`, their constants);
//! - gestures and settings the shipped code does through the session (`pin`, `unpin`,
//!   `apply_setting`) and the handles' identities ([`HandleId`], [`HeldInstance`]).
//!
//! [`gallery`] draws the documentation pictures.

#[cfg(feature = "testing")]
pub mod gallery;

pub use crate::assembly::{HandleId, HeldInstance};
pub use crate::export::gltf::{to_glb, to_gltf};
pub use crate::export::obj::to_obj;
pub use crate::export::{
    MAX_NAME_BYTES, MAX_THICKNESS, SHARE_TOLERANCE, SHARE_TOLERANCE_PER_METRE, srgb_to_linear,
};
pub use crate::plane::polygon_area;
pub use crate::render::{
    BACKGROUND, CONTOUR_MIN_TRIANGLES, PixmapCanvas, STRAIN_FULL, SiteFrame, Skin, contours,
    pose_assembly, pose_instance, pose_piece, render_pixmap, sheet_pixmap, strain_colour,
    tessellate_polyline, tessellate_proxy,
};
pub use crate::rules::stretch::MAX_GROWTH;
pub use crate::rules::{Rewrite, Rules, cut, merge, replace, site_centre, site_out, stretch};
pub use crate::session::{apply_setting, pin, unpin};
pub use crate::solver::{
    Between, Components, bbox, bbox_diagonal, edge_strain, edge_strains, elastic_energy,
    max_edge_strain,
};
pub use crate::summary::connected_components;
