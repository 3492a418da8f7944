//! The canvas's isometric 3D view (View > Isometric 3D, or I): the live model drawn by the same
//! code as `clayc render --view iso` ([`clay::iso_pixmap`] of the export's
//! [`clay::scene`]) into a texture the size of the canvas. The picture is made again
//! only when the model or the canvas size changes. While it is shown the canvas takes no
//! sculpting gestures: a point on the picture is not a point of the floor plan (docs/editor.md).

use clay::{ExportOptions, iso_pixmap, scene};
use egui::{Color32, ColorImage, Rect, TextureHandle, TextureOptions};

use super::Sculpt;

/// The last picture: what it shows (grammar, revision, size in pixels) and its texture.
pub struct IsoPicture {
    key: (usize, u64, [u32; 2]),
    texture: TextureHandle,
    /// The picture's pixels (premultiplied RGBA, as tiny-skia makes them).
    pub pixels: Vec<u8>,
    pub size: [u32; 2],
}

/// Draws the sculpt's isometric picture over `rect`, reusing `last` when it still shows it.
pub fn paint(
    ui: &egui::Ui,
    painter: &egui::Painter,
    rect: Rect,
    sculpt: &Sculpt,
    last: &mut Option<IsoPicture>,
) {
    let ppp = ui.ctx().pixels_per_point();
    let side = |points: f32| ((points * ppp).round() as u32).clamp(1, 4096);
    let size = [side(rect.width()), side(rect.height())];
    let key = (
        std::sync::Arc::as_ptr(sculpt.grammar()) as usize,
        sculpt.revision(),
        size,
    );
    if last.as_ref().is_none_or(|p| p.key != key) {
        let s = scene(sculpt.grammar(), sculpt.data(), &ExportOptions::default());
        *last = iso_pixmap(&s, size[0], size[1]).ok().map(|pixmap| {
            let image = ColorImage::from_rgba_premultiplied(
                [size[0] as usize, size[1] as usize],
                pixmap.data(),
            );
            IsoPicture {
                key,
                texture: ui
                    .ctx()
                    .load_texture("clay-iso", image, TextureOptions::LINEAR),
                pixels: pixmap.data().to_vec(),
                size,
            }
        });
    }
    let Some(picture) = last else { return };
    let uv = Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
    painter.image(picture.texture.id(), rect, uv, Color32::WHITE);
    painter.text(
        rect.left_top() + egui::vec2(8.0, 8.0),
        egui::Align2::LEFT_TOP,
        "Isometric 3D: sculpting is off (I to go back)",
        egui::FontId::proportional(13.0),
        Color32::from_gray(90),
    );
}
