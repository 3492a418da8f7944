//! Rendering assemblies built in code: pixels land where the view says, stretched skinned walls
//! have no holes, rigid connectors keep their area when turned, output is deterministic and
//! never carries NaN.

use clay::testing::{pose_assembly, render_pixmap};
use clay::{
    Overlays, RenderOptions, TessellationCache, View, render_png, render_svg, sheet_png, sheet_svg,
};
use clay_dsl::compiled::{
    AssemblyData, Binding, CompiledGrammar, FORMAT_VERSION, Instance, Piece, Proxy, ProxyShape,
    RestState, Rgba, Site, SiteType, SolverParams,
};
use glam::DVec2;

const BG: Rgba = Rgba([255, 255, 255, 255]);
const RED: Rgba = Rgba([200, 0, 0, 255]);
const BLACK: Rgba = Rgba([0, 0, 0, 255]);

fn grammar(pieces: Vec<Piece>) -> CompiledGrammar {
    CompiledGrammar {
        format_version: FORMAT_VERSION,
        source: "test.clay".into(),
        solver: SolverParams::default(),
        params: Vec::new(),
        site_types: vec![SiteType {
            name: "joint".into(),
            docks_with: vec![0],
        }],
        pieces,
        stretch_rules: vec![],
        merge_rules: vec![],
        cut_rules: vec![],
        assembly: AssemblyData {
            positions: vec![],
            instances: vec![],
            docks: vec![],
            chains: vec![],
            parts: vec![],
            next_id: 0,
        },
    }
}

fn polygon(outer: &[(f64, f64)], fill: Rgba, binding: Binding) -> Proxy {
    Proxy {
        shape: ProxyShape::Polygon {
            outer: outer.iter().map(|&(x, y)| DVec2::new(x, y)).collect(),
            holes: vec![],
        },
        fill,
        binding,
        extrude: None,
    }
}

/// A piece whose vertices are the corners of its one polygon.
fn piece(name: &str, corners: &[(f64, f64)], fill: Rgba, binding: Binding) -> Piece {
    let n = corners.len();
    Piece {
        name: name.into(),
        vertices: (0..n).map(|i| format!("v{i}")).collect(),
        edges: (0..n).map(|i| [i, (i + 1) % n]).collect(),
        sites: vec![],
        states: vec![RestState {
            name: "base".into(),
            positions: corners.iter().map(|&(x, y)| DVec2::new(x, y)).collect(),
            geometry: vec![polygon(corners, fill, binding)],
            geometry_frame: 0,
        }],
        axis: None,
    }
}

/// A 1 x 0.5 brick whose geometry covers it entirely, stretching between west and east sites.
fn brick(binding: Binding) -> Piece {
    let mut p = piece(
        "brick",
        &[(0.0, 0.0), (1.0, 0.0), (1.0, 0.5), (0.0, 0.5)],
        RED,
        binding,
    );
    p.sites = vec![
        Site {
            name: "west".into(),
            site_type: 0,
            vertices: vec![3, 0],
            out: DVec2::NEG_X,
        },
        Site {
            name: "east".into(),
            site_type: 0,
            vertices: vec![1, 2],
            out: DVec2::X,
        },
    ];
    p.axis = Some([0, 1]);
    p
}

fn assembly(positions: Vec<DVec2>, instances: Vec<(usize, Vec<usize>)>) -> AssemblyData {
    let instances = instances
        .into_iter()
        .enumerate()
        .map(|(i, (piece, vertices))| Instance {
            id: i as u64,
            name: format!("i{i}"),
            piece,
            vertices,
            state: 0,
        })
        .collect::<Vec<_>>();
    AssemblyData {
        positions,
        next_id: instances.len() as u64,
        instances,
        docks: vec![],
        chains: vec![],
        parts: vec![],
    }
}

/// A wall of `n` bricks along x; column k has vertices 2k (bottom) and 2k + 1 (top).
fn wall(n: usize) -> AssemblyData {
    let positions = (0..=n)
        .flat_map(|k| [DVec2::new(k as f64, 0.0), DVec2::new(k as f64, 0.5)])
        .collect();
    let instances = (0..n)
        .map(|k| (0, vec![2 * k, 2 * k + 2, 2 * k + 3, 2 * k + 1]))
        .collect();
    assembly(positions, instances)
}

fn options(width: u32, height: u32, view: View) -> RenderOptions {
    RenderOptions {
        width,
        height,
        background: BG,
        outlines: false,
        view: Some(view),
        ..RenderOptions::default()
    }
}

fn pixel(p: &tiny_skia::Pixmap, x: u32, y: u32) -> [u8; 4] {
    let c = p.pixel(x, y).unwrap().demultiply();
    [c.red(), c.green(), c.blue(), c.alpha()]
}

#[test]
fn unit_square_lands_on_the_expected_pixels() {
    let g = grammar(vec![piece(
        "sq",
        &[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)],
        RED,
        Binding::Rigid,
    )]);
    let a = assembly(
        pts(&[(2.0, 3.0), (3.0, 3.0), (3.0, 4.0), (2.0, 4.0)]),
        vec![(0, vec![0, 1, 2, 3])],
    );
    // 10 px per metre, world (0, 0) at pixel (0, 100): the square spans x 20..30, y 60..70.
    let view = View {
        scale: 10.0,
        world_origin: DVec2::ZERO,
        pixel_origin: DVec2::new(0.0, 100.0),
    };
    let img = render_pixmap(
        &g,
        &a,
        &options(100, 100, view),
        &mut TessellationCache::new(),
    )
    .unwrap();
    for y in 0..100 {
        for x in 0..100 {
            let c = pixel(&img, x, y);
            let inside = (20..30).contains(&x) && (60..70).contains(&y);
            let expected = if inside { RED.0 } else { BG.0 };
            assert_eq!(c, expected, "pixel ({x}, {y})");
        }
    }
}

fn pts(p: &[(f64, f64)]) -> Vec<DVec2> {
    p.iter().map(|&(x, y)| DVec2::new(x, y)).collect()
}

/// Background pixels along the wall's centre line (y = 0.25 m) between x0 and x1 metres.
fn holes_on_centre_line(g: &CompiledGrammar, a: &AssemblyData, x0: f64, x1: f64) -> usize {
    let view = View {
        scale: 40.0,
        world_origin: DVec2::ZERO,
        pixel_origin: DVec2::new(20.0, 60.0),
    };
    let img = render_pixmap(
        g,
        a,
        &options(560, 100, view),
        &mut TessellationCache::new(),
    )
    .unwrap();
    let y = view.to_pixel(DVec2::new(0.0, 0.25))[1] as u32;
    let (px0, px1) = (
        view.to_pixel(DVec2::new(x0, 0.0))[0] as u32,
        view.to_pixel(DVec2::new(x1, 0.0))[0] as u32,
    );
    (px0 + 1..px1 - 1)
        .filter(|&x| pixel(&img, x, y) == BG.0)
        .count()
}

#[test]
fn stretched_skinned_wall_has_no_hole_on_its_centre_line() {
    let g = grammar(vec![brick(Binding::Skinned)]);
    let mut a = wall(8);
    // The east handle drags the end column to 1.5x the wall's length; nothing else moves.
    a.positions[16].x = 12.0;
    a.positions[17].x = 12.0;
    assert_eq!(holes_on_centre_line(&g, &a, 0.0, 12.0), 0);
    // And with every column spread to 1.5x (an evenly stretched wall).
    let mut even = wall(8);
    for p in &mut even.positions {
        p.x *= 1.5;
    }
    assert_eq!(holes_on_centre_line(&g, &even, 0.0, 12.0), 0);
}

#[test]
fn stretched_rigid_wall_does_show_the_gap() {
    // The same drag with rigid geometry leaves the last brick's gap open: this is what skinning
    // is for, and it shows the hole count above can fail.
    let g = grammar(vec![brick(Binding::Rigid)]);
    let mut a = wall(8);
    a.positions[16].x = 12.0;
    a.positions[17].x = 12.0;
    assert!(holes_on_centre_line(&g, &a, 0.0, 12.0) > 100);
}

/// Summed ink coverage (black on white) of a render.
fn coverage(img: &tiny_skia::Pixmap) -> f64 {
    img.pixels()
        .iter()
        .map(|p| (255 - p.demultiply().red()) as f64 / 255.0)
        .sum()
}

#[test]
fn rotated_rigid_connector_keeps_its_area() {
    // A plus-shaped junction, 3 m across, arms 1 m wide: 5 m^2.
    let plus = [
        (-0.5, -1.5),
        (0.5, -1.5),
        (0.5, -0.5),
        (1.5, -0.5),
        (1.5, 0.5),
        (0.5, 0.5),
        (0.5, 1.5),
        (-0.5, 1.5),
        (-0.5, 0.5),
        (-1.5, 0.5),
        (-1.5, -0.5),
        (-0.5, -0.5),
    ];
    let g = grammar(vec![piece("junction", &plus, BLACK, Binding::Rigid)]);
    let view = View {
        scale: 30.0,
        world_origin: DVec2::ZERO,
        pixel_origin: DVec2::new(100.0, 100.0),
    };
    let render = |turn: f64| {
        let rot = DVec2::from_angle(turn.to_radians());
        let positions = plus
            .iter()
            .map(|&(x, y)| rot.rotate(DVec2::new(x, y)) + DVec2::new(0.2, 0.1))
            .collect();
        let a = assembly(positions, vec![(0, (0..12).collect())]);
        render_pixmap(
            &g,
            &a,
            &options(200, 200, view),
            &mut TessellationCache::new(),
        )
        .unwrap()
    };
    let rest = coverage(&render(0.0));
    let expected = 5.0 * 30.0 * 30.0;
    assert!(
        (rest - expected).abs() / expected < 0.01,
        "rest coverage {rest} vs {expected}"
    );
    for turn in [17.0, 30.0, 45.0, 128.0] {
        let turned = coverage(&render(turn));
        assert!(
            (turned - rest).abs() / rest < 0.01,
            "{turn} deg: {turned} vs {rest}"
        );
    }
}

fn busy_scene() -> (CompiledGrammar, AssemblyData, RenderOptions) {
    let g = grammar(vec![brick(Binding::Skinned)]);
    let mut a = wall(5);
    a.positions[10].x = 7.0;
    a.positions[11] = DVec2::new(7.2, 0.8);
    let overlays = Overlays {
        part_graph: true,
        sites: true,
        strain: true,
        states: true,
        handles: vec![10, 11],
        pins: vec![0, 1],
    };
    let options = RenderOptions {
        width: 320,
        height: 200,
        overlays,
        ..RenderOptions::default()
    };
    (g, a, options)
}

#[test]
fn rendering_is_deterministic() {
    let (g, a, o) = busy_scene();
    let first = render_png(&g, &a, &o).unwrap();
    let second = render_png(&g, &a, &o).unwrap();
    assert_eq!(first, second);
    assert_eq!(render_svg(&g, &a, &o), render_svg(&g, &a, &o));
    assert_eq!(sheet_png(&g).unwrap(), sheet_png(&g).unwrap());
    assert_eq!(sheet_svg(&g), sheet_svg(&g));
}

#[test]
fn non_finite_positions_reach_no_output() {
    let (g, mut a, o) = busy_scene();
    a.positions[4] = DVec2::new(f64::NAN, 0.0);
    a.positions[5] = DVec2::new(f64::INFINITY, 1.0);
    let meshes = pose_assembly(&g, &a, &mut TessellationCache::new());
    assert!(
        meshes
            .iter()
            .flat_map(|m| &m.positions)
            .flatten()
            .all(|v| v.is_finite())
    );
    // Instances touching the broken vertices are skipped, the others still drawn.
    assert!(!meshes.is_empty());
    let svg = render_svg(&g, &a, &o);
    assert!(!svg.contains("NaN") && !svg.contains("inf"), "{svg}");
    render_png(&g, &a, &o).unwrap();
}

#[test]
fn broken_indices_do_not_panic() {
    let (g, mut a, o) = busy_scene();
    a.instances[0].vertices[0] = 999;
    a.instances[1].piece = 7;
    a.instances[2].state = 3;
    let mut opts = o.clone();
    opts.overlays.handles.push(12345);
    render_png(&g, &a, &opts).unwrap();
    render_svg(&g, &a, &opts);
}

#[test]
fn svg_has_one_filled_path_per_mesh() {
    let (g, a, mut o) = busy_scene();
    o.overlays = Overlays::default();
    o.outlines = false;
    let svg = render_svg(&g, &a, &o);
    let meshes = pose_assembly(&g, &a, &mut TessellationCache::new());
    assert_eq!(svg.matches("<path").count(), meshes.len());
}

#[test]
fn a_large_mesh_filled_by_its_contours_looks_as_filled_by_its_triangles() {
    use clay::Canvas;
    use clay::testing::PixmapCanvas;
    // A 20,000-point star with a hole, about 300 px across: far above the contour threshold.
    let ring = |n: usize, centre: DVec2, scale: f64| -> Vec<DVec2> {
        (0..n)
            .map(|k| {
                let r = if k % 2 == 0 { 1.0 } else { 0.8 };
                centre + DVec2::from_angle(k as f64 * std::f64::consts::TAU / n as f64) * r * scale
            })
            .collect()
    };
    let outer = ring(20_000, DVec2::splat(160.0), 150.0);
    let hole = ring(600, DVec2::new(120.0, 170.0), 40.0);
    let (v, t) = clay::tessellate_polygon(&outer, &[hole]).unwrap();
    assert!(t.len() > clay::testing::CONTOUR_MIN_TRIANGLES);
    let points: Vec<[f32; 2]> = v.iter().map(|p| [p.x as f32, p.y as f32]).collect();
    let contours = clay::testing::contours(&points, &t).unwrap();
    assert_eq!(contours.len(), 2, "the outer ring and the hole");
    let mut by_triangles = PixmapCanvas::new(320, 320, BG).unwrap();
    by_triangles.fill_triangles(&points, &t, RED);
    let mut by_contours = PixmapCanvas::new(320, 320, BG).unwrap();
    by_contours.fill_contours(&contours, RED);
    let (a, b) = (by_triangles.pixmap, by_contours.pixmap);
    let mut differing = 0;
    for (p, q) in a.pixels().iter().zip(b.pixels()) {
        let (p, q) = (p.demultiply(), q.demultiply());
        let gap = [
            p.red().abs_diff(q.red()),
            p.green().abs_diff(q.green()),
            p.blue().abs_diff(q.blue()),
        ];
        // Anti-aliasing may round an edge pixel differently, never more than a few levels.
        assert!(gap.iter().all(|&g| g <= 8), "{p:?} vs {q:?}");
        differing += usize::from(gap.iter().any(|&g| g > 0));
    }
    // Only edge pixels may differ, a few of the star's rim of about 2,000.
    assert!(differing < 100, "{differing} pixels differ");
    // The inside is filled (the centre) and the hole is not.
    let centre = pixel(&a, 200, 160);
    assert_eq!(pixel(&b, 200, 160), centre);
    assert_eq!(centre, RED.0);
    assert_eq!(pixel(&b, 120, 170), BG.0);
}
