//! Derived rest states (`state NAME bend ANGLE`, `state NAME mirror OTHER`): what they compile
//! to, and the one error each mistake gives.

use clay_dsl::compiled::{CompiledGrammar, Piece, ProxyShape, RestState};
use clay_dsl::{CompileOptions, Diagnostics, compile, render};
use glam::DVec2;

/// A 1 m wide, 2 m long ladder along x with its axis; `STATES` is replaced by the test's states.
const ROAD: &str = "
site type lane
piece road {
    vertex s0 (0, -0.5)
    vertex s1 (1, -0.5)
    vertex s2 (2, -0.5)
    vertex n0 (0, 0.5)
    vertex n1 (1, 0.5)
    vertex n2 (2, 0.5)
    edges s0-s1-s2-n2-n1-n0-s0, n1-s1, s0-n1, s1-n2
    site west: lane [n0, s0] out (-1, 0)
    site east: lane [s2, n2] out (1, 0)
    AXIS
    polygon skinned fill #4b4f56 {
        (0, -0.5) (2, -0.5) (2, 0.5) (0, 0.5)
    }
    polyline skinned width 0.05 fill #e8e8e8 {
        (-0.5, 0.4) (2.5, 0.4)
    }
    STATES
}
model {
    street = chain road x 2 along west -> east
}
";

fn road(states: &str) -> String {
    ROAD.replace("AXIS", "axis west -> east")
        .replace("STATES", states)
}

fn ok(src: &str) -> CompiledGrammar {
    match compile(src, "t.clay", &CompileOptions::default()) {
        Ok(c) => c.grammar,
        Err(d) => panic!("{}", render(&d, src, "t.clay", false)),
    }
}

fn errors(src: &str) -> Diagnostics {
    compile(src, "t.clay", &CompileOptions::default()).expect_err("expected errors")
}

/// The codes of the errors, in order, and the rendered text for messages.
fn codes(src: &str) -> (Vec<String>, String) {
    let d = errors(src);
    (
        d.iter().map(|x| x.code.to_string()).collect(),
        render(&d, src, "t.clay", false),
    )
}

fn state<'g>(p: &'g Piece, name: &str) -> &'g RestState {
    p.states.iter().find(|s| s.name == name).unwrap()
}

fn pos(p: &Piece, state_name: &str, v: &str) -> DVec2 {
    let i = p.vertices.iter().position(|x| x == v).unwrap();
    state(p, state_name).positions[i]
}

fn signed_area(ring: &[DVec2]) -> f64 {
    (0..ring.len())
        .map(|i| ring[i].perp_dot(ring[(i + 1) % ring.len()]))
        .sum::<f64>()
        / 2.0
}

fn outer(s: &RestState, k: usize) -> &[DVec2] {
    match &s.geometry[k].shape {
        ProxyShape::Polygon { outer, .. } => outer,
        ProxyShape::Polyline { points, .. } | ProxyShape::Mesh { points, .. } => points,
    }
}

#[test]
fn a_quarter_bend_lays_the_ladder_on_an_arc() {
    let g = ok(&road("state left bend 90"));
    let p = &g.pieces[0];
    let r = 4.0 / std::f64::consts::PI;
    for (v, at) in [
        ("s0", DVec2::new(0.0, -0.5)),
        ("n0", DVec2::new(0.0, 0.5)),
        ("s2", DVec2::new(r + 0.5, r)),
        ("n2", DVec2::new(r - 0.5, r)),
        // Half way: at 45 degrees round the centre (0, r), 0.5 m outside the arc.
        (
            "s1",
            DVec2::new(0.0, r) + (r + 0.5) * DVec2::from_angle(-std::f64::consts::FRAC_PI_4),
        ),
    ] {
        assert!(pos(p, "left", v).distance(at) < 1e-12, "{v}");
    }
    let left = state(p, "left");
    assert_eq!(left.geometry_frame, 1);
    // The asphalt's long sides are cut in 16, the rungs are not: 34 corners, all on the arcs.
    let ring = outer(left, 0);
    assert_eq!(ring.len(), 34);
    let centre = DVec2::new(0.0, r);
    assert!(ring.iter().all(|q| {
        let d = q.distance(centre);
        (d - (r + 0.5)).abs() < 1e-9 || (d - (r - 0.5)).abs() < 1e-9
    }));
    assert!(signed_area(ring) > 0.0, "still counter-clockwise");
}

#[test]
fn geometry_beyond_the_axis_ends_follows_the_end_tangents() {
    let g = ok(&road("state left bend 90"));
    let line = outer(state(&g.pieces[0], "left"), 1);
    let r = 4.0 / std::f64::consts::PI;
    // (-0.5, 0.4) is before the axis: unchanged. (2.5, 0.4) is 0.5 m past the end, whose
    // tangent points north: at (r - 0.4, r + 0.5).
    assert_eq!(line[0], DVec2::new(-0.5, 0.4));
    let last = *line.last().unwrap();
    assert!(
        last.distance(DVec2::new(r - 0.4, r + 0.5)) < 1e-12,
        "{last}"
    );
    // Cut where the line enters and leaves the axis, 16 pieces on the arc, straight outside.
    assert_eq!(line.len(), 1 + 1 + 16 + 1);
}

#[test]
fn bend_zero_is_the_base_state() {
    let g = ok(&road("state same bend 0"));
    let p = &g.pieces[0];
    assert_eq!(p.states[1].positions, p.states[0].positions);
    assert_eq!(p.states[1].geometry, p.states[0].geometry);
}

#[test]
fn the_mirror_of_a_bend_is_the_opposite_bend() {
    let g = ok(&road(
        "state left bend 90\nstate right mirror left\nstate also_right bend -90\nstate again mirror right",
    ));
    let p = &g.pieces[0];
    let (right, also) = (state(p, "right"), state(p, "also_right"));
    for (a, b) in right.positions.iter().zip(&also.positions) {
        assert!(a.distance(*b) < 1e-12);
    }
    assert_eq!(right.geometry, also.geometry);
    assert_eq!(state(p, "again").positions, state(p, "left").positions);
    // Each vertex keeps its side: s0 stays south.
    assert!(pos(p, "right", "s1").y < -0.5);
    assert!(signed_area(outer(right, 0)) > 0.0);
}

#[test]
fn an_asymmetric_piece_bends_both_ways() {
    // A kerb vertex on the north side only: a listed state could not be mirrored, a bend can.
    let src = road("state left bend 60\nstate right mirror left")
        .replace(
            "vertex n2 (2, 0.5)",
            "vertex n2 (2, 0.5)\n    vertex k (1, 0.8)",
        )
        .replace("s1-n2", "s1-n2, n0-k-n2");
    let g = ok(&src);
    let p = &g.pieces[0];
    // On the right bend the kerb is on the outside, farther from the centre than n1.
    let centre = DVec2::new(0.0, -2.0 / (std::f64::consts::PI / 3.0));
    assert!(pos(p, "right", "k").distance(centre) > pos(p, "right", "n1").distance(centre));
}

#[test]
fn the_mirror_of_a_listed_state_swaps_mirror_images() {
    let lean =
        "state lean { s0 (0, -0.5) s1 (1, -0.4) s2 (2, -0.3) n0 (0, 0.5) n1 (1, 0.6) n2 (2, 0.7) }";
    let g = ok(&road(&format!("{lean}\nstate lean_back mirror lean")));
    let p = &g.pieces[0];
    // lean_back's s2 is the reflection of where lean puts n2, its mirror image.
    assert!(pos(p, "lean_back", "s2").distance(DVec2::new(2.0, -0.7)) < 1e-12);
    assert!(pos(p, "lean_back", "n1").distance(DVec2::new(1.0, 0.4)) < 1e-12);
    // lean shows the base geometry; so does its mirror, reflected, against the base positions.
    assert_eq!(state(p, "lean_back").geometry_frame, 0);
}

#[test]
fn mirror_of_base_keeps_the_positions_and_reflects_the_picture() {
    let g = ok(&road("state flipped mirror base"));
    let p = &g.pieces[0];
    for (a, b) in p.states[1].positions.iter().zip(&p.states[0].positions) {
        assert!(a.distance(*b) < 1e-12);
    }
    let line = outer(&p.states[1], 1);
    assert_eq!(line[0], DVec2::new(-0.5, -0.4));
    assert!(signed_area(outer(&p.states[1], 0)) > 0.0);
}

#[test]
fn a_body_gives_a_derived_state_its_own_geometry() {
    let g = ok(&road(
        "state left bend 90 {\n polygon fill #ffffff { (0, -0.5) (1, 0) (0, 0.5) }\n }\nstate right mirror left",
    ));
    let p = &g.pieces[0];
    let left = state(p, "left");
    assert_eq!(left.geometry.len(), 1);
    assert_eq!(outer(left, 0).len(), 3);
    // The mirror reflects the written geometry, reversed to stay counter-clockwise.
    let right = state(p, "right");
    assert_eq!(
        outer(right, 0),
        &[
            DVec2::new(0.0, -0.5),
            DVec2::new(1.0, 0.0),
            DVec2::new(0.0, 0.5)
        ]
    );
    assert_eq!(right.geometry_frame, 2);
}

#[test]
fn keywords_stay_contextual() {
    let g = ok(&road("state bend bend 45\nstate mirror mirror bend"));
    let names: Vec<&str> = g.pieces[0].states.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["base", "bend", "mirror"]);
}

#[test]
fn an_unknown_state_gets_a_did_you_mean() {
    let (c, text) = codes(&road("state left bend 90\nstate right mirror lfet"));
    assert_eq!(c, ["E011"], "{text}");
    assert!(text.contains("unknown state `lfet`") && text.contains("did you mean `left`?"));
}

#[test]
fn a_mirror_of_itself_is_one_error() {
    let (c, text) = codes(&road("state right mirror right"));
    assert_eq!(c, ["E057"], "{text}");
    assert!(text.contains("mirror of itself"), "{text}");
}

#[test]
fn two_mirrors_of_each_other_are_one_error() {
    let (c, text) = codes(&road("state a mirror b\nstate b mirror a"));
    assert_eq!(c, ["E057"], "{text}");
}

#[test]
fn no_axis_is_one_error_for_each_form() {
    for states in ["state left bend 90", "state right mirror base"] {
        let src = ROAD.replace("AXIS", "").replace("STATES", states);
        let (c, text) = codes(&src);
        // The skinned geometry's E027 would repeat the missing axis: not reported.
        assert_eq!(c, ["E055"], "{text}");
        assert!(text.contains("axis west -> east"), "{text}");
    }
}

#[test]
fn a_broken_axis_is_reported_once() {
    let src = ROAD
        .replace("AXIS", "axis west -> west")
        .replace("STATES", "state left bend 90\nstate right mirror left");
    let (c, text) = codes(&src);
    assert_eq!(c, ["E040"], "{text}");
}

#[test]
fn an_angle_beyond_a_full_turn_is_out_of_range() {
    let (c, text) = codes(&road("state left bend 400\nstate right mirror left"));
    assert_eq!(c, ["E013"], "{text}");
}

#[test]
fn a_full_turn_puts_the_ends_on_each_other() {
    // A ladder 0.5 m wide (radius 1/pi m, about 0.32 m, clears its rails): the two ends
    // meet and the vertices there coincide.
    let narrow = road("state ring bend 360")
        .replace("0.5)", "0.25)")
        .replace("0.4)", "0.2)");
    let (c, text) = codes(&narrow);
    assert!(!c.is_empty() && c.iter().all(|c| c == "E023"), "{text}");
}

#[test]
fn a_fold_by_a_proxy_point_is_reported() {
    // The vertices are 0.5 m from the axis (radius 0.64 m at 180 degrees), but the polyline
    // is 0.7 m out on the inside.
    let src = road("state u bend 180").replace("(-0.5, 0.4) (2.5, 0.4)", "(0, 0.7) (2, 0.7)");
    let (c, text) = codes(&src);
    assert_eq!(c, ["E056"], "{text}");
    assert!(text.contains("proxy point"), "{text}");
    // Turning the other way it is on the outside: fine.
    ok(&road("state u bend -180").replace("(-0.5, 0.4) (2.5, 0.4)", "(0, 0.7) (2, 0.7)"));
}

#[test]
fn a_mirror_that_folds_is_reported() {
    // Bending left by 180 degrees is fine for a piece whose south side reaches 0.7 m out; its
    // mirror bends right and folds the south side.
    let src = road("state u bend 180\nstate n mirror u")
        .replace("(-0.5, 0.4) (2.5, 0.4)", "(0, -0.7) (2, -0.7)");
    let (c, text) = codes(&src);
    assert_eq!(c, ["E056"], "{text}");
    assert!(text.contains("state `n`"), "{text}");
}

#[test]
fn tiny_and_odd_angles_stay_finite() {
    for a in ["1e-300", "-0", "0.0000001", "359.9999", "-360"] {
        let src = road(&format!("state s bend {a}"));
        if let Ok(c) = compile(&src, "t.clay", &CompileOptions::default()) {
            let p = &c.grammar.pieces[0];
            assert!(p.states[1].positions.iter().all(|q| q.is_finite()), "{a}");
        }
    }
}

/// How long this takes (near-linear, not quadratic) is timed by `benches/dsl.rs`
/// (`dsl/mirror_listed_piece`).
#[test]
fn mirroring_a_big_listed_piece_compiles_and_mirrors() {
    // 20,000 vertices on two rails, a listed state and its mirror.
    let n = 10_000;
    let mut src = String::from("site type t\npiece big {\n");
    for i in 0..n {
        src += &format!("vertex s{i} ({i}, -0.5)\nvertex n{i} ({i}, 0.5)\n");
    }
    src += &format!(
        "site west: t [n0, s0] out (-1, 0)\nsite east: t [s{0}, n{0}] out (1, 0)\naxis west -> east\n",
        n - 1
    );
    src += "state lean {\n";
    for i in 0..n {
        src += &format!("s{i} ({i}, -0.6) n{i} ({i}, 0.4)\n");
    }
    src += "}\nstate lean_back mirror lean\n}\nmodel { b = big }\n";
    let g = ok(&src);
    assert!(pos(&g.pieces[0], "lean_back", "s7").distance(DVec2::new(7.0, -0.4)) < 1e-12);
}

#[test]
fn the_example_in_the_language_docs_compiles_as_it_says() {
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/language.md"))
        .unwrap();
    let start = doc
        .find("```clay\n// bend.clay's road")
        .expect("the example")
        + 8;
    let len = doc[start..].find("```").unwrap();
    let src = format!(
        "site type lane\n{}\nmodel {{ r = road }}\n",
        &doc[start..start + len]
    );
    let g = ok(&src);
    let p = &g.pieces[0];
    // "east end at (1.27, 1.27)": the east site's centre.
    let east = (pos(p, "left", "s2") + pos(p, "left", "n2")) / 2.0;
    assert!(east.distance(DVec2::splat(4.0 / std::f64::consts::PI)) < 1e-12);
    // "the same as `bend -90`".
    let minus = ok(&src.replace("state right mirror left", "state right bend -90"));
    for (a, b) in state(p, "right")
        .positions
        .iter()
        .zip(&state(&minus.pieces[0], "right").positions)
    {
        assert!(a.distance(*b) < 1e-12);
    }
}
