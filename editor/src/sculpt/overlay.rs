//! The View menu's overlays on the canvas: strain colours, active state names, docking sites,
//! handles and pins, and part outlines. They are drawn by the same code as `clayc render
//! --overlay` ([`clay::draw_overlays`]) through an egui painter that implements
//! the renderer's [`clay::Canvas`], so the editor and the pictures never disagree.

use clay::{Overlays, View, draw_overlays};
use clay_dsl::compiled::Rgba;
use egui::{Color32, Pos2, Rect, Shape, Stroke, Vec2};

use super::Sculpt;
use crate::camera::Camera;

/// Which overlays are on (the View menu's toggles).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ViewOverlays {
    /// Every part edge coloured by its strain in the active state, with a legend.
    pub strain: bool,
    /// The active rest state's name on every part that has alternatives.
    pub states: bool,
    /// Docking sites, coloured by site type; open sites with their out arrow.
    pub sites: bool,
    /// The grab's held vertices as rings and pinned vertices as squares.
    pub handles: bool,
    /// The edges and vertices of every part (the graph the solver works on).
    pub part_graph: bool,
}

impl ViewOverlays {
    /// Whether any overlay is on.
    pub fn any(&self) -> bool {
        self.strain || self.states || self.sites || self.handles || self.part_graph
    }

    /// The renderer's overlay set for this sculpt.
    pub fn for_renderer(&self, sculpt: &Sculpt) -> Overlays {
        let mut overlays = Overlays {
            part_graph: self.part_graph,
            sites: self.sites,
            strain: self.strain,
            states: self.states,
            ..Default::default()
        };
        if self.handles {
            let (grabbed, pinned) = sculpt.held_vertices();
            overlays.handles = grabbed;
            overlays.pins = pinned;
        }
        overlays
    }
}

/// Draws the overlays that are on over the canvas rectangle `rect`.
pub fn paint(
    painter: &egui::Painter,
    rect: Rect,
    camera: &Camera,
    sculpt: &Sculpt,
    on: &ViewOverlays,
) {
    if !on.any() {
        return;
    }
    // The renderer works in pixels from the picture's corner (its strain legend sits at
    // (12, 12)); the egui canvas is offset by `rect.min`.
    let view = View {
        scale: camera.scale,
        world_origin: camera.centre,
        pixel_origin: glam::DVec2::new(rect.width() as f64 / 2.0, rect.height() as f64 / 2.0),
    };
    let mut canvas = PainterCanvas {
        painter: painter.with_clip_rect(rect),
        offset: rect.min.to_vec2(),
    };
    draw_overlays(
        &mut canvas,
        sculpt.grammar(),
        sculpt.data(),
        &view,
        &on.for_renderer(sculpt),
    );
}

/// An egui painter as the renderer's drawing surface.
struct PainterCanvas {
    painter: egui::Painter,
    offset: Vec2,
}

impl PainterCanvas {
    fn at(&self, [x, y]: [f32; 2]) -> Pos2 {
        Pos2::new(x, y) + self.offset
    }
}

fn colour(c: Rgba) -> Color32 {
    let [r, g, b, a] = c.0;
    Color32::from_rgba_unmultiplied(r, g, b, a)
}

impl clay::Canvas for PainterCanvas {
    fn fill_triangles(&mut self, points: &[[f32; 2]], triangles: &[[u32; 3]], c: Rgba) {
        let mut mesh = egui::Mesh::default();
        let fill = colour(c);
        for p in points {
            mesh.colored_vertex(self.at(*p), fill);
        }
        let n = points.len() as u32;
        for &[a, b, d] in triangles {
            if a < n && b < n && d < n {
                mesh.add_triangle(a, b, d);
            }
        }
        self.painter.add(Shape::mesh(mesh));
    }

    /// The renderer fills big meshes by their outlines; overlays never do. The contours are
    /// triangulated as an outline with holes (the case the renderer produces) and filled.
    fn fill_contours(&mut self, contours: &[Vec<[f32; 2]>], c: Rgba) {
        let ring = |r: &Vec<[f32; 2]>| -> Vec<glam::DVec2> {
            r.iter()
                .map(|p| glam::DVec2::new(p[0] as f64, p[1] as f64))
                .collect()
        };
        let Some((outer, holes)) = contours.split_first() else {
            return;
        };
        let holes: Vec<_> = holes.iter().map(ring).collect();
        if let Some((points, triangles)) = clay::tessellate_polygon(&ring(outer), &holes) {
            let points: Vec<[f32; 2]> = points.iter().map(|p| [p.x as f32, p.y as f32]).collect();
            self.fill_triangles(&points, &triangles, c);
        }
    }

    fn stroke_segments(&mut self, segments: &[[[f32; 2]; 2]], width: f32, c: Rgba) {
        let stroke = Stroke::new(width, colour(c));
        for [a, b] in segments {
            self.painter
                .line_segment([self.at(*a), self.at(*b)], stroke);
        }
    }

    fn fill_circle(&mut self, centre: [f32; 2], radius: f32, c: Rgba) {
        self.painter
            .circle_filled(self.at(centre), radius, colour(c));
    }

    fn fill_rect(&mut self, min: [f32; 2], size: [f32; 2], c: Rgba) {
        let rect = Rect::from_min_size(self.at(min), Vec2::new(size[0], size[1]));
        self.painter.rect_filled(rect, 0.0, colour(c));
    }

    fn text(&mut self, origin: [f32; 2], size: f32, c: Rgba, text: &str) {
        self.painter.text(
            self.at(origin),
            egui::Align2::LEFT_BOTTOM,
            text,
            egui::FontId::proportional(size),
            colour(c),
        );
    }
}
