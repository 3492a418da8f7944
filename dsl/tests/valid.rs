//! Valid grammars compile to the rest-state sets, site types, rules and initial assembly that
//! docs/language.md and compiled.rs describe (real numbers, not echoes of the code).

use clay_dsl::compiled::*;
use clay_dsl::{CompileOptions, Compiled, compile};
use glam::DVec2;

fn ok(source: &str) -> Compiled {
    match compile(source, "test.clay", &CompileOptions::default()) {
        Ok(c) => c,
        Err(d) => panic!("{}", clay_dsl::render(&d, source, "test.clay", false)),
    }
}

fn close(a: DVec2, b: DVec2) -> bool {
    a.distance(b) < 1e-9
}

fn doc_example() -> String {
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/language.md"))
        .unwrap();
    let start = doc
        .find("```clay\n")
        .expect("a clay example in language.md")
        + 8;
    let end = start + doc[start..].find("```").unwrap();
    doc[start..end].to_string()
}

#[test]
fn the_language_doc_example_compiles_to_a_wall_of_eight_bricks() {
    let c = ok(&doc_example());
    assert!(c.warnings.is_empty(), "{:?}", c.warnings);
    let g = c.grammar;
    assert_eq!(g.solver.merge_distance, 0.3);
    assert_eq!(g.solver.norm, 0.5);
    let a = &g.assembly;
    assert_eq!(a.instances.len(), 8);
    assert_eq!(a.instances[7].name, "wall[7]");
    assert_eq!(a.next_id, 8);
    assert_eq!(
        a.instances.iter().map(|i| i.id).collect::<Vec<_>>(),
        (0..8).collect::<Vec<_>>()
    );
    // 8 bricks of 4 vertices, 7 docks sharing 2 vertices each.
    assert_eq!(a.positions.len(), 8 * 4 - 7 * 2);
    assert_eq!(a.docks.len(), 7);
    assert_eq!(
        a.chains,
        vec![Chain {
            rule: 0,
            instances: (0..8).collect(),
            trend: 0,
        }]
    );
    assert_eq!(a.parts.len(), 7);
    assert!(
        a.parts
            .iter()
            .all(|p| matches!(p.kind, PartKind::Stretch { chain: 0, .. }))
    );
    // The last brick's north-east corner is 8 m east.
    let ne = a.instances[7].vertices[2];
    assert!(
        close(a.positions[ne], DVec2::new(8.0, 0.5)),
        "{:?}",
        a.positions[ne]
    );
    assert_eq!(g.pieces[0].axis, Some([0, 1]));
}

/// A 2 m segment piece: vertices, edges, sites, skinned geometry; `extra` goes inside it.
macro_rules! segment {
    ($extra:literal, $rest:literal) => {
        concat!(
            "site type end\npiece seg {\n",
            "    vertex a (0, 0)\n    vertex b (2, 0)\n    vertex c (2, 1)\n    vertex d (0, 1)\n",
            "    edges a-b-c-d-a, a-c\n",
            "    site west: end [d, a] out (-1, 0)\n    site east: end [b, c] out (1, 0)\n",
            "    polygon skinned fill #808080 { (0, 0) (2, 0) (2, 1) (0, 1) }\n",
            $extra,
            "}\n",
            $rest
        )
    };
}

const SEGMENT: &str = segment!(
    "",
    "stretch seg from west to east { min 3 }\nmodel { road = chain seg x 4 at (10, 5) }\n"
);

/// The segment outside any chain, with alternative states: a stretch piece may not have them
/// (E047), so it gets its axis from `axis` instead.
const POSED: &str = segment!(
    r#"    axis west -> east
    state leaning {
        a (0, 0) b (2, 0) c (2.5, 1) d (0.5, 1)
    }
    state bent {
        a (0, 0) b (2, 0) c (2, 1.5) d (0, 1)
        polygon rigid fill #ff000080 { (0, 0) (2, 0) (2, 1.5) }
    }
"#,
    "model { post = seg at (10, 5) }\n"
);

#[test]
fn alternative_states_keep_vertex_order_and_frame_their_geometry() {
    let g = ok(POSED).grammar;
    let p = &g.pieces[0];
    let names: Vec<&str> = p.states.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["base", "leaning", "bent"]);
    assert_eq!(p.states[1].positions[2], DVec2::new(2.5, 1.0));
    // `leaning` has no geometry of its own: it shows the base state's, framed by state 0.
    assert_eq!(p.states[1].geometry_frame, 0);
    assert_eq!(p.states[1].geometry, p.states[0].geometry);
    assert_eq!(p.states[2].geometry_frame, 2);
    assert_eq!(p.states[2].geometry[0].fill, Rgba([255, 0, 0, 128]));
    assert_eq!(p.states[2].geometry[0].binding, Binding::Rigid);
    assert_eq!(p.states[0].geometry[0].binding, Binding::Skinned);
    assert_eq!(p.sites[0].out, DVec2::new(-1.0, 0.0));
}

#[test]
fn stretch_part_states_scale_two_elements_along_the_axis() {
    let g = ok(SEGMENT).grammar;
    let rule = &g.stretch_rules[0];
    assert_eq!((rule.from, rule.to, rule.min), (0, 1, 3));
    assert_eq!(
        rule.variants,
        vec![Variant {
            piece: 0,
            frequency: 1.0
        }]
    );
    let part = &rule.part;
    // Element 1 shares its west vertices (d, a) with element 0's east ones (b, c).
    assert_eq!(part.vertices.len(), 4 + 2);
    assert_eq!(
        &part.vertices[4..],
        &[
            ElementVertex {
                element: 1,
                vertex: 1
            },
            ElementVertex {
                element: 1,
                vertex: 2
            }
        ]
    );
    // 5 edges per element, the shared rung b-c stored once.
    assert_eq!(part.edges.len(), 9);
    let names: Vec<&str> = part.states.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["one", "two", "three"]);
    // Element 0's from-site centre is (0, 0.5); element 1's to-site centre is at 2L, L = 2.
    let to_centre = |s: &PartState| (s.positions[4] + s.positions[5]) / 2.0;
    let from_centre = |s: &PartState| (s.positions[0] + s.positions[3]) / 2.0;
    for (k, expected) in [(0, 2.0), (1, 4.0), (2, 6.0)] {
        let s = &part.states[k];
        assert!(close(from_centre(s), DVec2::new(0.0, 0.5)), "{}", s.name);
        assert!(
            close(to_centre(s), DVec2::new(expected, 0.5)),
            "{}: {:?}",
            s.name,
            to_centre(s)
        );
        // Perpendicular components are unchanged: the top vertices stay at y = 1.
        assert!((s.positions[5].y - 1.0).abs() < 1e-9);
    }
    // `three` puts element 1's to-site centre at 3 element lengths.
    assert!(close(
        to_centre(&part.states[2]),
        DVec2::new(3.0 * 2.0, 0.5)
    ));
    // The chain: 4 elements placed from (10, 5), 3 stretch parts starting in `two`.
    let a = &g.assembly;
    assert_eq!(a.parts.len(), 3);
    assert!(a.parts.iter().all(|p| p.active == 1 && p.states.len() == 3));
    let last_c = a.instances[3].vertices[2];
    assert!(close(a.positions[last_c], DVec2::new(18.0, 6.0)));
}

#[test]
fn a_diagonal_stretch_axis_scales_only_along_the_axis() {
    // The 2 x 1 segment turned so its length runs along u = (0.6, 0.8).
    let src = r#"
site type j
piece tile {
    vertex a (0, 0)
    vertex b (1.2, 1.6)
    vertex c (0.4, 2.2)
    vertex d (-0.8, 0.6)
    edges a-b-c-d-a
    site west: j [d, a] out (-0.6, -0.8)
    site east: j [b, c] out (0.6, 0.8)
}
stretch tile from west to east
model { t = chain tile x 2 }
"#;
    let g = ok(src).grammar;
    let part = &g.stretch_rules[0].part;
    let u = DVec2::new(0.6, 0.8);
    let origin = DVec2::new(-0.4, 0.3);
    let to_centre = |s: &PartState| (s.positions[4] + s.positions[5]) / 2.0;
    for (k, lengths) in [(0, 2.0), (1, 4.0), (2, 6.0)] {
        let c = to_centre(&part.states[k]);
        assert!(
            close(c, origin + u * lengths),
            "{}: {c:?}",
            part.states[k].name
        );
    }
    let (two, three) = (&part.states[1].positions, &part.states[2].positions);
    for (p2, p3) in two.iter().zip(three) {
        let (d2, d3) = (*p2 - origin, *p3 - origin);
        assert!((d3.dot(u) - 1.5 * d2.dot(u)).abs() < 1e-9);
        assert!((d3.perp_dot(u) - d2.perp_dot(u)).abs() < 1e-9);
    }
}

#[test]
fn docking_is_symmetric_and_explicit_docks_form_chains() {
    let src = r#"
site type plug docks socket
site type socket
piece brick {
    vertex sw (0, 0)
    vertex se (1, 0)
    vertex ne (1, 0.5)
    vertex nw (0, 0.5)
    edges sw-se-ne-nw-sw
    site west: socket [nw, sw] out (-1, 0)
    site east: plug [se, ne] out (1, 0)
}
piece tower {
    vertex a (-0.5, -0.5)
    vertex b (0.5, -0.5)
    vertex c (0.5, 0.5)
    vertex p (0.25, 0.5)
    vertex q (-0.25, 0.5)
    vertex d (-0.5, 0.5)
    edges a-b-c-p-q-d-a, a-c
    site north: socket [p, q] out (0, 1)
}
stretch brick from west to east
model {
    t = tower at (5, 0) rotate 90
    x = brick
    y = brick
    z = brick
    dock x.east to y.west
    dock y.east to z.west
    dock z.east to t.north
}
"#;
    let g = ok(src).grammar;
    let plug = g.site_types.iter().position(|t| t.name == "plug").unwrap();
    let socket = g
        .site_types
        .iter()
        .position(|t| t.name == "socket")
        .unwrap();
    assert!(g.types_dock(plug, socket) && g.types_dock(socket, plug));
    // `plug` lists its partners, so it does not dock with itself; `socket` lists none, so it does.
    assert!(!g.types_dock(plug, plug));
    assert!(g.types_dock(socket, socket));
    assert_eq!(g.site_types[socket].docks_with, vec![0, 1]);
    let a = &g.assembly;
    // x, y, z form one chain although no `chain` statement names them.
    assert_eq!(
        a.chains,
        vec![Chain {
            rule: 0,
            instances: vec![1, 2, 3],
            trend: 0,
        }]
    );
    assert_eq!(
        a.parts
            .iter()
            .filter(|p| matches!(p.kind, PartKind::Stretch { .. }))
            .count(),
        2
    );
    assert_eq!(
        a.parts
            .iter()
            .filter(|p| matches!(p.kind, PartKind::Piece { .. }))
            .count(),
        1
    );
    // Shared vertices: x's east [se, ne] meets y's west [nw, sw] reversed: se = sw, ne = nw.
    let (x, y) = (&a.instances[1], &a.instances[2]);
    assert_eq!(x.vertices[1], y.vertices[0]);
    assert_eq!(x.vertices[2], y.vertices[3]);
    assert_eq!(a.positions.len(), 6 + 3 * 4 - 3 * 2);
    // The tower, turned 90 degrees at (5, 0), has its north site facing west; the wall is
    // placed from it: z's east site centre meets the tower's north centre at (4.5, 0).
    let z = &a.instances[3];
    let centre = (a.positions[z.vertices[1]] + a.positions[z.vertices[2]]) / 2.0;
    assert!(close(centre, DVec2::new(4.5, 0.0)), "{centre:?}");
    let x_sw = a.positions[x.vertices[0]];
    assert!(close(x_sw, DVec2::new(1.5, -0.25)), "{x_sw:?}");
}

const JUNCTION: &str = r#"
site type end
piece road {
    vertex a (0, 0)
    vertex b (1, 0)
    vertex c (1, 1)
    vertex d (0, 1)
    edges a-b-c-d-a
    site west: end [d, a] out (-1, 0)
    site east: end [b, c] out (1, 0)
}
piece tee {
    vertex a (0, 0)
    vertex b (1, 0)
    vertex c (1, 1)
    vertex d (0, 1)
    edges a-b-c-d-a
    site west: end [d, a] out (-1, 0)
    site east: end [b, c] out (1, 0)
    site north: end [c, d] out (0, 1)
}
stretch road from west to east
merge road.east onto road.west into tee.north within 0.25
model {
    main = chain road x 3
    side = chain road x 2 at (5, 5)
}
"#;

#[test]
fn merges_into_junctions_derive_their_cut() {
    let c = ok(JUNCTION);
    let g = &c.grammar;
    assert_eq!(g.merge_rules.len(), 1);
    let m = &g.merge_rules[0];
    assert_eq!(m.junction, Some(SiteRef { piece: 1, site: 2 }));
    assert_eq!(m.within, Some(0.25));
    // An explicit `within` wins over the live merge distance; without it the rule follows it.
    let mut params = g.solver;
    params.merge_distance = 2.0;
    assert_eq!(m.distance(&params), 0.25);
    let follows = clay_dsl::compiled::MergeRule {
        within: None,
        ..m.clone()
    };
    assert_eq!(follows.distance(&params), 2.0);
    assert_eq!(
        g.cut_rules,
        vec![CutRule {
            junction: SiteRef { piece: 1, site: 2 },
            into: 0,
            derived: true
        }]
    );
    assert!(c.warnings.is_empty(), "{:?}", c.warnings);
}

#[test]
fn compiled_grammar_round_trips_through_json() {
    let g = ok(JUNCTION).grammar;
    let text = serde_json::to_string(&g).unwrap();
    let back: CompiledGrammar = serde_json::from_str(&text).unwrap();
    assert_eq!(back, g);
    assert_eq!(back.format_version, FORMAT_VERSION);
}

#[test]
fn the_example_grammars_compile() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../grammars");
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut n = 0;
    for e in entries {
        let path = e.unwrap().path();
        if path.extension().is_none_or(|x| x != "clay") {
            continue;
        }
        let src = std::fs::read_to_string(&path).unwrap();
        let shown = path.display().to_string();
        match compile(&src, &shown, &CompileOptions::default()) {
            Ok(c) => assert!(
                !c.grammar.assembly.instances.is_empty(),
                "{shown} has an empty model"
            ),
            Err(d) => panic!("{}", clay_dsl::render(&d, &src, &shown, false)),
        }
        n += 1;
    }
    assert!(n > 0 || std::fs::read_dir(dir).is_err());
}

#[test]
fn line_col_counts_lines_and_chars_from_one() {
    let s = "ab\ncé\nx";
    assert_eq!(clay_dsl::line_col(s, 0), (1, 1));
    assert_eq!(clay_dsl::line_col(s, 3), (2, 1));
    assert_eq!(clay_dsl::line_col(s, 6), (2, 3)); // after the two-byte é
    assert_eq!(clay_dsl::line_col(s, 5), (2, 2)); // inside é: clamped back
    assert_eq!(clay_dsl::line_col(s, 99), (3, 2));
}

#[test]
fn a_line_index_agrees_with_line_col_at_every_offset() {
    for s in [
        "",
        "\n",
        "ab\ncé\nx",
        "\n\né\r\n€x\n",
        "no newline",
        "end\n",
    ] {
        let index = clay_dsl::LineIndex::new(s);
        for b in 0..=s.len() + 2 {
            assert_eq!(index.line_col(b), clay_dsl::line_col(s, b), "{s:?} at {b}");
        }
    }
}

#[test]
fn statements_need_no_line_of_their_own() {
    // docs/language.md: no terminator, no separator; a line break is whitespace. The doc's
    // example with every line joined into one (its comment lines dropped), and with a
    // solver block, `let`s, a listed state and model statements sharing lines too.
    let example = doc_example();
    let code: Vec<&str> = example
        .lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect();
    let (by_lines, one_line) = (code.join("\n"), code.join(" "));
    assert!(code.len() > 20 && !one_line.contains('\n'));
    assert_eq!(
        serde_json::to_value(&ok(&one_line).grammar).unwrap(),
        serde_json::to_value(&ok(&by_lines).grammar).unwrap()
    );
    // `clayc fmt` prints a statement a line, whichever way the text was written.
    assert_eq!(
        clay_dsl::format(&one_line).unwrap(),
        clay_dsl::format(&by_lines).unwrap()
    );
    let packed = "let w = 1 let h = 0.5\nsolver { hysteresis = 0.2 norm = 0.6 }\n\
                  site type joint\n\
                  piece brick { vertex sw (0, 0) vertex se (w, 0) vertex ne (w, h) vertex nw (0, h)\n\
                  edges sw-se-ne-nw-sw, sw-ne site west: joint [nw, sw] out (-1, 0)\n\
                  site east: joint [se, ne] out (1, 0) state tall { sw (0, 0) se (w, 0) ne (w, 1)\n\
                  nw (0, 1) } }\n\
                  model { a = brick b = brick at (3, 0) dock a.east to b.west }\n";
    let c = ok(packed);
    let g = &c.grammar;
    assert_eq!(g.solver.hysteresis, 0.2);
    assert_eq!(g.solver.norm, 0.6);
    assert_eq!(g.pieces[0].vertices, ["sw", "se", "ne", "nw"]);
    assert_eq!(g.pieces[0].sites.len(), 2);
    assert_eq!(g.pieces[0].states.len(), 2);
    assert_eq!(g.pieces[0].states[1].positions[2], DVec2::new(1.0, 1.0));
    assert_eq!(g.assembly.instances.len(), 2);
    assert_eq!(g.assembly.docks.len(), 1);
}
