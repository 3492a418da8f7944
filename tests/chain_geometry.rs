//! `rigid` and `skinned` geometry on a chain element, as docs/language.md says (issue 40): the
//! stretch rule gives the element an axis, but only `skinned` geometry follows it; `rigid`
//! geometry keeps its rest size and follows the element's best rigid motion.

use clay::TessellationCache;
use clay::testing::pose_assembly;
use clay_dsl::compiled::CompiledGrammar;

/// grammars/wall.clay with its brick's face (and course line) bound as `binding`.
fn wall(binding: &str) -> CompiledGrammar {
    let src = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/grammars/wall.clay"))
        .unwrap();
    let text = src
        .replace("polygon skinned", &format!("polygon {binding}"))
        .replace("polyline skinned", &format!("polyline {binding}"));
    assert!(text.contains(&format!("polygon {binding} fill")));
    assert!(text.contains(&format!("polyline {binding} width")));
    clay_dsl::compile(&text, "wall.clay", &clay_dsl::CompileOptions::default())
        .unwrap()
        .grammar
}

/// The area of the brick face (the first proxy) of the last brick, its extent along x and the
/// middle of that extent, with that brick's east end pulled `by` metres east.
fn last_face(g: &CompiledGrammar, by: f64) -> (f64, f64, f64) {
    let mut data = g.assembly.clone();
    let last = data.instances.len() - 1;
    assert_eq!(data.instances[last].name, "wall[7]");
    let piece = &g.pieces[data.instances[last].piece];
    let east = &piece.sites[piece.sites.iter().position(|s| s.name == "east").unwrap()];
    for &v in &east.vertices {
        let global = data.instances[last].vertices[v];
        data.positions[global].x += by;
    }
    let meshes = pose_assembly(g, &data, &mut TessellationCache::new());
    let face = meshes
        .iter()
        .find(|m| m.instance == last)
        .expect("the last brick's face");
    let p = |i: u32| face.positions[i as usize].map(f64::from);
    let area: f64 = face
        .triangles
        .iter()
        .map(|&[a, b, c]| {
            let (a, b, c) = (p(a), p(b), p(c));
            ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])).abs() / 2.0
        })
        .sum();
    let xs = face.positions.iter().map(|q| f64::from(q[0]));
    let (lo, hi) = (
        xs.clone().fold(f64::MAX, f64::min),
        xs.fold(f64::MIN, f64::max),
    );
    (area, hi - lo, (lo + hi) / 2.0)
}

#[test]
fn a_stretched_elements_rigid_face_keeps_its_size_and_a_skinned_one_stretches() {
    // The face at rest: 0.94 m x 0.44 m, on the brick from 7 m to 8 m.
    let rest = 0.94 * 0.44;
    for binding in ["rigid", "skinned"] {
        let (area, width, middle) = last_face(&wall(binding), 0.0);
        assert!((area - rest).abs() < 1e-6, "{binding} at rest: {area}");
        assert!((width - 0.94).abs() < 1e-6, "{binding} at rest: {width}");
        assert!((middle - 7.5).abs() < 1e-6, "{binding} at rest: {middle}");
    }
    // The last brick pulled to 1.5 m long (7 m to 8.5 m). The rigid face keeps its size,
    // centred on the brick: a gap each side.
    let (area, width, middle) = last_face(&wall("rigid"), 0.5);
    assert!((area - rest).abs() < 1e-6, "rigid keeps its area: {area}");
    assert!(
        (width - 0.94).abs() < 1e-3,
        "rigid keeps its length: {width}"
    );
    assert!(
        (middle - 7.75).abs() < 1e-3,
        "rigid follows the brick: {middle}"
    );
    // Squeezed to 0.5 m (7 m to 7.5 m), the rigid face still is 0.94 m long: it overlaps.
    let (area, width, middle) = last_face(&wall("rigid"), -0.5);
    assert!((area - rest).abs() < 1e-6, "rigid keeps its area: {area}");
    assert!(
        (width - 0.94).abs() < 1e-3,
        "rigid keeps its length: {width}"
    );
    assert!(
        (middle - 7.25).abs() < 1e-3,
        "rigid follows the brick: {middle}"
    );
    // The skinned face stretches with the brick, by 1.5.
    let (area, width, middle) = last_face(&wall("skinned"), 0.5);
    assert!(
        (width - 0.94 * 1.5).abs() < 1e-3,
        "skinned stretches: {width}"
    );
    assert!(
        (area - rest * 1.5).abs() < 1e-3,
        "skinned stretches: {area}"
    );
    assert!(
        (middle - 7.75).abs() < 1e-3,
        "skinned spans the brick: {middle}"
    );
}
