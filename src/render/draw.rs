//! The drawing of an assembly, written once against a small [`Canvas`] trait in pixel space so
//! that the PNG (tiny-skia) and SVG outputs show the same triangles, outlines and overlays.

use std::collections::HashMap;

use clay_dsl::compiled::{AssemblyData, CompiledGrammar, PartKind, Rgba};
use glam::DVec2;

use super::contour::finite;
use super::contour::{CONTOUR_MIN_TRIANGLES, contours};
use super::pose::{WorldMesh, drawn_site_out};
use super::text;

/// The triangles a canvas fills: those whose corners exist and are finite, all turned to one
/// winding, so that under the nonzero rule their union is filled once, with no anti-aliasing
/// seams along shared edges.
pub(crate) fn wound_triangles<'a>(
    points: &'a [[f32; 2]],
    triangles: &'a [[u32; 3]],
) -> impl Iterator<Item = [[f32; 2]; 3]> + 'a {
    triangles.iter().filter_map(move |t| {
        let mut c = [[0.0f32; 2]; 3];
        for (k, &i) in t.iter().enumerate() {
            c[k] = *points.get(i as usize).filter(|p| finite(p))?;
        }
        let area =
            (c[1][0] - c[0][0]) * (c[2][1] - c[0][1]) - (c[1][1] - c[0][1]) * (c[2][0] - c[0][0]);
        if area < 0.0 {
            c.swap(1, 2);
        }
        Some(c)
    })
}

/// A pixel-space drawing surface (x right, y down).
pub trait Canvas {
    /// Fills the union of the triangles (each one's winding is normalised, so overlaps do not
    /// cancel or double-blend).
    fn fill_triangles(&mut self, points: &[[f32; 2]], triangles: &[[u32; 3]], colour: Rgba);
    /// Fills what the closed contours wind around (the nonzero rule).
    fn fill_contours(&mut self, contours: &[Vec<[f32; 2]>], colour: Rgba);
    /// Strokes each segment with round caps.
    fn stroke_segments(&mut self, segments: &[[[f32; 2]; 2]], width: f32, colour: Rgba);
    fn fill_circle(&mut self, centre: [f32; 2], radius: f32, colour: Rgba);
    fn fill_rect(&mut self, min: [f32; 2], size: [f32; 2], colour: Rgba);
    /// A line of text, its baseline starting at `origin`.
    fn text(&mut self, origin: [f32; 2], size: f32, colour: Rgba, text: &str);
}

/// World (metres, y north) to pixels (y down): `pixel = pixel_origin + (p - world_origin) * (scale, -scale)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    pub scale: f64,
    pub world_origin: DVec2,
    pub pixel_origin: DVec2,
}

impl View {
    /// The view that fits the world box `[min, max]` centred into the pixel rectangle
    /// `[rect_min, rect_min + rect_size]` leaving `margin` pixels on every side. An empty or
    /// non-finite box gives a 1 m square around the origin.
    pub fn fit(min: DVec2, max: DVec2, rect_min: DVec2, rect_size: DVec2, margin: f64) -> Self {
        let (min, max) = if min.is_finite() && max.is_finite() && min.cmple(max).all() {
            (min, max)
        } else {
            (DVec2::splat(-0.5), DVec2::splat(0.5))
        };
        let extent = (max - min).max(DVec2::splat(1e-6));
        let room = (rect_size - DVec2::splat(2.0 * margin)).max(DVec2::ONE);
        let scale = (room.x / extent.x).min(room.y / extent.y);
        Self {
            scale,
            world_origin: (min + max) / 2.0,
            pixel_origin: rect_min + rect_size / 2.0,
        }
    }

    pub fn to_pixel(&self, p: DVec2) -> [f32; 2] {
        let d = (p - self.world_origin) * self.scale;
        [
            (self.pixel_origin.x + d.x) as f32,
            (self.pixel_origin.y - d.y) as f32,
        ]
    }
}

/// Which overlays to draw over the geometry.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Overlays {
    /// The edges and vertices of every part.
    pub part_graph: bool,
    /// Docking sites, coloured by site type; free sites get their out arrow.
    pub sites: bool,
    /// Every part edge coloured by its strain `|len / rest_len - 1|` in the active state.
    pub strain: bool,
    /// Each part's active rest state as a label (parts with alternatives only).
    pub states: bool,
    /// Global vertex indices the user drags (drawn as rings).
    pub handles: Vec<usize>,
    /// Global vertex indices held in place (drawn as squares).
    pub pins: Vec<usize>,
}

/// Options of [`super::render_png`] and friends.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    /// Pixels left free around the fitted assembly.
    pub margin: f32,
    pub background: Rgba,
    /// Draw each proxy's boundary in a darker shade of its fill.
    pub outlines: bool,
    pub overlays: Overlays,
    /// A fixed view; `None` fits the assembly into the image.
    pub view: Option<View>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            width: 1024,
            height: 768,
            margin: 24.0,
            background: BACKGROUND,
            outlines: true,
            overlays: Overlays::default(),
            view: None,
        }
    }
}

pub const BACKGROUND: Rgba = Rgba([246, 243, 236, 255]);
const INK: Rgba = Rgba([40, 40, 48, 255]);
const GRAPH: Rgba = Rgba([60, 60, 80, 200]);
const HANDLE: Rgba = Rgba([220, 30, 60, 255]);
const PIN: Rgba = Rgba([30, 60, 200, 255]);
/// Strain at which the ramp reaches full red.
pub const STRAIN_FULL: f64 = 0.5;

/// A fixed, distinguishable colour per site type index (cycling after ten).
pub fn site_type_colour(site_type: usize) -> Rgba {
    const PALETTE: [[u8; 3]; 10] = [
        [31, 119, 180],
        [255, 127, 14],
        [44, 160, 44],
        [214, 39, 40],
        [148, 103, 189],
        [140, 86, 75],
        [227, 119, 194],
        [127, 127, 127],
        [188, 189, 34],
        [23, 190, 207],
    ];
    let [r, g, b] = PALETTE[site_type % PALETTE.len()];
    Rgba([r, g, b, 255])
}

/// The strain ramp: green at 0, yellow at half of [`STRAIN_FULL`], red from it on.
pub fn strain_colour(strain: f64) -> Rgba {
    let t = if strain.is_finite() {
        (strain / STRAIN_FULL).clamp(0.0, 1.0)
    } else {
        1.0
    };
    let lerp = |a: f64, b: f64, s: f64| (a + (b - a) * s).round() as u8;
    let (r, g, b) = if t < 0.5 {
        let s = t * 2.0;
        (
            lerp(40.0, 240.0, s),
            lerp(170.0, 200.0, s),
            lerp(60.0, 30.0, s),
        )
    } else {
        let s = (t - 0.5) * 2.0;
        (
            lerp(240.0, 215.0, s),
            lerp(200.0, 30.0, s),
            lerp(30.0, 30.0, s),
        )
    };
    Rgba([r, g, b, 255])
}

/// The strain of every part edge, as (global vertex a, global vertex b, strain); an edge shared
/// by overlapping parts reports the largest.
pub fn strained_edges(
    grammar: &CompiledGrammar,
    assembly: &AssemblyData,
) -> Vec<(usize, usize, f64)> {
    let mut worst: HashMap<(usize, usize), f64> = HashMap::new();
    let mut order = Vec::new();
    for part in parts_of(grammar, assembly) {
        let Some(state) = part.states.get(part.active) else {
            continue;
        };
        for &[i, j] in &part.edges {
            let (Some(&a), Some(&b)) = (part.vertices.get(i), part.vertices.get(j)) else {
                continue;
            };
            let (Some(ra), Some(rb)) = (state.positions.get(i), state.positions.get(j)) else {
                continue;
            };
            let (Some(pa), Some(pb)) = (assembly.positions.get(a), assembly.positions.get(b))
            else {
                continue;
            };
            let Some(strain) = crate::solver::edge_strain(ra.distance(*rb), pa.distance(*pb))
            else {
                continue;
            };
            let strain = strain.abs();
            if !strain.is_finite() {
                continue;
            }
            let key = (a.min(b), a.max(b));
            let entry = worst.entry(key).or_insert_with(|| {
                order.push(key);
                0.0
            });
            *entry = entry.max(strain);
        }
    }
    order.into_iter().map(|k| (k.0, k.1, worst[&k])).collect()
}

/// The assembly's parts; rebuilt from the grammar when the data carries none (e.g. an assembly
/// written by hand in a test) or when they refer to missing vertices.
fn parts_of(grammar: &CompiledGrammar, assembly: &AssemblyData) -> Vec<clay_dsl::compiled::Part> {
    let valid =
        |p: &clay_dsl::compiled::Part| p.vertices.iter().all(|&v| v < assembly.positions.len());
    if !assembly.parts.is_empty() && assembly.parts.iter().all(valid) {
        return assembly.parts.clone();
    }
    let consistent = assembly
        .instances
        .iter()
        .all(|i| i.piece < grammar.pieces.len())
        && assembly.chains.iter().all(|c| {
            c.rule < grammar.stretch_rules.len()
                && c.instances.iter().all(|&i| i < assembly.instances.len())
        });
    if !consistent {
        return Vec::new();
    }
    grammar.parts(assembly).into_iter().filter(valid).collect()
}

/// World-space bounding box of the meshes and the assembly's vertices.
pub fn bounds(meshes: &[WorldMesh], assembly: &AssemblyData) -> (DVec2, DVec2) {
    points_bounds(meshes, &assembly.positions)
}

/// World-space bounding box of the meshes' drawn corners and the given points, skipping
/// non-finite ones (an empty input gives an inverted box: min +inf, max -inf).
pub fn points_bounds(meshes: &[WorldMesh], positions: &[DVec2]) -> (DVec2, DVec2) {
    let mut min = DVec2::splat(f64::INFINITY);
    let mut max = DVec2::splat(f64::NEG_INFINITY);
    let points = meshes
        .iter()
        .flat_map(|m| {
            m.triangles
                .iter()
                .flatten()
                .map(|&i| m.positions[i as usize])
        })
        .map(|[x, y]| DVec2::new(x as f64, y as f64))
        .chain(positions.iter().copied());
    for p in points.filter(|p| p.is_finite()) {
        min = min.min(p);
        max = max.max(p);
    }
    (min, max)
}

/// A darker shade for outlines.
fn darker(c: Rgba) -> Rgba {
    let [r, g, b, a] = c.0;
    let f = |v: u8| (v as f32 * 0.55) as u8;
    Rgba([f(r), f(g), f(b), a])
}

/// Draws posed meshes (fills, then outlines) through a view.
pub fn draw_meshes(canvas: &mut dyn Canvas, meshes: &[WorldMesh], view: &View, outlines: bool) {
    let px = |m: &WorldMesh| -> Vec<[f32; 2]> {
        m.positions
            .iter()
            .map(|&[x, y]| view.to_pixel(DVec2::new(x as f64, y as f64)))
            .collect()
    };
    for m in meshes {
        let points = px(m);
        // A large mesh is filled by its boundary: the same pixels without every interior edge.
        match (m.triangles.len() >= CONTOUR_MIN_TRIANGLES)
            .then(|| contours(&points, &m.triangles))
            .flatten()
        {
            Some(c) => canvas.fill_contours(&c, m.fill),
            None => canvas.fill_triangles(&points, &m.triangles, m.fill),
        }
    }
    if outlines {
        for m in meshes {
            let p = px(m);
            let segments: Vec<_> = m
                .outline
                .iter()
                .map(|&[a, b]| [p[a as usize], p[b as usize]])
                .collect();
            canvas.stroke_segments(&segments, 1.0, darker(m.fill));
        }
    }
}

/// Draws the requested overlays of an assembly.
pub fn draw_overlays(
    canvas: &mut dyn Canvas,
    grammar: &CompiledGrammar,
    assembly: &AssemblyData,
    view: &View,
    overlays: &Overlays,
) {
    let pos = |v: usize| {
        assembly
            .positions
            .get(v)
            .filter(|p| p.is_finite())
            .map(|p| view.to_pixel(*p))
    };
    if overlays.strain {
        for (a, b, strain) in strained_edges(grammar, assembly) {
            if let (Some(pa), Some(pb)) = (pos(a), pos(b)) {
                canvas.stroke_segments(&[[pa, pb]], 3.0, strain_colour(strain));
            }
        }
        strain_legend(canvas);
    }
    if overlays.part_graph {
        let mut segments = Vec::new();
        let mut seen = std::collections::HashSet::new();
        for part in parts_of(grammar, assembly) {
            for &[i, j] in &part.edges {
                let (Some(&a), Some(&b)) = (part.vertices.get(i), part.vertices.get(j)) else {
                    continue;
                };
                if seen.insert((a.min(b), a.max(b)))
                    && let (Some(pa), Some(pb)) = (pos(a), pos(b))
                {
                    segments.push([pa, pb]);
                }
            }
        }
        canvas.stroke_segments(&segments, 1.0, GRAPH);
        for p in assembly.positions.iter().filter(|p| p.is_finite()) {
            canvas.fill_circle(view.to_pixel(*p), 2.0, GRAPH);
        }
    }
    if overlays.sites {
        draw_instance_sites(canvas, grammar, assembly, view);
    }
    if overlays.states {
        draw_state_labels(canvas, grammar, assembly, view);
    }
    for &v in &overlays.pins {
        if let Some([x, y]) = pos(v) {
            canvas.fill_rect([x - 5.0, y - 5.0], [10.0, 10.0], PIN);
        }
    }
    for &v in &overlays.handles {
        if let Some(p) = pos(v) {
            canvas.fill_circle(p, 7.0, HANDLE);
            canvas.fill_circle(p, 4.0, Rgba([255, 255, 255, 255]));
        }
    }
}

/// Marks a docking site: its vertices as dots joined by a bar in the type colour and, when
/// `out` is given, an arrow from the site centre along it.
pub fn draw_site(canvas: &mut dyn Canvas, points: &[[f32; 2]], out: Option<DVec2>, colour: Rgba) {
    if points.is_empty() {
        return;
    }
    let bars: Vec<_> = points.windows(2).map(|w| [w[0], w[1]]).collect();
    canvas.stroke_segments(&bars, 3.0, colour);
    for p in points {
        canvas.fill_circle(*p, 3.5, colour);
    }
    if let Some(out) = out.filter(|d| d.is_finite()) {
        let n = points.len() as f32;
        let c = [
            points.iter().map(|p| p[0]).sum::<f32>() / n,
            points.iter().map(|p| p[1]).sum::<f32>() / n,
        ];
        arrow(canvas, c, [out.x as f32, -out.y as f32], 16.0, colour);
    }
}

/// An arrow of `length` pixels from `from` along the pixel-space unit direction `dir`.
fn arrow(canvas: &mut dyn Canvas, from: [f32; 2], dir: [f32; 2], length: f32, colour: Rgba) {
    let tip = [from[0] + dir[0] * length, from[1] + dir[1] * length];
    let back = [-dir[0] * 5.0, -dir[1] * 5.0];
    let side = [-dir[1] * 3.5, dir[0] * 3.5];
    let head = [
        [tip[0] + back[0] + side[0], tip[1] + back[1] + side[1]],
        [tip[0] + back[0] - side[0], tip[1] + back[1] - side[1]],
    ];
    canvas.stroke_segments(&[[from, tip]], 2.0, colour);
    canvas.fill_triangles(&[tip, head[0], head[1]], &[[0, 1, 2]], colour);
}

fn draw_instance_sites(
    canvas: &mut dyn Canvas,
    grammar: &CompiledGrammar,
    assembly: &AssemblyData,
    view: &View,
) {
    let docked: std::collections::HashSet<(usize, usize)> = assembly
        .docks
        .iter()
        .flat_map(|d| [(d.a.instance, d.a.site), (d.b.instance, d.b.site)])
        .collect();
    for (ii, inst) in assembly.instances.iter().enumerate() {
        let Some(piece) = grammar.pieces.get(inst.piece) else {
            continue;
        };
        let Some(current) = inst
            .vertices
            .iter()
            .map(|&v| assembly.positions.get(v).copied())
            .collect::<Option<Vec<_>>>()
        else {
            continue;
        };
        for (si, site) in piece.sites.iter().enumerate() {
            let Some(points) = site
                .vertices
                .iter()
                .map(|&v| {
                    current
                        .get(v)
                        .filter(|p| p.is_finite())
                        .map(|p| view.to_pixel(*p))
                })
                .collect::<Option<Vec<_>>>()
            else {
                continue;
            };
            // Docked sites are joints, not open ends: marked, but without an arrow.
            let out = (!docked.contains(&(ii, si)))
                .then(|| drawn_site_out(grammar, inst.piece, inst.state, si, &current))
                .flatten();
            draw_site(canvas, &points, out, site_type_colour(site.site_type));
        }
    }
}

fn draw_state_labels(
    canvas: &mut dyn Canvas,
    grammar: &CompiledGrammar,
    assembly: &AssemblyData,
    view: &View,
) {
    for part in parts_of(grammar, assembly) {
        // Every part with alternatives: a stretch part always has them (`one`, `two`, `three`),
        // so a chain at rest reads `two` at each joint.
        let worth = match part.kind {
            PartKind::Piece { .. } => part.states.len() > 1,
            PartKind::Stretch { .. } => true,
        };
        let Some(state) = part.states.get(part.active).filter(|_| worth) else {
            continue;
        };
        let pts: Vec<DVec2> = part
            .vertices
            .iter()
            .filter_map(|&v| assembly.positions.get(v).copied())
            .collect();
        if pts.is_empty() {
            continue;
        }
        let centre = pts.iter().sum::<DVec2>() / pts.len() as f64;
        if centre.is_finite() {
            label(canvas, view.to_pixel(centre), 12.0, &state.name, true);
        }
    }
}

/// A label on a light plate so it reads over any fill; `centred` centres it on `at`, otherwise
/// `at` is the left end of the baseline.
pub fn label(canvas: &mut dyn Canvas, at: [f32; 2], size: f32, text_: &str, centred: bool) {
    let width = text::measure(text_, size);
    let x = if centred { at[0] - width / 2.0 } else { at[0] };
    let y = if centred { at[1] + size * 0.35 } else { at[1] };
    let pad = size * 0.25;
    canvas.fill_rect(
        [x - pad, y - size * 0.85],
        [width + 2.0 * pad, size * 1.15],
        Rgba([255, 255, 255, 210]),
    );
    canvas.text([x, y], size, INK, text_);
}

/// Where the strain legend's plate sits, in pixels from the picture's top-left corner: `[x, y,
/// width, height]` (a view that fits a model beside it keeps clear of this).
pub const STRAIN_LEGEND: [f32; 4] = [8.0, 8.0, 128.0, 34.0];

fn strain_legend(canvas: &mut dyn Canvas) {
    let [px, py, pw, ph] = STRAIN_LEGEND;
    let (x, y, w) = (px + 4.0, py + 4.0, pw - 8.0);
    canvas.fill_rect([px, py], [pw, ph], Rgba([255, 255, 255, 220]));
    let steps = 24;
    for k in 0..steps {
        let s = STRAIN_FULL * k as f64 / (steps - 1) as f64;
        let step = w / steps as f32;
        canvas.fill_rect(
            [x + k as f32 * step, y],
            [step + 0.5, 8.0],
            strain_colour(s),
        );
    }
    canvas.text([x, y + 22.0], 11.0, INK, "strain 0");
    let end = format!("{STRAIN_FULL}+");
    canvas.text(
        [x + w - text::measure(&end, 11.0), y + 22.0],
        11.0,
        INK,
        &end,
    );
}

/// Draws a whole assembly: posed meshes then overlays, through `view`.
pub fn draw_assembly(
    canvas: &mut dyn Canvas,
    grammar: &CompiledGrammar,
    assembly: &AssemblyData,
    meshes: &[WorldMesh],
    view: &View,
    options: &RenderOptions,
) {
    draw_meshes(canvas, meshes, view, options.outlines);
    draw_overlays(canvas, grammar, assembly, view, &options.overlays);
}

/// Hex `#rrggbb` (and opacity) for SVG attributes.
pub fn hex(c: Rgba) -> (String, f32) {
    let [r, g, b, a] = c.0;
    (format!("#{r:02x}{g:02x}{b:02x}"), a as f32 / 255.0)
}
