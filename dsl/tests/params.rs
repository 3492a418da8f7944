//! Grammar parameters (issue 39): `param NAME = EXPR [in LO..HI]` parses, compiles with and
//! without overrides, lists itself in the compiled grammar, reports each mistake once with its
//! own code, formats canonically, and takes any value in its range.

use clay_dsl::syntax::{ExprKind, Item};
use clay_dsl::{
    CompileOptions, Compiled, CompiledGrammar, Diagnostic, Diagnostics, compile, decode_utf8,
    format, parse,
};
use proptest::prelude::*;

/// A wall of `bays` bricks (a parameter), each `width` wide (a parameter) and half as tall (a `let`).
const WALL: &str = "\
// The wall's bays can be set from outside.
param bays = 4 in 2..12
param width = 1 in 0.5..2
let height = width / 2

site type joint

piece brick {
    vertex sw (0, 0)
    vertex se (width, 0)
    vertex ne (width, height)
    vertex nw (0, height)
    edges sw-se-ne-nw-sw, sw-ne
    site west: joint [nw, sw] out (-1, 0)
    site east: joint [se, ne] out (1, 0)
}

stretch brick from west to east

model {
    wall = chain brick x bays at (0, 0)
}
";

fn with(source: &str, params: &[(&str, f64)]) -> Result<Compiled, Diagnostics> {
    let mut options = CompileOptions::default();
    for (name, value) in params {
        options = options.param(*name, *value);
    }
    compile(source, "wall.clay", &options)
}

fn ok(source: &str, params: &[(&str, f64)]) -> CompiledGrammar {
    match with(source, params) {
        Ok(c) => {
            assert!(c.warnings.is_empty(), "{:?}", c.warnings.items);
            c.grammar
        }
        Err(d) => panic!("{:#?}", d.items),
    }
}

/// The one error a compile gives.
fn only_error(source: &str, params: &[(&str, f64)]) -> Diagnostic {
    let diags = with(source, params).expect_err("the compile fails");
    assert_eq!(diags.len(), 1, "{:#?}", diags.items);
    diags.items.into_iter().next().unwrap()
}

fn text<'a>(source: &'a str, d: &Diagnostic) -> &'a str {
    &source[d.primary.span.start..d.primary.span.end]
}

fn secondary<'a>(source: &'a str, d: &Diagnostic) -> Vec<&'a str> {
    d.secondary
        .iter()
        .map(|l| &source[l.span.start..l.span.end])
        .collect()
}

/// A brick's width: the x of its `se` vertex.
fn brick_width(g: &CompiledGrammar) -> f64 {
    g.pieces[0].states[0].positions[1].x
}

#[test]
fn a_param_parses_with_and_without_its_range() {
    let file = parse("param bays = 4 in 2..12\nparam w = 2 * 0.5\nparam a = -1.5 in -2.5..(1+1)\n")
        .unwrap();
    let params: Vec<_> = file
        .items
        .iter()
        .map(|i| match i {
            Item::Param(p) => p,
            other => panic!("not a param: {other:?}"),
        })
        .collect();
    assert_eq!(params.len(), 3);
    assert_eq!(params[0].name.name, "bays");
    assert_eq!(default_expr(&params[0].value).kind, ExprKind::Number(4.0));
    let range = params[0].range.as_ref().unwrap();
    assert_eq!(range.low.kind, ExprKind::Number(2.0));
    assert_eq!(range.high.kind, ExprKind::Number(12.0));
    assert!(params[1].range.is_none());
    assert!(matches!(
        default_expr(&params[1].value).kind,
        ExprKind::Binary(..)
    ));
    let range = params[2].range.as_ref().unwrap();
    assert!(matches!(range.low.kind, ExprKind::Unary(..)));
    assert!(matches!(range.high.kind, ExprKind::Paren(..)));
    // The range spans from `in` to its end; the declaration ends with it.
    let text = "param bays = 4 in 2..12";
    let file = parse(text).unwrap();
    let Item::Param(p) = &file.items[0] else {
        panic!()
    };
    let r = p.range.as_ref().unwrap();
    assert_eq!(&text[r.span.start..r.span.end], "in 2..12");
    assert_eq!(p.span.end, text.len());
}

#[test]
fn a_fraction_before_the_range_dots_is_still_a_number() {
    // `1..8` is 1, `..`, 8, and `0.5..1.5` is 0.5, `..`, 1.5: a `.` followed by a `.` is not
    // a fraction's point.
    for (text, low, high) in [
        ("param p = 1 in 1..8", 1.0, 8.0),
        ("param p = 1 in 0.5..1.5", 0.5, 1.5),
        ("param p = 1 in .5 .. 2.", 0.5, 2.0),
        ("param p = 1 in 0..1e1", 0.0, 10.0),
    ] {
        let file = parse(text).unwrap_or_else(|d| panic!("{text}: {:?}", d.items));
        let Item::Param(p) = &file.items[0] else {
            panic!()
        };
        let r = p.range.as_ref().unwrap();
        assert_eq!(r.low.kind, ExprKind::Number(low), "{text}");
        assert_eq!(r.high.kind, ExprKind::Number(high), "{text}");
    }
    // A fraction elsewhere is unchanged.
    assert!(parse("let a = 1.\nlet b = 1.5e3\n").is_ok());
    assert_eq!(
        parse("param p = 1 in 1 . . 8").unwrap_err().items[0].code,
        "E001"
    );
}

#[test]
fn param_and_in_stay_contextual_keywords() {
    // `param` and `in` may name a vertex, as other keywords may.
    let src = "site type s\npiece p {\n    vertex param (0, 0)\n    vertex in (1, 0)\n    edges param-in\n}\nmodel {\n    x = p\n}\n";
    compile(src, "t.clay", &CompileOptions::default()).unwrap();
}

#[test]
fn without_overrides_a_param_is_its_default_and_is_listed() {
    let g = ok(WALL, &[]);
    assert_eq!(g.assembly.instances.len(), 4);
    assert_eq!(brick_width(&g), 1.0);
    let listed: Vec<_> = g
        .params
        .iter()
        .map(|p| {
            (
                p.name.as_str(),
                number(&p.value),
                number(&p.default),
                p.range,
            )
        })
        .collect();
    assert_eq!(
        listed,
        [
            ("bays", 4.0, 4.0, Some([2.0, 12.0])),
            ("width", 1.0, 1.0, Some([0.5, 2.0])),
        ]
    );
}

#[test]
fn an_override_replaces_the_default_wherever_the_param_is_used() {
    let g = ok(WALL, &[("bays", 7.0), ("width", 1.5)]);
    assert_eq!(g.assembly.instances.len(), 7);
    assert_eq!(brick_width(&g), 1.5);
    // `let height = width / 2` follows the override.
    assert_eq!(g.pieces[0].states[0].positions[2].y, 0.75);
    assert_eq!(g.params[0].value, 7.0);
    assert_eq!(g.params[0].default, 4.0);
    assert_eq!(g.params[1].value, 1.5);
    // The ends of the range are in it; of two values for one name the last counts.
    assert_eq!(ok(WALL, &[("bays", 2.0)]).assembly.instances.len(), 2);
    assert_eq!(ok(WALL, &[("bays", 12.0)]).assembly.instances.len(), 12);
    assert_eq!(
        ok(WALL, &[("bays", 3.0), ("bays", 5.0)])
            .assembly
            .instances
            .len(),
        5
    );
}

#[test]
fn a_param_without_a_range_takes_any_finite_value() {
    let src = WALL.replace("param width = 1 in 0.5..2", "param width = 1");
    let g = ok(&src, &[("width", 3.25)]);
    assert_eq!(brick_width(&g), 3.25);
    assert_eq!(g.params[1].range, None);
    let d = only_error(&src, &[("width", f64::INFINITY)]);
    assert_eq!(d.code, "E071");
    assert!(d.message.contains("not a finite number"), "{}", d.message);
    assert_eq!(text(&src, &d), "width");
    assert_eq!(only_error(&src, &[("width", f64::NAN)]).code, "E071");
}

#[test]
fn the_bytes_entry_point_and_the_plain_one_agree() {
    let options = CompileOptions::default().param("bays", 5.0);
    let a = decode_utf8(WALL.as_bytes())
        .and_then(|s| compile(s, "wall.clay", &options))
        .unwrap();
    let b = compile(WALL, "wall.clay", &options).unwrap();
    assert_eq!(a.grammar, b.grammar);
    // `compile` is the options' default.
    assert_eq!(
        compile(WALL, "wall.clay", &CompileOptions::default())
            .unwrap()
            .grammar,
        with(WALL, &[]).unwrap().grammar
    );
}

#[test]
fn the_compiled_grammar_lists_its_params_in_json_and_reads_older_files() {
    let g = ok(WALL, &[("bays", 6.0)]);
    let value = serde_json::to_value(&g).unwrap();
    assert_eq!(
        value["params"][0],
        serde_json::json!({"name": "bays", "value": 6.0, "default": 4.0, "range": [2.0, 12.0]})
    );
    let back: CompiledGrammar = serde_json::from_value(value.clone()).unwrap();
    assert_eq!(back, g);
    // A file written before parameters existed reads with none.
    let mut old = value;
    old.as_object_mut().unwrap().remove("params");
    let back: CompiledGrammar = serde_json::from_value(old).unwrap();
    assert!(back.params.is_empty());
}

#[test]
fn a_param_of_an_imported_file_is_a_param_of_the_grammar() {
    struct Lib;
    impl clay_dsl::Loader for Lib {
        fn load(&self, path: &str) -> std::io::Result<Vec<u8>> {
            match path {
                "lib.clay" => Ok(LIB.as_bytes().to_vec()),
                _ => Err(std::io::ErrorKind::NotFound.into()),
            }
        }
    }
    // A library's parameter, used by the library's piece (a library's constants are its own,
    // as its `let`s are).
    const LIB: &str = "param lane = 3 in 2..5\nsite type s\npiece p {\n    vertex a (0, 0)\n    vertex b (lane, 0)\n    edges a-b\n}\n";
    let src = "import \"lib.clay\"\n\nmodel {\n    x = p\n}\n";
    let options = CompileOptions::with_loader(&Lib).param("lane", 4.0);
    let g = compile(src, "main.clay", &options).unwrap().grammar;
    assert_eq!(g.params[0].name, "lane");
    assert_eq!(g.pieces[0].states[0].positions[1].x, 4.0);
    // Its override error points into the library, where the parameter is declared.
    let options = CompileOptions::with_loader(&Lib).param("lane", 9.0);
    let d = compile(src, "main.clay", &options).unwrap_err();
    assert_eq!(d.len(), 1);
    assert_eq!(d.items[0].code, "E071");
    assert!(d.items[0].primary.span.start > src.len());
    let shown = clay_dsl::render(&d, src, "main.clay", false);
    assert!(shown.contains("lib.clay:1:7"), "{shown}");
}

#[test]
fn the_language_doc_example_of_params_compiles_as_it_says() {
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/language.md"))
        .unwrap();
    let section = &doc[doc.find("## Parameters").expect("the section")..];
    let start = section.find("```clay\n").expect("an example") + "```clay\n".len();
    let example = &section[start..start + section[start..].find("```").unwrap()];
    // "Compiled as it is, this is a fence of 6 bays 2 m wide".
    let g = ok(example, &[]);
    assert_eq!(g.assembly.instances.len(), 6);
    assert_eq!(brick_width(&g), 2.0);
    // "with `bays` set to 12 and `bay_width` to 1.5, a fence of 12 bays 1.5 m wide".
    let g = ok(example, &[("bays", 12.0), ("bay_width", 1.5)]);
    assert_eq!(g.assembly.instances.len(), 12);
    assert_eq!(brick_width(&g), 1.5);
    assert_eq!(format(example).unwrap(), example);
}

#[test]
fn keep_clay_sets_its_wall_height() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../grammars/keep.clay");
    let source = std::fs::read_to_string(path).unwrap();
    let wall_top = |g: &CompiledGrammar| {
        let wall = g.pieces.iter().find(|p| p.name == "wall").unwrap();
        wall.states[0].geometry[0].extrude.unwrap().height
    };
    let options = CompileOptions::default();
    let g = compile(&source, path, &options).unwrap().grammar;
    assert_eq!(wall_top(&g), 4.0);
    assert_eq!(g.params[0].range, Some([3.0, 6.0]));
    let options = CompileOptions::default().param("wall_height", 5.5);
    let g = compile(&source, path, &options).unwrap().grammar;
    assert_eq!(wall_top(&g), 5.5);
}

// ---- mistakes ------------------------------------------------------------------------------

#[test]
fn an_unknown_override_names_the_closest_and_all_parameters() {
    let d = only_error(WALL, &[("bys", 3.0)]);
    assert_eq!(d.code, "E070");
    assert_eq!(d.message, "unknown parameter `bys`");
    // No place in the file is wrong: the diagnostic sits at its start.
    assert_eq!((d.primary.span.start, d.primary.span.end), (0, 0));
    assert_eq!(secondary(WALL, &d), ["bays"]);
    assert_eq!(
        d.hints,
        ["did you mean `bays`?", "the parameters are `bays`, `width`"]
    );
    // Far from every name: no suggestion, the list.
    let d = only_error(WALL, &[("colour", 3.0)]);
    assert_eq!(d.hints, ["the parameters are `bays`, `width`"]);
    assert!(d.secondary.is_empty());
    // One error per name, however often it is given; each unknown name its own.
    let diags = with(WALL, &[("x", 1.0), ("x", 2.0), ("y", 1.0)]).unwrap_err();
    let codes: Vec<_> = diags.iter().map(|d| (d.code, d.message.as_str())).collect();
    assert_eq!(
        codes,
        [
            ("E070", "unknown parameter `x`"),
            ("E070", "unknown parameter `y`")
        ]
    );
}

#[test]
fn an_override_of_a_grammar_without_params_says_it_has_none() {
    let src = WALL
        .replace("param bays = 4 in 2..12", "")
        .replace("param width = 1 in 0.5..2", "let width = 1")
        .replace("x bays", "x 4");
    let d = only_error(&src, &[("bays", 3.0)]);
    assert_eq!(d.code, "E070");
    assert_eq!(
        d.hints,
        ["the grammar declares no parameters (`param NAME = VALUE`)"]
    );
}

#[test]
fn an_override_of_a_let_says_it_is_a_constant() {
    let d = only_error(WALL, &[("height", 1.0)]);
    assert_eq!(d.code, "E070");
    assert_eq!(
        d.message,
        "`height` is a constant, not a parameter: it cannot be set"
    );
    assert_eq!(text(WALL, &d), "height");
    assert_eq!(
        d.hints,
        ["declare it with `param height = ...` to let it be set"]
    );
}

#[test]
fn an_override_outside_the_range_names_the_parameter_and_its_range() {
    let d = only_error(WALL, &[("bays", 13.0)]);
    assert_eq!(d.code, "E071");
    assert_eq!(
        d.message,
        "parameter `bays` is set to 13, outside its range 2..12"
    );
    assert_eq!(text(WALL, &d), "bays");
    assert_eq!(secondary(WALL, &d), ["in 2..12"]);
    assert_eq!(d.hints, ["choose a value of `bays` from 2 to 12"]);
    let d = only_error(WALL, &[("width", 0.25)]);
    assert_eq!(
        d.message,
        "parameter `width` is set to 0.25, outside its range 0.5..2"
    );
}

#[test]
fn a_value_in_range_that_a_use_rejects_is_reported_at_the_use() {
    // A chain count must be whole: the range allows 2.5, the chain does not.
    let d = only_error(WALL, &[("bays", 2.5)]);
    assert_eq!(d.code, "E013");
    assert_eq!(text(WALL, &d), "bays");
    assert!(d.primary.span.start > WALL.find("model").unwrap());
}

#[test]
fn a_default_outside_its_range_is_e013() {
    let src = WALL.replace("param bays = 4 in 2..12", "param bays = 20 in 2..12");
    let d = only_error(&src, &[]);
    assert_eq!(d.code, "E013");
    assert_eq!(
        d.message,
        "the default of parameter `bays` is outside its range"
    );
    assert_eq!(text(&src, &d), "20");
    assert_eq!(secondary(&src, &d), ["in 2..12"]);
    // The parameter is poisoned: its uses are silent, and an override of it adds nothing.
    let d = only_error(&src, &[("bays", 5.0)]);
    assert_eq!(d.code, "E013");
}

#[test]
fn an_empty_range_is_e013_with_the_bounds_swapped_in_the_hint() {
    let src = WALL.replace("param bays = 4 in 2..12", "param bays = 4 in 12..2");
    let d = only_error(&src, &[]);
    assert_eq!(d.code, "E013");
    assert_eq!(
        d.message,
        "the range of parameter `bays` is empty: its low end is above its high end"
    );
    assert_eq!(text(&src, &d), "in 12..2");
    assert_eq!(d.hints, ["write the low end first: `in 2..12`"]);
    // A range of one value is allowed.
    let src = WALL.replace("param bays = 4 in 2..12", "param bays = 4 in 4..4");
    assert_eq!(ok(&src, &[]).params[0].range, Some([4.0, 4.0]));
}

#[test]
fn a_default_or_range_that_uses_a_parameter_is_e072() {
    // Directly.
    let src = WALL.replace(
        "param width = 1 in 0.5..2",
        "param width = bays / 4 in 0.5..2",
    );
    let d = only_error(&src, &[]);
    assert_eq!(d.code, "E072");
    assert_eq!(
        d.message,
        "the default of parameter `width` uses parameter `bays`"
    );
    assert_eq!(text(&src, &d), "bays");
    assert_eq!(secondary(&src, &d), ["bays"]);
    // Through a `let`, in the range; both ends using it is still one mistake.
    let src = WALL.replace(
        "param width = 1 in 0.5..2",
        "let most = bays\nparam width = 1 in most / 12..most",
    );
    let d = only_error(&src, &[]);
    assert_eq!(d.code, "E072");
    assert_eq!(
        d.message,
        "the range of parameter `width` uses `most`, which depends on parameter `bays`"
    );
    assert_eq!(text(&src, &d), "most");
    // A `let` that uses no parameter is fine.
    let src = WALL.replace(
        "param width = 1 in 0.5..2",
        "let unit = 0.5\nparam width = 2 * unit in unit..4 * unit",
    );
    assert_eq!(ok(&src, &[]).params[1].range, Some([0.5, 2.0]));
}

#[test]
fn a_param_and_a_let_of_one_name_are_e010() {
    let src = WALL.replace(
        "let height = width / 2",
        "let bays = 3\nlet height = width / 2",
    );
    let d = only_error(&src, &[]);
    assert_eq!(d.code, "E010");
    assert_eq!(
        d.message,
        "`bays` is defined twice, as a parameter and as a constant"
    );
    let decl = src.find("let bays").unwrap() + 4;
    assert_eq!(d.primary.span.start, decl);
    assert_eq!(secondary(&src, &d), ["bays"]);
    assert_eq!(d.secondary[0].message, "first defined here, with `param`");
    // And the other way round, and a parameter twice.
    let src = format!("let bays = 3\n{WALL}");
    let d = only_error(&src, &[]);
    assert_eq!(
        d.message,
        "`bays` is defined twice, as a constant and as a parameter"
    );
    let src = format!("param width = 1\n{WALL}");
    let d = only_error(&src, &[]);
    assert_eq!(d.message, "parameter `width` is defined twice");
    // A built-in name.
    let src = format!("param pi = 3\n{WALL}");
    let d = only_error(&src, &[]);
    assert_eq!((d.code, d.message.as_str()), ("E010", "`pi` is built in"));
}

#[test]
fn a_param_used_above_its_declaration_is_e052() {
    let src = WALL
        .replace("param bays = 4 in 2..12\n", "")
        .replace("model {", "param bays = 4 in 2..12\n\nmodel {");
    // A use in the model below the `param`: fine.
    ok(&src, &[]);
    let src = WALL.replace(
        "let height = width / 2",
        "let height = depth / 2\nparam depth = 1",
    );
    let d = only_error(&src, &[]);
    assert_eq!(d.code, "E052");
    assert_eq!(d.message, "parameter `depth` is used before its `param`");
}

#[test]
fn an_unused_param_is_w007() {
    let src = format!("param spare = 1 in 0..2\n{WALL}");
    let c = with(&src, &[("spare", 2.0)]).unwrap();
    let w: Vec<_> = c
        .warnings
        .iter()
        .map(|d| (d.code, d.message.as_str()))
        .collect();
    assert_eq!(w, [("W007", "parameter `spare` is never used")]);
    assert_eq!(c.grammar.params[0].value, 2.0);
}

#[test]
fn file_errors_and_override_errors_are_reported_together() {
    let src = WALL.replace("vertex nw (0, height)", "vertex nw (0, heigth)");
    let diags = with(&src, &[("bays", 99.0)]).unwrap_err();
    let codes: Vec<_> = diags.iter().map(|d| d.code).collect();
    assert_eq!(codes, ["E071", "E011"]);
}

// ---- editors ----------------------------------------------------------------------------------

#[test]
fn the_analysis_knows_a_param_as_a_constant_and_colours_its_keywords() {
    use clay_dsl::analysis::{Analysis, SymbolKind, TokenKind};
    let a = Analysis::new(WALL, "wall.clay");
    assert!(a.diagnostics().is_empty(), "{:?}", a.diagnostics().items);
    let decl = WALL.find("param bays").unwrap() + "param ".len();
    let used = WALL.find("x bays").unwrap() + "x ".len();
    assert_eq!(
        a.definition(used),
        Some(clay_dsl::syntax::Span::new(decl, decl + 4))
    );
    let tokens = a.semantic_tokens();
    let kind_at = |offset: usize| {
        tokens
            .iter()
            .find(|t| t.span.start == offset)
            .map(|t| (t.kind, t.declaration))
    };
    assert_eq!(
        kind_at(WALL.find("param bays").unwrap()),
        Some((TokenKind::Keyword, false))
    );
    assert_eq!(
        kind_at(decl),
        Some((TokenKind::Symbol(SymbolKind::Constant), true))
    );
    assert_eq!(
        kind_at(WALL.find(" in 2..12").unwrap() + 1),
        Some((TokenKind::Keyword, false))
    );
    // Renaming the parameter renames its uses.
    let edits = a.rename(used, "sections").unwrap();
    assert_eq!(edits.len(), 2);
}

// ---- formatting --------------------------------------------------------------------------------

#[test]
fn the_formatter_prints_params_canonically_and_round_trips() {
    let messy = "param   bays=4   in 2 .. 12 // the bays\nparam w = 2*0.5 in 0.5..(1+1)\nlet x = bays\n\nparam  free=-1";
    let formatted = format(messy).unwrap();
    assert_eq!(
        formatted,
        "param bays = 4 in 2..12 // the bays\nparam w = 2 * 0.5 in 0.5..(1 + 1)\nlet x = bays\n\nparam free = -1\n"
    );
    assert_eq!(format(&formatted).unwrap(), formatted);
    let canonical = format(WALL).unwrap();
    assert_eq!(canonical, WALL);
    for params in [&[][..], &[("bays", 9.0)][..]] {
        assert_eq!(ok(&canonical, params), ok(WALL, params));
    }
}

// ---- any value ---------------------------------------------------------------------------------

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// Any value in the range compiles, is listed, and is the value used.
    #[test]
    fn any_override_in_range_compiles(width in 0.5f64..=2.0, bays in 2u32..=12) {
        let g = ok(WALL, &[("width", width), ("bays", f64::from(bays))]);
        prop_assert_eq!(brick_width(&g), width);
        prop_assert_eq!(g.assembly.instances.len(), bays as usize);
        prop_assert_eq!(g.params[1].value.clone(), width);
    }

    /// Any value outside the range, or not finite, is exactly one error: E071 at the parameter.
    #[test]
    fn any_override_out_of_range_is_one_error(
        width in prop_oneof![
            -1e300f64..0.4999999,
            2.0000001f64..1e300,
            Just(f64::INFINITY),
            Just(f64::NEG_INFINITY),
            Just(f64::NAN),
        ],
    ) {
        let d = only_error(WALL, &[("width", width)]);
        prop_assert_eq!(d.code, "E071");
        prop_assert_eq!(text(WALL, &d), "width");
        prop_assert!(d.message.contains("`width`"), "{}", d.message);
    }
}

/// The expression of a number parameter's default.
fn default_expr(d: &clay_dsl::syntax::ParamDefault) -> &clay_dsl::syntax::Expr {
    match d {
        clay_dsl::syntax::ParamDefault::Expr(e) => e,
        other => panic!("not an expression: {other:?}"),
    }
}

/// The number a parameter's value holds.
fn number(v: &clay_dsl::compiled::ParamValue) -> f64 {
    v.number().expect("a number")
}
