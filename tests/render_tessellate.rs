//! Tessellation of proxy geometry: exact areas for concave polygons with holes, and no panic or
//! non-finite output on arbitrary (degenerate, self-crossing) input.

use clay::tessellate_polygon;
use clay::testing::{polygon_area, tessellate_polyline, tessellate_proxy};

fn polygon_area_of(ring: &[glam::DVec2]) -> f64 {
    polygon_area(ring.iter().copied())
}
use clay_dsl::compiled::{Binding, Proxy, ProxyShape, Rgba};
use glam::DVec2;
use proptest::prelude::*;

fn triangles_area(v: &[DVec2], t: &[[u32; 3]]) -> f64 {
    t.iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| v[i as usize]);
            (b - a).perp_dot(c - a) / 2.0
        })
        .sum()
}

fn pts(p: &[(f64, f64)]) -> Vec<DVec2> {
    p.iter().map(|&(x, y)| DVec2::new(x, y)).collect()
}

#[test]
fn concave_polygon_with_hole_has_the_shoelace_area() {
    // A "C"-like concave outline (clockwise, to check orientation does not matter) with a
    // square hole in its thick left bar.
    let outer = pts(&[
        (0.0, 0.0),
        (0.0, 3.0),
        (3.0, 3.0),
        (3.0, 2.2),
        (1.4, 2.2),
        (1.4, 0.8),
        (3.0, 0.8),
        (3.0, 0.0),
    ]);
    let hole = pts(&[(0.3, 1.1), (1.1, 1.1), (1.1, 1.9), (0.3, 1.9)]);
    let expected = polygon_area_of(&outer).abs() - polygon_area_of(&hole).abs();
    let (v, t) = tessellate_polygon(&outer, std::slice::from_ref(&hole)).unwrap();
    let area = triangles_area(&v, &t);
    assert!(
        (area - expected).abs() < 1e-9,
        "triangles {area} vs shoelace {expected}"
    );
    // Every triangle counter-clockwise.
    for tri in &t {
        let [a, b, c] = tri.map(|i| v[i as usize]);
        assert!((b - a).perp_dot(c - a) > 0.0);
    }
}

#[test]
fn two_holes_and_a_star_outline() {
    let outer: Vec<DVec2> = (0..10)
        .map(|k| {
            let r = if k % 2 == 0 { 5.0 } else { 2.5 };
            DVec2::from_angle(k as f64 * std::f64::consts::TAU / 10.0) * r
        })
        .collect();
    let holes = vec![
        pts(&[(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]),
        pts(&[(1.0, 0.8), (1.6, 0.8), (1.3, 1.4)]),
    ];
    let expected =
        polygon_area_of(&outer) - holes.iter().map(|h| polygon_area_of(h).abs()).sum::<f64>();
    let (v, t) = tessellate_polygon(&outer, &holes).unwrap();
    assert!((triangles_area(&v, &t) - expected).abs() < 1e-9);
}

#[test]
fn mitred_polyline_corner_has_no_gap_or_overlap() {
    // An L of two 2 m legs, 0.2 m wide: area = 2 * 2 * 0.2 exactly (miter fills the corner
    // square, the inner side meets at one point).
    let (v, t) = tessellate_polyline(&pts(&[(0.0, 0.0), (2.0, 0.0), (2.0, 2.0)]), 0.2).unwrap();
    assert!(
        (triangles_area(&v, &t) - 0.8).abs() < 1e-9,
        "area {}",
        triangles_area(&v, &t)
    );
}

#[test]
fn sharp_polyline_turn_falls_back_to_a_bevel() {
    // A hairpin: the miter would be far longer than the limit; the result stays near the line.
    let (v, _) = tessellate_polyline(&pts(&[(0.0, 0.0), (2.0, 0.0), (0.0, 0.05)]), 0.2).unwrap();
    assert!(v.iter().all(|p| p.x < 2.3), "a vertex shoots out: {v:?}");
}

#[test]
fn self_touching_polygon_does_not_panic() {
    // A bow tie (crossing) and a ring touching itself at a point.
    let bow = pts(&[(0.0, 0.0), (2.0, 2.0), (2.0, 0.0), (0.0, 2.0)]);
    if let Some((v, t)) = tessellate_polygon(&bow, &[]) {
        assert!(v.iter().all(|p| p.is_finite()) && !t.is_empty());
    }
    let touching = pts(&[
        (0.0, 0.0),
        (2.0, 0.0),
        (1.0, 1.0),
        (2.0, 2.0),
        (0.0, 2.0),
        (1.0, 1.0),
    ]);
    let _ = tessellate_polygon(&touching, &[]);
    let duplicate_hole = vec![pts(&[(0.0, 0.0), (2.0, 0.0), (1.0, 1.0)])];
    let _ = tessellate_polygon(&bow, &duplicate_hole);
}

/// A star of `n` points (radii alternating 1 and 0.8) around `centre`, counter-clockwise.
fn star(n: usize, centre: DVec2, scale: f64) -> Vec<DVec2> {
    (0..n)
        .map(|k| {
            let r = if k % 2 == 0 { 1.0 } else { 0.8 };
            centre + DVec2::from_angle(k as f64 * std::f64::consts::TAU / n as f64) * r * scale
        })
        .collect()
}

#[test]
fn a_20k_point_star_with_holes_covers_its_exact_area() {
    let outer = star(20_000, DVec2::ZERO, 10.0);
    // Three holes: two small stars and a 4,000-point circle, clockwise as authors often draw them.
    let mut circle: Vec<DVec2> = (0..4000)
        .map(|k| {
            DVec2::new(-3.0, 2.0)
                + DVec2::from_angle(k as f64 * std::f64::consts::TAU / 4000.0) * 1.5
        })
        .collect();
    circle.reverse();
    let holes = vec![
        star(1000, DVec2::new(3.0, 3.0), 1.0),
        star(2000, DVec2::new(2.0, -4.0), 2.0),
        circle,
    ];
    let expected =
        polygon_area_of(&outer) - holes.iter().map(|h| polygon_area_of(h).abs()).sum::<f64>();
    let (v, t) = tessellate_polygon(&outer, &holes).unwrap();
    let area = triangles_area(&v, &t);
    assert!(
        ((area - expected) / expected).abs() < 1e-9,
        "triangles {area} vs shoelace {expected}"
    );
    for tri in &t {
        let [a, b, c] = tri.map(|i| v[i as usize]);
        assert!((b - a).perp_dot(c - a) > 0.0);
    }
}

#[test]
fn a_hole_sharing_the_outer_edges_is_cut_out() {
    // The hole's corner square shares two half edges with the outer square: the ring segments
    // over them count twice, so the region inside both is outside by the even-odd rule.
    let outer = pts(&[(0.0, 0.0), (3.0, 0.0), (3.0, 3.0), (0.0, 3.0)]);
    let hole = pts(&[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]);
    let (v, t) = tessellate_polygon(&outer, &[hole]).unwrap();
    assert!((triangles_area(&v, &t) - 8.0).abs() < 1e-12);
}

fn proxy(shape: ProxyShape) -> Proxy {
    Proxy {
        shape,
        fill: Rgba([1, 2, 3, 255]),
        binding: Binding::Rigid,
        extrude: None,
    }
}

proptest! {
    #[test]
    fn arbitrary_polygons_never_panic_and_stay_finite(
        outer in prop::collection::vec((-3i32..3, -3i32..3), 0..9),
        hole in prop::collection::vec((-3i32..3, -3i32..3), 0..6),
    ) {
        // Small integer grids produce many duplicates, collinear runs and crossings.
        let outer: Vec<DVec2> = outer.iter().map(|&(x, y)| DVec2::new(x as f64, y as f64)).collect();
        let hole: Vec<DVec2> = hole.iter().map(|&(x, y)| DVec2::new(x as f64 * 0.5, y as f64 * 0.5)).collect();
        if let Some(mesh) = tessellate_proxy(&proxy(ProxyShape::Polygon { outer, holes: vec![hole] })) {
            prop_assert!(mesh.vertices.iter().all(|p| p.is_finite()));
            prop_assert!(mesh.triangles.iter().flatten().all(|&i| (i as usize) < mesh.vertices.len()));
            prop_assert!(mesh.area() > 0.0);
        }
    }

    #[test]
    fn star_shaped_polygons_with_a_hole_have_the_shoelace_area(
        radii in prop::collection::vec(0.5f64..2.0, 3..200),
        hole_share in 0.1f64..0.9,
        hole_points in 3usize..40,
    ) {
        // Points at increasing angles with any radius make a simple polygon. It holds the disk
        // of radius 0.5 cos(pi / n) (the smallest radius times the cosine of half the angle
        // between neighbours); the hole is a regular polygon inside that disk.
        let n = radii.len();
        let hole_radius = hole_share * 0.5 * (std::f64::consts::PI / n as f64).cos();
        let outer: Vec<DVec2> = radii
            .iter()
            .enumerate()
            .map(|(k, &r)| DVec2::from_angle(k as f64 * std::f64::consts::TAU / n as f64) * r)
            .collect();
        let hole: Vec<DVec2> = (0..hole_points)
            .map(|k| DVec2::from_angle(k as f64 * std::f64::consts::TAU / hole_points as f64) * hole_radius)
            .collect();
        let expected = polygon_area_of(&outer) - polygon_area_of(&hole);
        let (v, t) = tessellate_polygon(&outer, &[hole]).unwrap();
        let area = triangles_area(&v, &t);
        prop_assert!(((area - expected) / expected).abs() < 1e-9, "{} vs {}", area, expected);
    }

    #[test]
    fn arbitrary_polylines_never_panic_and_stay_finite(
        points in prop::collection::vec((-3i32..3, -3i32..3), 0..8),
        width in -0.5f64..1.0,
    ) {
        let points: Vec<DVec2> = points.iter().map(|&(x, y)| DVec2::new(x as f64, y as f64)).collect();
        if let Some(mesh) = tessellate_proxy(&proxy(ProxyShape::Polyline { points, width })) {
            prop_assert!(width > 0.0);
            prop_assert!(mesh.vertices.iter().all(|p| p.is_finite()));
            prop_assert!(mesh.triangles.iter().flatten().all(|&i| (i as usize) < mesh.vertices.len()));
        }
    }
}
