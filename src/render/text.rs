//! Label text: lays out a line of text in the Hack font (shipped by `epaint_default_fonts`, the
//! font egui uses for monospace) and hands its glyph outlines to a path sink, since tiny-skia
//! draws no text of its own.

use std::sync::OnceLock;

use skrifa::instance::{LocationRef, Size};
use skrifa::outline::{DrawSettings, OutlinePen};
use skrifa::{FontRef, MetadataProvider};

/// Receives glyph outlines in pixel coordinates (y down).
pub trait PathSink {
    fn move_to(&mut self, x: f32, y: f32);
    fn line_to(&mut self, x: f32, y: f32);
    fn quad_to(&mut self, x1: f32, y1: f32, x: f32, y: f32);
    fn cubic_to(&mut self, x1: f32, y1: f32, x2: f32, y2: f32, x: f32, y: f32);
    fn close(&mut self);
}

fn font() -> Option<&'static FontRef<'static>> {
    static FONT: OnceLock<Option<FontRef<'static>>> = OnceLock::new();
    FONT.get_or_init(|| FontRef::new(epaint_default_fonts::HACK_REGULAR).ok())
        .as_ref()
}

/// The advance width of `text` at `size` pixels (0 if the font cannot be read).
pub fn measure(text: &str, size: f32) -> f32 {
    let Some(font) = font() else { return 0.0 };
    let metrics = font.glyph_metrics(Size::new(size), LocationRef::default());
    let charmap = font.charmap();
    text.chars()
        .filter_map(|c| charmap.map(c).or_else(|| charmap.map('?')))
        .filter_map(|g| metrics.advance_width(g))
        .sum()
}

/// Emits the outlines of `text` at `size` pixels with its baseline starting at `(x, y)`.
pub fn outline(text: &str, size: f32, x: f32, y: f32, sink: &mut dyn PathSink) {
    let Some(font) = font() else { return };
    let metrics = font.glyph_metrics(Size::new(size), LocationRef::default());
    let charmap = font.charmap();
    let outlines = font.outline_glyphs();
    let mut pen_x = x;
    for c in text.chars() {
        let Some(gid) = charmap.map(c).or_else(|| charmap.map('?')) else {
            continue;
        };
        if let Some(glyph) = outlines.get(gid) {
            let mut pen = Flip { sink, x: pen_x, y };
            let settings = DrawSettings::unhinted(Size::new(size), LocationRef::default());
            // A glyph that fails to draw is left out; the rest of the label still reads.
            let _ = glyph.draw(settings, &mut pen);
        }
        pen_x += metrics.advance_width(gid).unwrap_or(0.0);
    }
}

/// Font units are y up from the baseline; pixels are y down.
struct Flip<'a> {
    sink: &'a mut dyn PathSink,
    x: f32,
    y: f32,
}

impl OutlinePen for Flip<'_> {
    fn move_to(&mut self, x: f32, y: f32) {
        self.sink.move_to(self.x + x, self.y - y);
    }
    fn line_to(&mut self, x: f32, y: f32) {
        self.sink.line_to(self.x + x, self.y - y);
    }
    fn quad_to(&mut self, cx0: f32, cy0: f32, x: f32, y: f32) {
        self.sink
            .quad_to(self.x + cx0, self.y - cy0, self.x + x, self.y - y);
    }
    fn curve_to(&mut self, cx0: f32, cy0: f32, cx1: f32, cy1: f32, x: f32, y: f32) {
        self.sink.cubic_to(
            self.x + cx0,
            self.y - cy0,
            self.x + cx1,
            self.y - cy1,
            self.x + x,
            self.y - y,
        );
    }
    fn close(&mut self) {
        self.sink.close();
    }
}
