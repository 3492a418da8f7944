//! Models built in code rather than from `.clay` files: a stretchable wall, a street with
//! base/left/right states, a city (grid of streets and junctions plus a long wall) of about N
//! parts for the benchmark, and the classic ARAP triangulated grid. Each returns a
//! [`CompiledGrammar`] whose `assembly` is the model. [`grammar_text`] instead writes a large
//! grammar as `.clay` text, for timing the compiler.
//!
//! Not behind the feature `testing`: the shipped `clayc bench` solves the city.

use clay_dsl::compiled::{
    AssemblyData, Binding, Chain, CompiledGrammar, Dock, ElementVertex, FORMAT_VERSION, Instance,
    InstanceSite, Part, PartKind, PartState, Piece, Proxy, ProxyShape, RestState, Rgba, Site,
    SiteType, SolverParams, StretchPart, StretchRule, Variant,
};
use glam::DVec2;

/// Brick / street-segment corners in piece order `sw, se, ne, nw`.
fn quad(length: f64, width: f64) -> Vec<DVec2> {
    vec![
        DVec2::ZERO,
        DVec2::new(length, 0.0),
        DVec2::new(length, width),
        DVec2::new(0.0, width),
    ]
}

/// Quad edges: the outline and both diagonals (braced so a quad keeps its shape).
const QUAD_EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [2, 3], [3, 0], [0, 2], [1, 3]];

fn state(name: &str, positions: Vec<DVec2>, colour: [u8; 4], binding: Binding) -> RestState {
    RestState {
        name: name.into(),
        geometry: vec![Proxy {
            shape: ProxyShape::Polygon {
                outer: positions.clone(),
                holes: vec![],
            },
            fill: Rgba(colour),
            binding,
            extrude: None,
        }],
        positions,
        geometry_frame: 0,
    }
}

/// A linear piece running along x from its `west` site (index 0) to its `east` site (index 1).
fn linear_piece(name: &str, site_type: usize, states: Vec<RestState>) -> Piece {
    Piece {
        name: name.into(),
        vertices: ["sw", "se", "ne", "nw"].map(String::from).to_vec(),
        edges: QUAD_EDGES.to_vec(),
        sites: vec![
            Site {
                name: "west".into(),
                site_type,
                vertices: vec![3, 0],
                out: -DVec2::X,
            },
            Site {
                name: "east".into(),
                site_type,
                vertices: vec![1, 2],
                out: DVec2::X,
            },
        ],
        states,
        axis: Some([0, 1]),
    }
}

fn empty_grammar(source: &str) -> CompiledGrammar {
    CompiledGrammar {
        format_version: FORMAT_VERSION,
        source: source.into(),
        solver: SolverParams::default(),
        params: Vec::new(),
        site_types: vec![],
        pieces: vec![],
        stretch_rules: vec![],
        merge_rules: vec![],
        cut_rules: vec![],
        assembly: AssemblyData::default(),
    }
}

/// The stretch rule of a brick piece: the two-element part with its one/two/three states.
fn brick_stretch_rule(piece: usize, length: f64, width: f64) -> StretchRule {
    // element 0: all four corners; element 1: its se, ne (its sw, nw are element 0's se, ne).
    let vertices = vec![
        ElementVertex {
            element: 0,
            vertex: 0,
        },
        ElementVertex {
            element: 0,
            vertex: 1,
        },
        ElementVertex {
            element: 0,
            vertex: 2,
        },
        ElementVertex {
            element: 0,
            vertex: 3,
        },
        ElementVertex {
            element: 1,
            vertex: 1,
        },
        ElementVertex {
            element: 1,
            vertex: 2,
        },
    ];
    let second = [1, 4, 5, 2];
    let mut edges: Vec<[usize; 2]> = QUAD_EDGES.to_vec();
    for e in QUAD_EDGES {
        let mapped = [second[e[0]], second[e[1]]];
        if !edges
            .iter()
            .any(|f| *f == mapped || *f == [mapped[1], mapped[0]])
        {
            edges.push(mapped);
        }
    }
    let two = [
        DVec2::new(0.0, 0.0),
        DVec2::new(length, 0.0),
        DVec2::new(length, width),
        DVec2::new(0.0, width),
        DVec2::new(2.0 * length, 0.0),
        DVec2::new(2.0 * length, width),
    ];
    let scaled = |s: f64| {
        two.iter()
            .map(|p| DVec2::new(p.x * s, p.y))
            .collect::<Vec<_>>()
    };
    StretchRule {
        piece,
        variants: vec![Variant {
            piece,
            frequency: 1.0,
        }],
        from: 0,
        to: 1,
        min: 2,
        max: None,
        part: StretchPart {
            vertices,
            edges,
            states: vec![
                PartState {
                    name: "one".into(),
                    positions: scaled(0.5),
                },
                PartState {
                    name: "two".into(),
                    positions: scaled(1.0),
                },
                PartState {
                    name: "three".into(),
                    positions: scaled(1.5),
                },
            ],
        },
    }
}

/// Appends a chain of `count` bricks starting at `origin` along x: returns instance indices.
fn add_brick_chain(
    data: &mut AssemblyData,
    piece: usize,
    origin: DVec2,
    count: usize,
    length: f64,
    width: f64,
    prefix: &str,
) -> Vec<usize> {
    let base = data.positions.len();
    for k in 0..=count {
        data.positions
            .push(origin + DVec2::new(k as f64 * length, 0.0));
        data.positions
            .push(origin + DVec2::new(k as f64 * length, width));
    }
    let mut ids = Vec::with_capacity(count);
    for k in 0..count {
        let (sw, nw, se, ne) = (
            base + 2 * k,
            base + 2 * k + 1,
            base + 2 * k + 2,
            base + 2 * k + 3,
        );
        let index = data.instances.len();
        data.instances.push(Instance {
            id: data.next_id,
            name: format!("{prefix}[{k}]"),
            piece,
            vertices: vec![sw, se, ne, nw],
            state: 0,
        });
        data.next_id += 1;
        if k > 0 {
            data.docks.push(Dock {
                a: InstanceSite {
                    instance: index - 1,
                    site: 1,
                },
                b: InstanceSite {
                    instance: index,
                    site: 0,
                },
            });
        }
        ids.push(index);
    }
    ids
}

/// A straight wall of `bricks` stretchable 1 x 0.5 bricks along x from the origin, covered by
/// two-element stretch parts with `one`/`two`/`three` rest states (no rules: pure elasticity).
pub fn wall(bricks: usize) -> CompiledGrammar {
    let mut g = empty_grammar("synthetic:wall");
    g.site_types.push(SiteType {
        name: "course".into(),
        docks_with: vec![0],
    });
    g.pieces.push(linear_piece(
        "brick",
        0,
        vec![state(
            "base",
            quad(1.0, 0.5),
            [170, 80, 60, 255],
            Binding::Skinned,
        )],
    ));
    g.stretch_rules.push(brick_stretch_rule(0, 1.0, 0.5));
    let mut data = g.assembly.clone();
    let ids = add_brick_chain(&mut data, 0, DVec2::ZERO, bricks, 1.0, 0.5, "wall");
    data.chains.push(Chain {
        rule: 0,
        instances: ids,
        trend: 0,
    });
    data.parts = g.parts(&data);
    g.assembly = data;
    g
}

/// Rest states of a street segment of length `l`, width `w`: straight, and turning 45 degrees
/// left or right (two segments make a 90-degree bend).
fn street_states(l: f64, w: f64) -> Vec<RestState> {
    let turn = |angle: f64, pivot: DVec2| -> Vec<DVec2> {
        // the east end rotates about the inner corner of the turn
        let rot = DVec2::from_angle(angle);
        let mut p = quad(l, w);
        for k in [1, 2] {
            p[k] = pivot + rot.rotate(p[k] - pivot);
        }
        p
    };
    let grey = [90, 90, 100, 255];
    vec![
        state("base", quad(l, w), grey, Binding::Skinned),
        state(
            "left",
            turn(std::f64::consts::FRAC_PI_4, DVec2::new(l * 0.5, w)),
            grey,
            Binding::Skinned,
        ),
        state(
            "right",
            turn(-std::f64::consts::FRAC_PI_4, DVec2::new(l * 0.5, 0.0)),
            grey,
            Binding::Skinned,
        ),
    ]
}

/// A street of `segments` road pieces along x, each with base/left/right rest states, one
/// piece part per segment.
pub fn street(segments: usize) -> CompiledGrammar {
    let mut g = empty_grammar("synthetic:street");
    g.site_types.push(SiteType {
        name: "road".into(),
        docks_with: vec![0],
    });
    g.pieces
        .push(linear_piece("road", 0, street_states(2.0, 1.0)));
    let mut data = g.assembly.clone();
    add_brick_chain(&mut data, 0, DVec2::ZERO, segments, 2.0, 1.0, "road");
    data.parts = g.parts(&data);
    g.assembly = data;
    g
}

/// A city of about `parts` parts: a square grid of junctions joined by streets of three
/// segments, plus a long stretchable wall (a tenth of the parts) below it.
// Long because: one recipe in order (grid, streets, wall, docks, placement); each step extends the half-built model the next one needs.
pub fn city(parts: usize) -> CompiledGrammar {
    const SEGMENTS: usize = 3;
    const L: f64 = 2.0;
    const W: f64 = 1.0;
    let wall_parts = (parts / 10).max(2);
    // junctions g^2 plus streets 2 g (g - 1) SEGMENTS  ~= 7 g^2 for SEGMENTS = 3
    let street_budget = parts.saturating_sub(wall_parts) as f64;
    let g_side = ((street_budget / (1.0 + 2.0 * SEGMENTS as f64))
        .sqrt()
        .round() as usize)
        .max(2);
    let mut g = empty_grammar("synthetic:city");
    g.site_types.push(SiteType {
        name: "road".into(),
        docks_with: vec![0],
    });
    g.site_types.push(SiteType {
        name: "course".into(),
        docks_with: vec![1],
    });
    g.pieces.push(linear_piece("road", 0, street_states(L, W)));
    let grey = [90, 90, 100, 255];
    let square = vec![
        DVec2::ZERO,
        DVec2::new(W, 0.0),
        DVec2::new(W, W),
        DVec2::new(0.0, W),
        DVec2::splat(W / 2.0),
    ];
    g.pieces.push(Piece {
        name: "junction".into(),
        vertices: ["sw", "se", "ne", "nw", "c"].map(String::from).to_vec(),
        edges: vec![
            [0, 1],
            [1, 2],
            [2, 3],
            [3, 0],
            [4, 0],
            [4, 1],
            [4, 2],
            [4, 3],
        ],
        sites: vec![
            Site {
                name: "east".into(),
                site_type: 0,
                vertices: vec![1, 2],
                out: DVec2::X,
            },
            Site {
                name: "north".into(),
                site_type: 0,
                vertices: vec![2, 3],
                out: DVec2::Y,
            },
            Site {
                name: "west".into(),
                site_type: 0,
                vertices: vec![3, 0],
                out: -DVec2::X,
            },
            Site {
                name: "south".into(),
                site_type: 0,
                vertices: vec![0, 1],
                out: -DVec2::Y,
            },
        ],
        states: vec![state("base", square.clone(), grey, Binding::Rigid)],
        axis: None,
    });
    g.pieces.push(linear_piece(
        "brick",
        1,
        vec![state(
            "base",
            quad(1.0, 0.5),
            [170, 80, 60, 255],
            Binding::Skinned,
        )],
    ));
    g.stretch_rules.push(brick_stretch_rule(2, 1.0, 0.5));

    let mut data = g.assembly.clone();
    let spacing = W + SEGMENTS as f64 * L;
    let mut junction = vec![vec![0usize; g_side]; g_side];
    let mut junction_vertices = vec![vec![[0usize; 5]; g_side]; g_side];
    for (i, column) in junction.iter_mut().enumerate() {
        for (j, slot) in column.iter_mut().enumerate() {
            let origin = DVec2::new(i as f64 * spacing, j as f64 * spacing);
            let base = data.positions.len();
            data.positions.extend(square.iter().map(|&p| origin + p));
            let verts = [base, base + 1, base + 2, base + 3, base + 4];
            junction_vertices[i][j] = verts;
            *slot = data.instances.len();
            data.instances.push(Instance {
                id: data.next_id,
                name: format!("j[{i},{j}]"),
                piece: 1,
                vertices: verts.to_vec(),
                state: 0,
            });
            data.next_id += 1;
        }
    }
    // A street from junction site `(a, a_site)` to `(b, b_site)`: segment ends are the two
    // vertex pairs `start` (sw, nw) and `end` (se, ne) of the street's local frame.
    let add_street = |data: &mut AssemblyData,
                      start: [usize; 2],
                      end: [usize; 2],
                      docks: [InstanceSite; 2],
                      name: String| {
        let (s0, s1) = (data.positions[start[0]], data.positions[start[1]]);
        let (e0, e1) = (data.positions[end[0]], data.positions[end[1]]);
        let mut prev = start;
        let mut prev_instance = None;
        for m in 0..SEGMENTS {
            let next = if m + 1 == SEGMENTS {
                end
            } else {
                let t = (m + 1) as f64 / SEGMENTS as f64;
                let b = data.positions.len();
                data.positions.push(s0.lerp(e0, t));
                data.positions.push(s1.lerp(e1, t));
                [b, b + 1]
            };
            let index = data.instances.len();
            data.instances.push(Instance {
                id: data.next_id,
                name: format!("{name}[{m}]"),
                piece: 0,
                vertices: vec![prev[0], next[0], next[1], prev[1]],
                state: 0,
            });
            data.next_id += 1;
            let west = InstanceSite {
                instance: index,
                site: 0,
            };
            let a = prev_instance.map_or(docks[0], |p| InstanceSite {
                instance: p,
                site: 1,
            });
            data.docks.push(Dock { a, b: west });
            prev_instance = Some(index);
            prev = next;
        }
        if let Some(p) = prev_instance {
            data.docks.push(Dock {
                a: InstanceSite {
                    instance: p,
                    site: 1,
                },
                b: docks[1],
            });
        }
    };
    for i in 0..g_side {
        for j in 0..g_side {
            let v = junction_vertices[i][j];
            if i + 1 < g_side {
                let u = junction_vertices[i + 1][j];
                let docks = [
                    InstanceSite {
                        instance: junction[i][j],
                        site: 0,
                    },
                    InstanceSite {
                        instance: junction[i + 1][j],
                        site: 2,
                    },
                ];
                add_street(
                    &mut data,
                    [v[1], v[2]],
                    [u[0], u[3]],
                    docks,
                    format!("h[{i},{j}]"),
                );
            }
            if j + 1 < g_side {
                let u = junction_vertices[i][j + 1];
                let docks = [
                    InstanceSite {
                        instance: junction[i][j],
                        site: 1,
                    },
                    InstanceSite {
                        instance: junction[i][j + 1],
                        site: 3,
                    },
                ];
                add_street(
                    &mut data,
                    [v[2], v[3]],
                    [u[1], u[0]],
                    docks,
                    format!("v[{i},{j}]"),
                );
            }
        }
    }
    let ids = add_brick_chain(
        &mut data,
        2,
        DVec2::new(0.0, -5.0),
        wall_parts + 1,
        1.0,
        0.5,
        "wall",
    );
    data.chains.push(Chain {
        rule: 0,
        instances: ids,
        trend: 0,
    });
    data.parts = g.parts(&data);
    g.assembly = data;
    g
}

/// The classic ARAP set-up (Sorkine and Alexa): a `k x k` triangulated grid of unit spacing
/// whose parts are the vertices' one-rings (spokes as edges), one rest state each.
pub fn arap_grid(k: usize) -> CompiledGrammar {
    let k = k.max(2);
    let mut g = empty_grammar("synthetic:arap-grid");
    g.pieces.push(Piece {
        name: "node".into(),
        vertices: vec!["v".into()],
        edges: vec![],
        sites: vec![],
        states: vec![state(
            "base",
            vec![DVec2::ZERO],
            [200, 200, 200, 255],
            Binding::Rigid,
        )],
        axis: None,
    });
    let mut data = g.assembly.clone();
    let id = |i: usize, j: usize| j * k + i;
    for j in 0..k {
        for i in 0..k {
            data.positions.push(DVec2::new(i as f64, j as f64));
            data.instances.push(Instance {
                id: data.next_id,
                name: format!("n[{i},{j}]"),
                piece: 0,
                vertices: vec![id(i, j)],
                state: 0,
            });
            data.next_id += 1;
        }
    }
    // Each square (i, j)-(i+1, j+1) is split along its (i, j)-(i+1, j+1) diagonal.
    let offsets: [(i64, i64); 6] = [(1, 0), (1, 1), (0, 1), (-1, 0), (-1, -1), (0, -1)];
    for j in 0..k {
        for i in 0..k {
            let mut vertices = vec![id(i, j)];
            for (di, dj) in offsets {
                let (ni, nj) = (i as i64 + di, j as i64 + dj);
                if (0..k as i64).contains(&ni) && (0..k as i64).contains(&nj) {
                    vertices.push(id(ni as usize, nj as usize));
                }
            }
            let edges = (1..vertices.len()).map(|m| [0, m]).collect();
            let positions = vertices.iter().map(|&v| data.positions[v]).collect();
            data.parts.push(Part {
                kind: PartKind::Piece { instance: id(i, j) },
                vertices,
                edges,
                states: vec![PartState {
                    name: "base".into(),
                    positions,
                }],
                active: 0,
            });
        }
    }
    g.assembly = data;
    g
}

/// The text of a `.clay` grammar of `pieces` pieces (rounded up to a multiple of four) that
/// compiles clean, for timing the compiler (`benches/check.rs`, `docs/performance.md`). Per
/// group of four: a stretchable 8-vertex road (three sites, skinned proxy, a stretch rule), its
/// tee junction (four sites, a second rest state, a merge rule and a written cut), a 6-vertex
/// segment with a `left` state bent a quarter turn, and a square post with a `leaning` state;
/// the model has a chain of three roads and the segment docked to the post, per group.
pub fn grammar_text(pieces: usize) -> String {
    use std::fmt::Write;
    let groups = pieces.div_ceil(4).max(1);
    let mut s = String::with_capacity(groups * 2600);
    s.push_str(
        "// A synthetic grammar for timing the compiler (clay::synthetic::grammar_text).\n\
         solver { merge_distance = 0.5 }\n\n\
         site type lane\nsite type side docks lane\n",
    );
    const ROAD: &str = "    vertex s0 (0, -0.5)
    vertex s1 (0.5, -0.5)
    vertex s2 (1.5, -0.5)
    vertex s3 (2, -0.5)
    vertex n0 (0, 0.5)
    vertex n1 (0.5, 0.5)
    vertex n2 (1.5, 0.5)
    vertex n3 (2, 0.5)
    edges s0-s1-s2-s3-n3-n2-n1-n0-s0, n1-s1, n2-s2, s0-n1, s1-n2, s2-n3
    site west: lane [n0, s0] out (-1, 0)
    site east: lane [s3, n3] out (1, 0)
    site north_side: side [n2, n1] out (0, 1)
";
    for g in 0..groups {
        let _ = write!(
            s,
            "
piece road_{g} {{
{ROAD}    polygon skinned fill #4b4f56 {{
        (0, -0.5) (2, -0.5) (2, 0.5) (0, 0.5)
    }}
    polyline skinned width 0.05 fill #e8e8e8 {{
        (0, 0.4) (2, 0.4)
    }}
}}

piece tee_{g} {{
{ROAD}    vertex u_w (0.5, 1)
    vertex u_e (1.5, 1)
    edges n1-u_w-u_e-n2, n1-u_e
    site north: lane [u_e, u_w] out (0, 1)
    polygon fill #4b4f56 {{
        (0, -0.5) (2, -0.5) (2, 0.5) (1.5, 0.5) (1.5, 1) (0.5, 1) (0.5, 0.5) (0, 0.5)
    }}
    state long {{
        s0 (0, -0.5) s1 (0.5, -0.5) s2 (1.5, -0.5) s3 (2, -0.5)
        n0 (0, 0.5) n1 (0.5, 0.5) n2 (1.5, 0.5) n3 (2, 0.5)
        u_w (0.5, 1.25) u_e (1.5, 1.25)
    }}
}}

piece bend_{g} {{
    vertex s0 (0, -0.5)
    vertex s1 (1, -0.5)
    vertex s2 (2, -0.5)
    vertex n0 (0, 0.5)
    vertex n1 (1, 0.5)
    vertex n2 (2, 0.5)
    edges s0-s1-s2-n2-n1-n0-s0, n1-s1, s0-n1, s1-n2
    site west: lane [n0, s0] out (-1, 0)
    site east: lane [s2, n2] out (1, 0)
    polygon fill #4b4f56 {{
        (0, -0.5) (2, -0.5) (2, 0.5) (0, 0.5)
    }}
    state left {{
        s0 (0, -0.5)
        s1 (1.25387, 0.01937)
        s2 (1.77324, 1.27324)
        n0 (0, 0.5)
        n1 (0.546763, 0.726477)
        n2 (0.77324, 1.27324)
        polygon fill #4b4f56 {{
            (0, -0.5) (1.25387, 0.01937) (1.77324, 1.27324) (0.77324, 1.27324)
            (0.546763, 0.726477) (0, 0.5)
        }}
    }}
}}

piece post_{g} {{
    vertex sw (0, -0.5)
    vertex se (1, -0.5)
    vertex ne (1, 0.5)
    vertex nw (0, 0.5)
    edges sw-se-ne-nw-sw, sw-ne
    site west: lane [nw, sw] out (-1, 0)
    site east: lane [se, ne] out (1, 0)
    polygon fill #8a8d91 {{
        (0, -0.5) (1, -0.5) (1, 0.5) (0, 0.5)
    }}
    state leaning {{
        sw (0, -0.5) se (1, -0.5) ne (1.2, 0.5) nw (0.2, 0.5)
    }}
}}

stretch road_{g} from west to east {{ min 2 }}
merge road_{g}.east onto road_{g}.north_side into tee_{g}.north
cut tee_{g}.north into road_{g}
"
        );
    }
    s.push_str("\nmodel {\n");
    for g in 0..groups {
        let y = 4 * g;
        let _ = writeln!(
            s,
            "    r_{g} = chain road_{g} x 3 at (0, {y})\n    b_{g} = bend_{g} at (10, {y})\n    \
             p_{g} = post_{g}\n    dock b_{g}.east to p_{g}.west"
        );
    }
    s.push_str("}\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_timing_grammar_compiles_clean_with_every_piece_and_rule() {
        let text = grammar_text(8);
        let c = match clay_dsl::compile(
            &text,
            "synthetic.clay",
            &clay_dsl::CompileOptions::default(),
        ) {
            Ok(c) => c,
            Err(d) => panic!("{}", clay_dsl::render(&d, &text, "synthetic.clay", false)),
        };
        assert!(c.warnings.is_empty(), "{:?}", c.warnings);
        let g = c.grammar;
        assert_eq!(g.pieces.len(), 8);
        assert_eq!(g.stretch_rules.len(), 2);
        assert_eq!(g.merge_rules.len(), 2);
        assert_eq!(g.cut_rules.len(), 2);
        assert!(g.pieces.iter().filter(|p| p.states.len() == 2).count() == 6);
        // Per group: three roads in a chain, the segment and its post.
        assert_eq!(g.assembly.instances.len(), 10);
        assert_eq!(grammar_text(10_000).matches("\npiece ").count(), 10_000);
    }
}
