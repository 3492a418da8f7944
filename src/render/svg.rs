//! The SVG back end: a [`Canvas`] that writes the same triangles, strokes and glyph outlines as
//! the PNG back end into an SVG document (text as paths, so no font is needed to view it).

use std::fmt::Write;

use clay_dsl::compiled::{AssemblyData, CompiledGrammar, Rgba};

use super::contour::finite;
use super::draw::{Canvas, RenderOptions, draw_assembly, hex, wound_triangles};
use super::pose::pose_assembly;
use super::raster::view_for;
use super::tessellate::TessellationCache;
use super::text::{self, PathSink};

/// A [`Canvas`] collecting SVG elements.
pub struct SvgCanvas {
    width: u32,
    height: u32,
    body: String,
}

impl SvgCanvas {
    pub fn new(width: u32, height: u32, background: Rgba) -> Self {
        let mut canvas = Self {
            width,
            height,
            body: String::new(),
        };
        canvas.fill_rect([0.0, 0.0], [width as f32, height as f32], background);
        canvas
    }

    /// The finished document.
    pub fn finish(self) -> String {
        format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\">\n{}</svg>\n",
            self.body,
            w = self.width,
            h = self.height
        )
    }
}

/// Formats a coordinate; non-finite values never reach the file (callers skip them, this is the
/// last guard).
fn num(v: f32) -> String {
    let v = if v.is_finite() { v } else { 0.0 };
    let s = format!("{v:.2}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

fn fill_attrs(c: Rgba) -> String {
    let (h, a) = hex(c);
    if a < 1.0 {
        format!("fill=\"{h}\" fill-opacity=\"{}\"", num(a))
    } else {
        format!("fill=\"{h}\"")
    }
}

impl Canvas for SvgCanvas {
    fn fill_triangles(&mut self, points: &[[f32; 2]], triangles: &[[u32; 3]], colour: Rgba) {
        let mut d = String::new();
        for c in wound_triangles(points, triangles) {
            let _ = write!(
                d,
                "M{} {}L{} {}L{} {}Z",
                num(c[0][0]),
                num(c[0][1]),
                num(c[1][0]),
                num(c[1][1]),
                num(c[2][0]),
                num(c[2][1])
            );
        }
        if !d.is_empty() {
            let _ = writeln!(self.body, "<path d=\"{d}\" {}/>", fill_attrs(colour));
        }
    }

    fn fill_contours(&mut self, contours: &[Vec<[f32; 2]>], colour: Rgba) {
        let mut d = String::new();
        for c in contours.iter().filter(|c| c.len() >= 3) {
            let _ = write!(d, "M{} {}", num(c[0][0]), num(c[0][1]));
            for p in &c[1..] {
                let _ = write!(d, "L{} {}", num(p[0]), num(p[1]));
            }
            d.push('Z');
        }
        if !d.is_empty() {
            let _ = writeln!(self.body, "<path d=\"{d}\" {}/>", fill_attrs(colour));
        }
    }

    fn stroke_segments(&mut self, segments: &[[[f32; 2]; 2]], width: f32, colour: Rgba) {
        let mut d = String::new();
        for [a, b] in segments.iter().filter(|s| finite(&s[0]) && finite(&s[1])) {
            let _ = write!(
                d,
                "M{} {}L{} {}",
                num(a[0]),
                num(a[1]),
                num(b[0]),
                num(b[1])
            );
        }
        if !d.is_empty() {
            let (h, a) = hex(colour);
            let _ = writeln!(
                self.body,
                "<path d=\"{d}\" fill=\"none\" stroke=\"{h}\" stroke-opacity=\"{}\" stroke-width=\"{}\" stroke-linecap=\"round\"/>",
                num(a),
                num(width)
            );
        }
    }

    fn fill_circle(&mut self, centre: [f32; 2], radius: f32, colour: Rgba) {
        if finite(&centre) {
            let _ = writeln!(
                self.body,
                "<circle cx=\"{}\" cy=\"{}\" r=\"{}\" {}/>",
                num(centre[0]),
                num(centre[1]),
                num(radius),
                fill_attrs(colour)
            );
        }
    }

    fn fill_rect(&mut self, min: [f32; 2], size: [f32; 2], colour: Rgba) {
        if finite(&min) && finite(&size) {
            let _ = writeln!(
                self.body,
                "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" {}/>",
                num(min[0]),
                num(min[1]),
                num(size[0]),
                num(size[1]),
                fill_attrs(colour)
            );
        }
    }

    fn text(&mut self, origin: [f32; 2], size: f32, colour: Rgba, text_: &str) {
        let mut sink = PathData(String::new());
        text::outline(text_, size, origin[0], origin[1], &mut sink);
        if !sink.0.is_empty() {
            let _ = writeln!(self.body, "<path d=\"{}\" {}/>", sink.0, fill_attrs(colour));
        }
    }
}

struct PathData(String);

impl PathSink for PathData {
    fn move_to(&mut self, x: f32, y: f32) {
        let _ = write!(self.0, "M{} {}", num(x), num(y));
    }
    fn line_to(&mut self, x: f32, y: f32) {
        let _ = write!(self.0, "L{} {}", num(x), num(y));
    }
    fn quad_to(&mut self, x1: f32, y1: f32, x: f32, y: f32) {
        let _ = write!(self.0, "Q{} {} {} {}", num(x1), num(y1), num(x), num(y));
    }
    fn cubic_to(&mut self, x1: f32, y1: f32, x2: f32, y2: f32, x: f32, y: f32) {
        let _ = write!(
            self.0,
            "C{} {} {} {} {} {}",
            num(x1),
            num(y1),
            num(x2),
            num(y2),
            num(x),
            num(y)
        );
    }
    fn close(&mut self) {
        self.0.push('Z');
    }
}

/// Renders an assembly to an SVG document with the same drawing as the PNG.
pub fn render_svg(
    grammar: &CompiledGrammar,
    assembly: &AssemblyData,
    options: &RenderOptions,
) -> String {
    let mut canvas = SvgCanvas::new(options.width, options.height, options.background);
    let meshes = pose_assembly(grammar, assembly, &mut TessellationCache::new());
    let view = view_for(&meshes, assembly, options);
    draw_assembly(&mut canvas, grammar, assembly, &meshes, &view, options);
    canvas.finish()
}
