//! SVG drawing -> [`Drawing`]: every path (rectangles, polygons and lines included, as usvg
//! turns them into paths) becomes polylines in metres with y up.
//!
//! Units: coordinates are usvg's, i.e. the SVG's user units after every transform, mapped
//! through the `viewBox` to the document size in CSS pixels (the two agree when the document
//! has no `viewBox`, or one equal to its `width`/`height`). One such unit is `scale` metres
//! (`clayc author` defaults to 0.01: one unit is one centimetre). SVG's y points down; the
//! drawing is flipped so y points up (north). Curves are flattened into [`CURVE_SEGMENTS`]
//! straight pieces each.

use glam::DVec2;

use super::drawing::{AuthorError, Drawing, Polyline};
use super::graph::{MAX_COORDINATE, metres};

/// Straight segments per Bezier curve segment.
pub const CURVE_SEGMENTS: usize = 8;

/// Parses SVG text into a drawing, one unit being `scale` metres.
pub fn drawing_from_svg(text: &str, scale: f64) -> Result<Drawing, AuthorError> {
    if !(scale.is_finite() && scale > 0.0) {
        return Err(AuthorError(format!(
            "the scale must be a positive number of metres per SVG unit, found {scale}"
        )));
    }
    let tree = usvg::Tree::from_str(text, &usvg::Options::default())
        .map_err(|e| AuthorError(format!("not a readable SVG: {e}")))?;
    let mut drawing = Drawing::default();
    collect(tree.root(), scale, &mut drawing)?;
    if drawing.polylines.is_empty() {
        return Err(AuthorError("the SVG has no paths".into()));
    }
    Ok(drawing)
}

/// The line (from 1) of the first element of SVG `text` whose `id` attribute is `id`, for
/// pointing at a path an error names.
pub fn line_of_id(text: &str, id: &str) -> Option<usize> {
    ["\"", "'"].iter().find_map(|q| {
        let needle = format!("id={q}{id}{q}");
        text.match_indices(&needle)
            .find(|(at, _)| {
                text[..*at]
                    .chars()
                    .next_back()
                    .is_some_and(char::is_whitespace)
            })
            .map(|(at, _)| text[..at].matches('\n').count() + 1)
    })
}

fn collect(group: &usvg::Group, scale: f64, drawing: &mut Drawing) -> Result<(), AuthorError> {
    for node in group.children() {
        match node {
            usvg::Node::Group(g) => collect(g, scale, drawing)?,
            usvg::Node::Path(p) => add_path(p, scale, drawing)?,
            _ => {}
        }
    }
    Ok(())
}

/// Adds a path's polylines, or refuses it at its first point beyond [`MAX_COORDINATE`] (as
/// the graph would) before flattening on: usvg gives a circle of radius 1e38 units over three
/// million curve segments, flattened 26 million points and half a gigabyte, only for the graph
/// to refuse the first (issue 47).
fn add_path(path: &usvg::Path, scale: f64, drawing: &mut Drawing) -> Result<(), AuthorError> {
    let ts = path.abs_transform();
    let to_metres = |pt: usvg::tiny_skia_path::Point| {
        let mut pt = pt;
        ts.map_point(&mut pt);
        DVec2::new(f64::from(pt.x) * scale, -f64::from(pt.y) * scale)
    };
    let within_reach = |p: DVec2| {
        if p.is_finite() && p.abs().max_element() <= MAX_COORDINATE {
            return Ok(p);
        }
        let name = match path.id() {
            "" => "a path without an id".to_string(),
            id => format!("path `{id}`"),
        };
        Err(AuthorError(format!(
            "{name} has a point at {}, beyond the {MAX_COORDINATE:e} m a drawing may reach; check its coordinates and the scale",
            metres(p)
        )))
    };
    let fill = path.fill().and_then(|f| match f.paint() {
        usvg::Paint::Color(c) => Some([c.red, c.green, c.blue]),
        _ => None,
    });
    let name = (!path.id().is_empty()).then(|| path.id().to_string());
    let mut current: Vec<DVec2> = Vec::new();
    let mut last = DVec2::ZERO;
    let flush = |points: &mut Vec<DVec2>, closed: bool, drawing: &mut Drawing| {
        if points.len() >= 2 {
            drawing.polylines.push(Polyline {
                points: std::mem::take(points),
                closed,
                fill,
                name: name.clone(),
            });
        }
        points.clear();
    };
    for seg in path.data().segments() {
        use usvg::tiny_skia_path::PathSegment as S;
        match seg {
            S::MoveTo(p) => {
                flush(&mut current, false, drawing);
                last = within_reach(to_metres(p))?;
                current.push(last);
            }
            S::LineTo(p) => {
                last = within_reach(to_metres(p))?;
                current.push(last);
            }
            S::QuadTo(c, p) => {
                let (c, p) = (to_metres(c), to_metres(p));
                for k in 1..=CURVE_SEGMENTS {
                    let t = k as f64 / CURVE_SEGMENTS as f64;
                    let q = last * (1.0 - t) * (1.0 - t) + c * 2.0 * t * (1.0 - t) + p * t * t;
                    current.push(within_reach(q)?);
                }
                last = p;
            }
            S::CubicTo(c1, c2, p) => {
                let (c1, c2, p) = (to_metres(c1), to_metres(c2), to_metres(p));
                for k in 1..=CURVE_SEGMENTS {
                    let t = k as f64 / CURVE_SEGMENTS as f64;
                    let u = 1.0 - t;
                    let q = last * u * u * u
                        + c1 * 3.0 * u * u * t
                        + c2 * 3.0 * u * t * t
                        + p * t * t * t;
                    current.push(within_reach(q)?);
                }
                last = p;
            }
            S::Close => flush(&mut current, true, drawing),
        }
    }
    flush(&mut current, false, drawing);
    Ok(())
}
