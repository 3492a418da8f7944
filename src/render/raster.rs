//! The tiny-skia back end: a [`Canvas`] over a `Pixmap` with anti-aliased fills and strokes,
//! and the functions that render an assembly to RGBA pixels or PNG bytes.

use clay_dsl::compiled::{AssemblyData, CompiledGrammar, Rgba};
use tiny_skia::{
    Color, FillRule, LineCap, LineJoin, Paint, PathBuilder, Pixmap, Rect, Stroke, Transform,
};

use super::contour::finite;
use super::draw::{Canvas, RenderOptions, View, bounds, draw_assembly, wound_triangles};
use super::pose::pose_assembly;
use super::tessellate::TessellationCache;
use super::text::{self, PathSink};

/// Largest image side accepted, in pixels (tiny-skia and memory both have limits).
pub const MAX_SIDE: u32 = 16384;

/// Why an image could not be made.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum RenderError {
    /// Width or height is 0 or above [`MAX_SIDE`].
    Size { width: u32, height: u32 },
    /// PNG encoding failed.
    Encode(String),
}

impl std::fmt::Display for RenderError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Size { width, height } => {
                write!(
                    f,
                    "image size {width}x{height} is not between 1x1 and {MAX_SIDE}x{MAX_SIDE}"
                )
            }
            Self::Encode(e) => write!(f, "PNG encoding failed: {e}"),
        }
    }
}

impl std::error::Error for RenderError {}

/// A [`Canvas`] drawing into a tiny-skia pixmap.
pub struct PixmapCanvas {
    pub pixmap: Pixmap,
}

impl PixmapCanvas {
    pub fn new(width: u32, height: u32, background: Rgba) -> Result<Self, RenderError> {
        let err = RenderError::Size { width, height };
        if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
            return Err(err);
        }
        let mut pixmap = Pixmap::new(width, height).ok_or(err)?;
        let [r, g, b, a] = background.0;
        pixmap.fill(Color::from_rgba8(r, g, b, a));
        Ok(Self { pixmap })
    }
}

fn paint(c: Rgba) -> Paint<'static> {
    let mut p = Paint::default();
    let [r, g, b, a] = c.0;
    p.set_color_rgba8(r, g, b, a);
    p.anti_alias = true;
    p
}

impl Canvas for PixmapCanvas {
    fn fill_triangles(&mut self, points: &[[f32; 2]], triangles: &[[u32; 3]], colour: Rgba) {
        let mut pb = PathBuilder::new();
        for c in wound_triangles(points, triangles) {
            pb.move_to(c[0][0], c[0][1]);
            pb.line_to(c[1][0], c[1][1]);
            pb.line_to(c[2][0], c[2][1]);
            pb.close();
        }
        if let Some(path) = pb.finish() {
            self.pixmap.fill_path(
                &path,
                &paint(colour),
                FillRule::Winding,
                Transform::identity(),
                None,
            );
        }
    }

    fn fill_contours(&mut self, contours: &[Vec<[f32; 2]>], colour: Rgba) {
        let mut pb = PathBuilder::new();
        for c in contours.iter().filter(|c| c.len() >= 3) {
            pb.move_to(c[0][0], c[0][1]);
            for p in &c[1..] {
                pb.line_to(p[0], p[1]);
            }
            pb.close();
        }
        if let Some(path) = pb.finish() {
            self.pixmap.fill_path(
                &path,
                &paint(colour),
                FillRule::Winding,
                Transform::identity(),
                None,
            );
        }
    }

    fn stroke_segments(&mut self, segments: &[[[f32; 2]; 2]], width: f32, colour: Rgba) {
        let mut pb = PathBuilder::new();
        for [a, b] in segments.iter().filter(|s| finite(&s[0]) && finite(&s[1])) {
            pb.move_to(a[0], a[1]);
            pb.line_to(b[0], b[1]);
        }
        if let Some(path) = pb.finish() {
            let stroke = Stroke {
                width,
                line_cap: LineCap::Round,
                line_join: LineJoin::Round,
                ..Stroke::default()
            };
            self.pixmap
                .stroke_path(&path, &paint(colour), &stroke, Transform::identity(), None);
        }
    }

    fn fill_circle(&mut self, centre: [f32; 2], radius: f32, colour: Rgba) {
        if let Some(path) = PathBuilder::from_circle(centre[0], centre[1], radius) {
            self.pixmap.fill_path(
                &path,
                &paint(colour),
                FillRule::Winding,
                Transform::identity(),
                None,
            );
        }
    }

    fn fill_rect(&mut self, min: [f32; 2], size: [f32; 2], colour: Rgba) {
        if let Some(rect) = Rect::from_xywh(min[0], min[1], size[0], size[1]) {
            self.pixmap
                .fill_rect(rect, &paint(colour), Transform::identity(), None);
        }
    }

    fn text(&mut self, origin: [f32; 2], size: f32, colour: Rgba, text_: &str) {
        let mut sink = Builder(PathBuilder::new());
        text::outline(text_, size, origin[0], origin[1], &mut sink);
        if let Some(path) = sink.0.finish() {
            self.pixmap.fill_path(
                &path,
                &paint(colour),
                FillRule::Winding,
                Transform::identity(),
                None,
            );
        }
    }
}

struct Builder(PathBuilder);

impl PathSink for Builder {
    fn move_to(&mut self, x: f32, y: f32) {
        self.0.move_to(x, y);
    }
    fn line_to(&mut self, x: f32, y: f32) {
        self.0.line_to(x, y);
    }
    fn quad_to(&mut self, x1: f32, y1: f32, x: f32, y: f32) {
        self.0.quad_to(x1, y1, x, y);
    }
    fn cubic_to(&mut self, x1: f32, y1: f32, x2: f32, y2: f32, x: f32, y: f32) {
        self.0.cubic_to(x1, y1, x2, y2, x, y);
    }
    fn close(&mut self) {
        self.0.close();
    }
}

/// The view `options` asks for, or the one fitting the posed assembly into the image.
pub fn view_for(
    meshes: &[super::pose::WorldMesh],
    assembly: &AssemblyData,
    options: &RenderOptions,
) -> View {
    options.view.unwrap_or_else(|| {
        let (min, max) = bounds(meshes, assembly);
        View::fit(
            min,
            max,
            glam::DVec2::ZERO,
            glam::DVec2::new(options.width as f64, options.height as f64),
            options.margin as f64,
        )
    })
}

/// Renders an assembly into a pixmap.
pub fn render_pixmap(
    grammar: &CompiledGrammar,
    assembly: &AssemblyData,
    options: &RenderOptions,
    cache: &mut TessellationCache,
) -> Result<Pixmap, RenderError> {
    let mut canvas = PixmapCanvas::new(options.width, options.height, options.background)?;
    let meshes = pose_assembly(grammar, assembly, cache);
    let view = view_for(&meshes, assembly, options);
    draw_assembly(&mut canvas, grammar, assembly, &meshes, &view, options);
    Ok(canvas.pixmap)
}

/// Renders an assembly to PNG bytes.
pub fn render_png(
    grammar: &CompiledGrammar,
    assembly: &AssemblyData,
    options: &RenderOptions,
) -> Result<Vec<u8>, RenderError> {
    let pixmap = render_pixmap(grammar, assembly, options, &mut TessellationCache::new())?;
    pixmap
        .encode_png()
        .map_err(|e| RenderError::Encode(e.to_string()))
}
