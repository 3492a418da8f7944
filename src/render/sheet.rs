//! The grammar sheet: every piece in a row, each of its rest states side by side in a cell
//! labelled `piece / state`, with the piece graph and docking sites (type colour, out arrow).

use clay_dsl::compiled::{CompiledGrammar, Rgba};
use glam::DVec2;
use tiny_skia::Pixmap;

use super::draw::{
    BACKGROUND, Canvas, View, draw_meshes, draw_site, label, points_bounds, site_type_colour,
};
use super::pose::{drawn_site_out, pose_piece};
use super::raster::{MAX_SIDE, PixmapCanvas, RenderError};
use super::svg::SvgCanvas;
use super::tessellate::TessellationCache;
use super::text;

const CELL: DVec2 = DVec2::new(280.0, 230.0);
const LABEL_STRIP: f64 = 26.0;
const HEADER: f64 = 64.0;
const CELL_MARGIN: f64 = 30.0;
const FRAME: Rgba = Rgba([200, 195, 185, 255]);
const EDGE: Rgba = Rgba([90, 90, 110, 150]);
const INK: Rgba = Rgba([30, 30, 40, 255]);

/// Pixel size of the sheet of a grammar.
pub fn sheet_size(grammar: &CompiledGrammar) -> (u32, u32) {
    let columns = grammar
        .pieces
        .iter()
        .map(|p| p.states.len())
        .max()
        .unwrap_or(0)
        .max(1);
    let rows = grammar.pieces.len().max(1);
    let legend = legend_width(grammar) + 24.0;
    let width = (columns as f64 * CELL.x)
        .max(legend as f64)
        .min(MAX_SIDE as f64);
    let height = (HEADER + rows as f64 * CELL.y).min(MAX_SIDE as f64);
    (width as u32, height as u32)
}

fn legend_width(grammar: &CompiledGrammar) -> f32 {
    grammar
        .site_types
        .iter()
        .map(|t| 22.0 + text::measure(&t.name, 13.0) + 16.0)
        .sum::<f32>()
        + 90.0
}

/// Draws the sheet onto a canvas of [`sheet_size`].
pub fn draw_sheet(canvas: &mut dyn Canvas, grammar: &CompiledGrammar) {
    let count = grammar.pieces.len();
    let noun = if count == 1 { "piece" } else { "pieces" };
    let title = format!("{}: {count} {noun}", grammar.source);
    canvas.text([12.0, 24.0], 16.0, INK, &title);
    // Legend: one swatch per site type.
    let mut x = 12.0;
    canvas.text([x, 50.0], 13.0, INK, "site types:");
    x += text::measure("site types:", 13.0) + 10.0;
    for (i, t) in grammar.site_types.iter().enumerate() {
        canvas.fill_circle([x + 6.0, 45.5], 6.0, site_type_colour(i));
        canvas.text([x + 16.0, 50.0], 13.0, INK, &t.name);
        x += 22.0 + text::measure(&t.name, 13.0) + 16.0;
    }
    if grammar.pieces.is_empty() {
        canvas.text([12.0, HEADER as f32 + 30.0], 14.0, INK, "(no pieces)");
    }

    let mut cache = TessellationCache::new();
    for (pi, piece) in grammar.pieces.iter().enumerate() {
        for (si, state) in piece.states.iter().enumerate() {
            let cell_min = DVec2::new(si as f64 * CELL.x, HEADER + pi as f64 * CELL.y);
            let px = |v: DVec2| [v.x as f32, v.y as f32];
            // Cell frame.
            let corners = [
                cell_min,
                cell_min + DVec2::X * CELL.x,
                cell_min + CELL,
                cell_min + DVec2::Y * CELL.y,
            ];
            let frame: Vec<_> = (0..4)
                .map(|k| [px(corners[k]), px(corners[(k + 1) % 4])])
                .collect();
            canvas.stroke_segments(&frame, 1.0, FRAME);
            label(
                canvas,
                px(cell_min + DVec2::new(8.0, 18.0)),
                13.0,
                &format!("{} / {}", piece.name, state.name),
                false,
            );

            let current = &state.positions;
            let meshes = pose_piece(grammar, pi, si, current, &mut cache);
            let (min, max) = points_bounds(&meshes, current);
            let view = View::fit(
                min,
                max,
                cell_min + DVec2::Y * LABEL_STRIP,
                CELL - DVec2::Y * LABEL_STRIP,
                CELL_MARGIN,
            );
            draw_meshes(canvas, &meshes, &view, true);
            let pos = |v: usize| {
                current
                    .get(v)
                    .filter(|p| p.is_finite())
                    .map(|p| view.to_pixel(*p))
            };
            let edges: Vec<_> = piece
                .edges
                .iter()
                .filter_map(|&[a, b]| Some([pos(a)?, pos(b)?]))
                .collect();
            canvas.stroke_segments(&edges, 1.0, EDGE);
            for v in 0..current.len() {
                if let Some(p) = pos(v) {
                    canvas.fill_circle(p, 2.0, EDGE);
                }
            }
            for (k, site) in piece.sites.iter().enumerate() {
                let Some(points) = site
                    .vertices
                    .iter()
                    .map(|&v| pos(v))
                    .collect::<Option<Vec<_>>>()
                else {
                    continue;
                };
                draw_site(
                    canvas,
                    &points,
                    drawn_site_out(grammar, pi, si, k, current),
                    site_type_colour(site.site_type),
                );
            }
        }
    }
}

/// The sheet as a pixmap.
pub fn sheet_pixmap(grammar: &CompiledGrammar) -> Result<Pixmap, RenderError> {
    let (w, h) = sheet_size(grammar);
    let mut canvas = PixmapCanvas::new(w, h, BACKGROUND)?;
    draw_sheet(&mut canvas, grammar);
    Ok(canvas.pixmap)
}

/// The sheet as PNG bytes.
pub fn sheet_png(grammar: &CompiledGrammar) -> Result<Vec<u8>, RenderError> {
    sheet_pixmap(grammar)?
        .encode_png()
        .map_err(|e| RenderError::Encode(e.to_string()))
}

/// The sheet as an SVG document.
pub fn sheet_svg(grammar: &CompiledGrammar) -> String {
    let (w, h) = sheet_size(grammar);
    let mut canvas = SvgCanvas::new(w, h, BACKGROUND);
    draw_sheet(&mut canvas, grammar);
    canvas.finish()
}
