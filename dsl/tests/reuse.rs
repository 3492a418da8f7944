//! Reuse in the grammar language (issue 18): `piece NAME extends BASE` and `import "FILE"`,
//! with diagnostics that name the imported file and never cascade.

use std::collections::HashMap;
use std::io;

use clay_dsl::compiled::CompiledGrammar;
use clay_dsl::{CompileOptions, Compiled, Diagnostics, Loader, compile, render, to_json};

/// Files served from memory, as a language server would serve unsaved buffers.
struct Mem(HashMap<String, Vec<u8>>);

impl Mem {
    fn new(files: &[(&str, &str)]) -> Self {
        Self(
            files
                .iter()
                .map(|(p, t)| (p.to_string(), t.as_bytes().to_vec()))
                .collect(),
        )
    }
}

impl Loader for Mem {
    fn load(&self, path: &str) -> io::Result<Vec<u8>> {
        self.0
            .get(path)
            .cloned()
            .ok_or_else(|| io::Error::new(io::ErrorKind::NotFound, "not here"))
    }
}

const BRICK: &str = "site type joint

piece brick {
    vertex sw (0, 0)
    vertex se (1, 0)
    vertex ne (1, 0.5)
    vertex nw (0, 0.5)
    edges sw-se-ne-nw-sw, sw-ne
    site west: joint [nw, sw] out (-1, 0)
    site east: joint [se, ne] out (1, 0)
    polygon fill #b5651d {
        (0.03, 0.03) (0.97, 0.03) (0.97, 0.47) (0.03, 0.47)
    }
}
";

fn ok(source: &str, files: &[(&str, &str)]) -> Compiled {
    match compile(
        source,
        "g/main.clay",
        &CompileOptions::with_loader(&Mem::new(files)),
    ) {
        Ok(c) => c,
        Err(d) => panic!("{}", render(&d, source, "g/main.clay", false)),
    }
}

fn err(source: &str, files: &[(&str, &str)]) -> Diagnostics {
    compile(
        source,
        "g/main.clay",
        &CompileOptions::with_loader(&Mem::new(files)),
    )
    .expect_err("must not compile")
}

fn codes(d: &Diagnostics) -> Vec<&'static str> {
    d.iter().map(|d| d.code).collect()
}

fn piece<'a>(g: &'a CompiledGrammar, name: &str) -> &'a clay_dsl::compiled::Piece {
    g.pieces.iter().find(|p| p.name == name).expect(name)
}

/// Two JSON values equal, numbers within 1e-9.
fn same_json(a: &serde_json::Value, b: &serde_json::Value, at: &str) {
    use serde_json::Value::{Array, Number, Object};
    match (a, b) {
        (Number(x), Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            assert!((x - y).abs() <= 1e-9, "{at}: {x} != {y}");
        }
        (Array(x), Array(y)) => {
            assert_eq!(x.len(), y.len(), "{at}: lengths");
            for (k, (x, y)) in x.iter().zip(y).enumerate() {
                same_json(x, y, &format!("{at}[{k}]"));
            }
        }
        (Object(x), Object(y)) => {
            let keys = |o: &serde_json::Map<String, serde_json::Value>| {
                o.keys().cloned().collect::<Vec<_>>()
            };
            assert_eq!(keys(x), keys(y), "{at}: keys");
            for (k, v) in x {
                same_json(v, &y[k], &format!("{at}.{k}"));
            }
        }
        _ => assert_eq!(a, b, "{at}"),
    }
}

#[test]
fn examples_written_with_extends_compile_to_the_same_grammars_as_before() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let read = |p: &str| std::fs::read_to_string(format!("{root}/{p}")).unwrap();
    for (name, child) in [
        ("junction", "piece tee extends road"),
        ("centipede", "piece seg_c extends seg_a"),
    ] {
        // The text before the example used `extends`.
        let before = read(&format!("tests/fixtures/before/{name}.clay"));
        let after = read(&format!("grammars/{name}.clay"));
        assert!(after.contains(child), "{name} uses extends");
        assert!(after.len() < before.len(), "{name} is shorter");
        let path = format!("grammars/{name}.clay");
        let json = |src: &str| {
            let c = compile(src, &path, &CompileOptions::default()).unwrap();
            assert!(c.warnings.is_empty(), "{:?}", c.warnings);
            serde_json::to_value(&c.grammar).unwrap()
        };
        same_json(&json(&before), &json(&after), name);
    }
}

#[test]
fn a_child_is_its_base_plus_its_own_statements() {
    let src = format!(
        "{BRICK}
piece capped extends brick {{
    axis west -> east
    vertex top (0.5, 1)
    edges nw-top-ne
    site up: joint [top] out (0, 1)
}}
stretch brick from west to east
model {{ w = chain brick x 2  c = capped at (0, 3) }}"
    );
    let c = ok(&src, &[]);
    let p = piece(&c.grammar, "capped");
    assert_eq!(p.vertices, ["sw", "se", "ne", "nw", "top"]);
    assert_eq!(p.edges.len(), 5 + 2);
    let sites: Vec<&str> = p.sites.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(sites, ["west", "east", "up"]);
    // The base's geometry is inherited; the axis is the child's own.
    assert_eq!(p.states[0].geometry.len(), 1);
    assert_eq!(p.axis, Some([0, 1]));
}

#[test]
fn a_child_is_a_stretch_variant_a_merge_junction_and_a_cut_target() {
    let src = format!(
        "{BRICK}
site type side docks joint
piece red extends brick {{
    polygon skinned fill #ff0000 {{ (0, 0) (1, 0) (1, 0.5) (0, 0.5) }}
}}
piece tee extends brick {{
    vertex a (0.25, 1)
    vertex b (0.75, 1)
    edges nw-a-b-ne
    site north: joint [b, a] out (0, 1)
    polygon fill #808080 {{ (0, 0) (1, 0) (1, 1) (0, 1) }}
}}
piece slab extends tee {{ }}
stretch brick from west to east {{ variants {{ brick 0.5, red 0.5 }} }}
merge brick.east onto brick.west into tee.north
cut tee.north into slab
model {{ w = chain brick x 4 }}"
    );
    let c = ok(&src, &[]);
    let g = &c.grammar;
    assert_eq!(g.stretch_rules[0].variants.len(), 2);
    let tee = g.pieces.iter().position(|p| p.name == "tee").unwrap();
    assert_eq!(g.merge_rules[0].junction.unwrap().piece, tee);
    // The child's own geometry replaced the base's.
    assert_eq!(
        piece(g, "red").states[0].geometry[0].fill.0,
        [255, 0, 0, 255]
    );
    assert_eq!(piece(g, "tee").states[0].geometry.len(), 1);
    assert_eq!(piece(g, "slab").vertices, piece(g, "tee").vertices);
    assert!(c.warnings.is_empty(), "{:?}", c.warnings);
}

#[test]
fn a_base_may_come_later_or_from_an_imported_file() {
    let src = "import \"lib/brick.clay\"
piece late extends early { }
piece early extends brick { }
stretch brick from west to east
model { w = chain brick x 2  l = late at (0, 5) }";
    let c = ok(src, &[("g/lib/brick.clay", BRICK)]);
    assert_eq!(piece(&c.grammar, "late").vertices.len(), 4);
}

#[test]
fn redeclaring_an_inherited_name_points_at_the_base_in_its_file() {
    let src = "import \"lib/brick.clay\"
piece tee extends brick {
    vertex sw (5, 5)
}
model { t = tee }";
    let d = err(src, &[("g/lib/brick.clay", BRICK)]);
    assert_eq!(codes(&d), ["E010"], "{d:?}");
    let text = render(&d, src, "g/main.clay", false);
    assert!(text.contains("g/main.clay:3:12"), "{text}");
    assert!(text.contains("g/lib/brick.clay:4:12"), "{text}");
    assert!(text.contains("inherited from `brick` here"), "{text}");
    let json = to_json(&d, src, "g/main.clay");
    assert_eq!(json[0].file, "g/main.clay");
    assert_eq!(json[0].labels[1].file, "g/lib/brick.clay");
    assert_eq!(json[0].labels[1].start.line, 4);
}

#[test]
fn sites_states_and_the_axis_may_not_be_redeclared_either() {
    let src = format!(
        "{BRICK}
piece b2 extends brick {{
    axis west -> east
    state s {{ sw (0, 0) se (1, 0) ne (1, 0.4) nw (0, 0.5) }}
}}
piece b3 extends b2 {{
    site east: joint [se, ne] out (1, 0)
    axis west -> east
    state s {{ sw (0, 0) se (1, 0) ne (1, 0.4) nw (0, 0.5) }}
}}
model {{ a = b3 }}"
    );
    let d = err(&src, &[]);
    assert_eq!(codes(&d), ["E010", "E010", "E010"], "{d:?}");
    assert!(
        d.iter()
            .all(|d| d.secondary[0].message.contains("inherited from"))
    );
}

#[test]
fn an_error_in_the_base_is_reported_once_not_on_its_children() {
    let src = format!(
        "{}
piece a extends brick {{ }}
piece b extends a {{ vertex q (3, 3) }}
merge brick.east onto brick.west into b.east
stretch a from west to east
model {{ x = a  y = b at (0, 4) }}",
        BRICK.replace("site west: joint", "site west: jiont")
    );
    let d = err(&src, &[]);
    assert_eq!(
        codes(&d),
        ["E011"],
        "{}",
        render(&d, &src, "g/main.clay", false)
    );
}

#[test]
fn an_unknown_base_is_one_error_with_a_suggestion_and_the_child_stays_silent() {
    let src = format!(
        "{BRICK}
piece tee extends brik {{
    vertex top (0.5, 1)
    site north: joint [top, nw] out (0, 1)
}}
merge brick.east onto brick.west into tee.north
model {{ w = chain brick x 2 along west -> east  t = tee at (0, 4)  dock t.east to w[0].west }}"
    );
    let d = err(&src, &[]);
    assert_eq!(
        codes(&d),
        ["E011"],
        "{}",
        render(&d, &src, "g/main.clay", false)
    );
    assert_eq!(d.items[0].hints, ["did you mean `brick`?"]);
    // Rules that name the child say nothing either, even where the child's own statements
    // alone would not fit (its one-vertex site against a two-vertex one).
    let src = src.replace("[top, nw]", "[top]");
    let d = err(&src, &[]);
    assert_eq!(
        codes(&d),
        ["E011"],
        "{}",
        render(&d, &src, "g/main.clay", false)
    );
}

#[test]
fn extends_cycles_are_one_error_naming_the_chain() {
    let src = format!(
        "{BRICK}
piece a extends b {{ }}
piece b extends c {{ }}
piece c extends a {{ }}
piece d extends a {{ }}
piece me extends me {{ }}
model {{ x = d  y = me at (0, 5) }}"
    );
    let d = err(&src, &[]);
    let e: Vec<_> = d.iter().filter(|d| d.is_error()).collect();
    let errors: Vec<&str> = e.iter().map(|d| d.code).collect();
    assert_eq!(errors, ["E062", "E062"], "{d:?}");
    assert!(
        e[0].message
            .contains("`a` extends `b`, which extends `c`, which extends `a`"),
        "{}",
        e[0].message
    );
    assert_eq!(e[0].secondary.len(), 2);
    assert_eq!(e[1].message, "piece `me` extends itself");
}

#[test]
fn inherited_states_cover_the_base_vertices_and_new_vertices_need_a_full_piece() {
    let base = "piece flap {
    vertex a (0, 0)
    vertex b (1, 0)
    edges a-b
    state up { a (0, 0) b (0, 1) }
}
";
    let src = format!(
        "{base}piece flap2 extends flap {{ state down {{ a (0, 0) b (0, -1) }} }}\nmodel {{ f = flap2 }}"
    );
    let c = ok(&src, &[]);
    let names: Vec<&str> = piece(&c.grammar, "flap2")
        .states
        .iter()
        .map(|s| s.name.as_str())
        .collect();
    assert_eq!(names, ["base", "up", "down"]);

    let src =
        format!("{base}piece flap3 extends flap {{ vertex c (2, 0) }}\nmodel {{ f = flap3 }}");
    let d = err(&src, &[]);
    assert_eq!(codes(&d), ["E020"], "{d:?}");
    assert!(d.items[0].message.contains("inherited state `up`"), "{d:?}");
    assert!(
        d.items[0].secondary[0]
            .message
            .contains("inherited from `flap`")
    );
}

#[test]
fn inherited_skinned_geometry_needs_the_childs_own_axis() {
    // brick's axis comes from its stretch rule, which does not make `plain` a chain element.
    let src = format!(
        "{}
piece plain extends brick {{ }}
stretch brick from west to east
model {{ w = chain brick x 2  p = plain at (0, 3) }}",
        BRICK.replace("polygon fill", "polygon skinned fill")
    );
    let d = err(&src, &[]);
    assert_eq!(codes(&d), ["E027"], "{d:?}");
    assert!(
        d.items[0]
            .hints
            .iter()
            .any(|h| h.contains("inherits this geometry from `brick`"))
    );
    let with_axis = src.replace(
        "piece plain extends brick { }",
        "piece plain extends brick { axis west -> east }",
    );
    ok(&with_axis, &[]);
}

#[test]
fn a_base_used_only_by_its_children_is_not_unused() {
    let src =
        format!("{BRICK}\npiece b2 extends brick {{ axis west -> east }}\nmodel {{ x = b2 }}");
    let c = ok(&src, &[]);
    assert!(c.warnings.is_empty(), "{:?}", c.warnings);
}

#[test]
fn a_deep_extends_chain_is_one_limit_error_and_a_long_allowed_one_compiles() {
    let chain = |n: usize| {
        let mut s = format!("{BRICK}piece p0 extends brick {{ axis west -> east }}\n");
        for i in 1..n {
            s += &format!("piece p{i} extends p{} {{ vertex v{i} ({i}, 9) }}\n", i - 1);
        }
        s + &format!("model {{ x = p{} }}", n - 1)
    };
    let c = ok(&chain(clay_dsl::MAX_EXTENDS_DEPTH), &[]);
    assert_eq!(
        piece(&c.grammar, &format!("p{}", clay_dsl::MAX_EXTENDS_DEPTH - 1))
            .vertices
            .len(),
        4 + clay_dsl::MAX_EXTENDS_DEPTH - 1
    );
    let d = err(&chain(2000), &[]);
    assert_eq!(codes(&d), ["E063"], "{d:?}");
}

#[test]
fn imports_bring_site_types_pieces_and_rules_but_not_model_or_solver() {
    let lib = format!(
        "{BRICK}
solver {{ hysteresis = 0.5 }}
stretch brick from west to east {{ min 3 }}
piece spare {{ vertex a (0, 0) }}
model {{ never = brick }}"
    );
    let src = "import \"lib/brick.clay\"\nmodel { w = chain brick x 4 }";
    let c = ok(src, &[("g/lib/brick.clay", &lib)]);
    let g = &c.grammar;
    assert_eq!(g.stretch_rules[0].min, 3, "rules are imported");
    assert_eq!(
        g.solver.hysteresis, 0.15,
        "the library's solver block is not"
    );
    assert_eq!(g.assembly.instances.len(), 4, "nor is its model");
    // The library's unused `spare` is not the importer's warning.
    assert!(c.warnings.is_empty(), "{:?}", c.warnings);
    assert_eq!(c.imported_files().collect::<Vec<_>>(), ["g/lib/brick.clay"]);
}

#[test]
fn a_file_imported_twice_or_through_two_libraries_is_loaded_once() {
    let files = [
        ("g/lib/brick.clay", BRICK),
        (
            "g/lib/a.clay",
            "import \"brick.clay\"\npiece a extends brick { axis west -> east }",
        ),
        (
            "g/b.clay",
            "import \"lib/brick.clay\"\npiece b extends brick { axis west -> east }",
        ),
    ];
    let src = "import \"lib/a.clay\"\nimport \"b.clay\"\nimport \"./lib/../lib/brick.clay\"\nmodel { x = a  y = b at (0, 3) }";
    let c = ok(src, &files);
    assert_eq!(c.grammar.pieces.len(), 3);
    assert_eq!(c.imported_files().count(), 3);
}

#[test]
fn warnings_in_an_imported_file_render_against_that_file() {
    let lib = BRICK.replace(
        "edges sw-se-ne-nw-sw, sw-ne",
        "edges sw-se-ne-nw-sw, sw-ne, ne-sw",
    );
    let src = "import \"lib/brick.clay\"\nmodel { b = brick }";
    let c = ok(src, &[("g/lib/brick.clay", &lib)]);
    assert_eq!(codes(&c.warnings), ["W003"]);
    let text = render(&c.warnings, src, "g/main.clay", false);
    assert!(text.contains("g/lib/brick.clay:8:"), "{text}");
    assert!(
        text.contains("ne-sw"),
        "the imported source is shown: {text}"
    );
}

#[test]
fn a_local_declaration_clashing_with_an_imported_one_shows_both_files() {
    let src = "import \"lib/brick.clay\"\nsite type joint\nmodel { b = brick }";
    let d = err(src, &[("g/lib/brick.clay", BRICK)]);
    assert_eq!(codes(&d), ["E010"]);
    let text = render(&d, src, "g/main.clay", false);
    assert!(text.contains("g/main.clay:2:11"), "{text}");
    assert!(text.contains("g/lib/brick.clay:1:11"), "{text}");
}

#[test]
fn import_failures_are_reported_at_the_import_and_stop_the_compile() {
    // Missing: one error, not a cascade of unknown pieces.
    let src = "import \"lib/nope.clay\"\nmodel { b = brick }";
    let d = err(src, &[]);
    assert_eq!(codes(&d), ["E060"]);
    assert!(d.items[0].message.contains("g/lib/nope.clay"));
    // Not UTF-8.
    let d = compile(
        "import \"bin.clay\"",
        "g/main.clay",
        &CompileOptions::with_loader(&Mem(HashMap::from([(
            "g/bin.clay".to_string(),
            vec![0xff, 0, 1],
        )]))),
    )
    .unwrap_err();
    assert_eq!(codes(&d), ["E003"]);
    // Itself.
    let d = err("import \"main.clay\"", &[]);
    assert_eq!(codes(&d), ["E061"]);
    assert_eq!(d.items[0].message, "`g/main.clay` imports itself");
    // A cycle through two files: the chain is named and every import of it shown.
    let d = err(
        "import \"a.clay\"",
        &[
            ("g/a.clay", "import \"b.clay\""),
            ("g/b.clay", "import \"main.clay\""),
        ],
    );
    assert_eq!(codes(&d), ["E061"]);
    assert_eq!(
        d.items[0].message,
        "import cycle: `g/main.clay` imports `g/a.clay`, which imports `g/b.clay`, which imports `g/main.clay`"
    );
    assert_eq!(d.items[0].secondary.len(), 2);
    // A syntax error in a library names the library.
    let src = "import \"lib.clay\"";
    let d = err(src, &[("g/lib.clay", "site type a\npiece {")]);
    assert_eq!(codes(&d), ["E001"]);
    let json = to_json(&d, src, "g/main.clay");
    assert_eq!((json[0].file.as_str(), json[0].line), ("g/lib.clay", 2));
}

#[test]
fn too_many_imports_is_one_limit_error() {
    let n = clay_dsl::MAX_IMPORTS + 5;
    let mut files: Vec<(String, String)> = (0..n)
        .map(|i| {
            (
                format!("g/f{i}.clay"),
                format!("import \"f{}.clay\"\n", i + 1),
            )
        })
        .collect();
    files.push((format!("g/f{n}.clay"), String::new()));
    let refs: Vec<(&str, &str)> = files
        .iter()
        .map(|(a, b)| (a.as_str(), b.as_str()))
        .collect();
    let d = err("import \"f0.clay\"", &refs);
    assert_eq!(codes(&d), ["E063"], "{d:?}");
}

#[test]
fn compile_reads_imports_from_the_file_system_relative_to_the_importer() {
    let dir = std::env::temp_dir().join(format!("clay-reuse-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("lib")).unwrap();
    std::fs::write(dir.join("lib/brick.clay"), BRICK).unwrap();
    let main = dir.join("main.clay");
    let src =
        "import \"lib/brick.clay\"\nstretch brick from west to east\nmodel { w = chain brick x 2 }";
    let c = compile(src, &main.to_string_lossy(), &CompileOptions::default()).unwrap();
    assert_eq!(c.grammar.pieces.len(), 1);
    std::fs::remove_dir_all(&dir).unwrap();
}
