//! A 3D look without a 3D viewer (`clayc render --view iso`): the exported [`Scene`] (each
//! node's geometry placed by its node) drawn in an isometric projection with tiny-skia, seen
//! from the south-east and above, faces sorted back to front (painter's algorithm) and shaded
//! by their normal, back faces culled. The docs and tests use it to show heights; it is a
//! picture, not a renderer: intersecting faces may sort wrongly.

use tiny_skia::{FillRule, Paint, PathBuilder, Pixmap, Transform};

use super::Scene;
use crate::render::RenderError;
use crate::render::draw::BACKGROUND;

/// Towards the viewer, in the scene's y-up coordinates (east, up, south).
const TOWARDS_VIEWER: [f64; 3] = [1.0, 1.0, 1.0];
/// Where the light comes from (north-west of the viewer and high).
const LIGHT: [f64; 3] = [0.35, 1.0, 0.6];

/// The screen position (right, up) of a scene point, before fitting.
fn project(p: [f32; 3]) -> [f64; 2] {
    let (x, y, z) = (p[0] as f64, p[1] as f64, p[2] as f64);
    let cos30 = 3f64.sqrt() / 2.0;
    [(x - z) * cos30, y + (x + z) * -0.5]
}

/// Distance from the viewer along the view direction (larger is farther).
fn depth(p: [f32; 3]) -> f64 {
    let n = 3f64.sqrt();
    -(p[0] as f64 + p[1] as f64 + p[2] as f64) / n
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// One face to draw: its screen corners, depth and shaded colour.
struct Face {
    corners: [[f64; 2]; 3],
    depth: f64,
    rgba: [u8; 4],
}

/// The scene as an isometric picture of `width` x `height` pixels.
pub fn iso_pixmap(scene: &Scene, width: u32, height: u32) -> Result<Pixmap, RenderError> {
    let err = RenderError::Size { width, height };
    if width == 0
        || height == 0
        || width > crate::render::raster::MAX_SIDE
        || height > crate::render::raster::MAX_SIDE
    {
        return Err(err);
    }
    let mut pixmap = Pixmap::new(width, height).ok_or(err)?;
    let [r, g, b, a] = BACKGROUND.0;
    pixmap.fill(tiny_skia::Color::from_rgba8(r, g, b, a));
    let mut faces = lit_faces(scene);
    if faces.is_empty() {
        return Ok(pixmap);
    }
    let screen = ScreenFit::new(&faces, width, height);
    // Far faces first; ties keep the scene's order, so the picture is deterministic.
    faces.sort_by(|a, b| b.depth.total_cmp(&a.depth));
    paint_faces(&mut pixmap, &faces, &screen);
    Ok(pixmap)
}

/// Every triangle of the scene that faces the viewer, projected and shaded by the light.
fn lit_faces(scene: &Scene) -> Vec<Face> {
    let light_len = dot(LIGHT, LIGHT).sqrt();
    let mut faces = Vec::new();
    for node in &scene.nodes {
        for p in &node.primitives {
            let colour = scene
                .materials
                .get(p.material)
                .map_or([128, 128, 128, 255], |c| c.0);
            let world: Vec<[f32; 3]> = p
                .positions
                .iter()
                .map(|&q| node.to_world(q).as_vec3().to_array())
                .collect();
            for t in p.indices.chunks_exact(3) {
                let Some(v) = [t[0], t[1], t[2]]
                    .iter()
                    .map(|&i| world.get(i as usize).copied())
                    .collect::<Option<Vec<_>>>()
                else {
                    continue;
                };
                let Some(n) = p
                    .normals
                    .get(t[0] as usize)
                    .map(|&n| node.direction_to_world(n).to_array())
                else {
                    continue;
                };
                if dot(n, TOWARDS_VIEWER) <= 1e-9 {
                    continue;
                }
                let shade = 0.55 + 0.45 * (dot(n, LIGHT) / light_len).max(0.0);
                let lit = |c: u8| (c as f64 * shade).round().clamp(0.0, 255.0) as u8;
                faces.push(Face {
                    corners: [project(v[0]), project(v[1]), project(v[2])],
                    depth: (depth(v[0]) + depth(v[1]) + depth(v[2])) / 3.0,
                    rgba: [lit(colour[0]), lit(colour[1]), lit(colour[2]), colour[3]],
                });
            }
        }
    }
    faces
}

/// The projected faces fitted into the picture with a margin, y pointing down on screen.
struct ScreenFit {
    centre: [f64; 2],
    scale: f64,
    size: [f64; 2],
}

impl ScreenFit {
    fn new(faces: &[Face], width: u32, height: u32) -> Self {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for c in faces.iter().flat_map(|f| f.corners) {
            for k in 0..2 {
                lo[k] = lo[k].min(c[k]);
                hi[k] = hi[k].max(c[k]);
            }
        }
        let margin = 24.0;
        let scale = ((width as f64 - 2.0 * margin) / (hi[0] - lo[0]).max(1e-9))
            .min((height as f64 - 2.0 * margin) / (hi[1] - lo[1]).max(1e-9));
        Self {
            centre: [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0],
            scale,
            size: [width as f64, height as f64],
        }
    }

    /// A projected point in pixels.
    fn place(&self, c: [f64; 2]) -> (f32, f32) {
        (
            (self.size[0] / 2.0 + (c[0] - self.centre[0]) * self.scale) as f32,
            (self.size[1] / 2.0 - (c[1] - self.centre[1]) * self.scale) as f32,
        )
    }
}

/// Fills each face in order, with a hairline of its colour over its seams.
fn paint_faces(pixmap: &mut Pixmap, faces: &[Face], screen: &ScreenFit) {
    let mut paint = Paint {
        anti_alias: true,
        ..Paint::default()
    };
    let seam = tiny_skia::Stroke {
        width: 0.8,
        line_join: tiny_skia::LineJoin::Round,
        ..tiny_skia::Stroke::default()
    };
    for f in faces {
        let mut pb = PathBuilder::new();
        let (x, y) = screen.place(f.corners[0]);
        pb.move_to(x, y);
        for c in &f.corners[1..] {
            let (x, y) = screen.place(*c);
            pb.line_to(x, y);
        }
        pb.close();
        let Some(path) = pb.finish() else { continue };
        let [r, g, b, a] = f.rgba;
        paint.set_color_rgba8(r, g, b, a);
        pixmap.fill_path(
            &path,
            &paint,
            FillRule::Winding,
            Transform::identity(),
            None,
        );
        // A hairline of the same colour closes the anti-aliased seams between the triangles of
        // one face (they would show the background through as light lines).
        pixmap.stroke_path(&path, &paint, &seam, Transform::identity(), None);
    }
}
