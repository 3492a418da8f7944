//! Typed parameters (issue 48): `param NAME: int | bool | seed | choice(...)`. An `int` takes
//! whole numbers only, a `bool` switches `if` blocks of the model, a `choice` picks the piece
//! a model statement names, a `seed` shuffles the variants of the model's chains; a value of
//! the wrong type is E073 at its span, and a grammar must compile with every switch value.

use clay_dsl::compiled::{CompiledGrammar, ParamKind, ParamValue};
use clay_dsl::{CompileOptions, Compiled, Diagnostics, compile, format};

/// Two towers (or posts) joined by a wall of `bays` bricks of one of two kinds.
const FORT: &str = "\
param bays: int = 4 in 2..12
param towers: bool = true
param wall: choice(\"brick\", \"stone\") = \"brick\"
let tower_size = 2

site type joint

piece brick {
    vertex sw (0, 0)
    vertex se (1, 0)
    vertex ne (1, 0.5)
    vertex nw (0, 0.5)
    edges sw-se-ne-nw-sw, sw-ne
    site west: joint [nw, sw] out (-1, 0)
    site east: joint [se, ne] out (1, 0)
}

piece stone extends brick {
    polygon fill #808080 { (0, 0) (1, 0) (1, 0.5) (0, 0.5) }
}

piece tower {
    vertex a (0, 0)
    vertex b (tower_size, 0)
    vertex c (tower_size, 0.5)
    vertex d (0, 0.5)
    edges a-b-c-d-a, a-c
    site east: joint [b, c] out (1, 0)
}

piece post {
    vertex a (0, 0)
    vertex b (0.2, 0)
    vertex c (0.2, 0.5)
    vertex d (0, 0.5)
    edges a-b-c-d-a, a-c
    site east: joint [b, c] out (1, 0)
}

stretch brick from west to east {
    variants { brick 0.5, stone 0.5 }
}

model {
    w = chain wall x bays at (0, 0)
    if towers {
        t = tower
        dock t.east to w[0].west
    } else {
        t = post
        dock t.east to w[0].west
    }
}
";

fn with(source: &str, params: &[(&str, ParamValue)]) -> Result<Compiled, Diagnostics> {
    let mut options = CompileOptions::default();
    for (name, value) in params {
        options = options.param(*name, value.clone());
    }
    compile(source, "fort.clay", &options)
}

fn ok(source: &str, params: &[(&str, ParamValue)]) -> CompiledGrammar {
    match with(source, params) {
        Ok(c) => {
            assert!(c.warnings.is_empty(), "{:#?}", c.warnings.items);
            c.grammar
        }
        Err(d) => panic!("{:#?}", d.items),
    }
}

/// The pieces of the model's instances, by name.
fn pieces(g: &CompiledGrammar) -> Vec<String> {
    (g.assembly.instances.iter())
        .map(|i| g.pieces[i.piece].name.clone())
        .collect()
}

/// The errors of a compile that must fail: (code, line, message, hints).
fn errors(source: &str, params: &[(&str, ParamValue)]) -> Vec<(String, usize, String, String)> {
    let diags = with(source, params).expect_err("the compile fails");
    (diags.items.iter())
        .filter(|d| d.is_error())
        .map(|d| {
            let line = source[..d.primary.span.start].lines().count();
            (
                d.code.to_string(),
                line,
                d.message.clone(),
                d.hints.join(" | "),
            )
        })
        .collect()
}

#[test]
fn the_parameters_are_listed_with_their_types_and_values() {
    let g = ok(FORT, &[]);
    let kinds: Vec<(&str, &ParamKind, &ParamValue)> = (g.params.iter())
        .map(|p| (p.name.as_str(), &p.kind, &p.value))
        .collect();
    let choices = ParamKind::Choice {
        choices: vec!["brick".into(), "stone".into()],
    };
    assert_eq!(
        kinds,
        [
            ("bays", &ParamKind::Int, &ParamValue::Number(4.0)),
            ("towers", &ParamKind::Bool, &ParamValue::Bool(true)),
            ("wall", &choices, &ParamValue::Text("brick".into())),
        ]
    );
    // The compiled grammar's JSON gives the types and reads back.
    let json = serde_json::to_value(&g).unwrap();
    assert_eq!(json["params"][1]["kind"]["type"], "bool");
    assert_eq!(json["params"][1]["value"], true);
    assert_eq!(json["params"][2]["kind"]["choices"][1], "stone");
    let back: CompiledGrammar = serde_json::from_value(json).unwrap();
    assert_eq!(back, g);
}

#[test]
fn a_bool_switches_its_blocks_and_a_choice_picks_the_piece() {
    let g = ok(FORT, &[]);
    assert_eq!(pieces(&g), ["brick", "brick", "brick", "brick", "tower"]);
    let g = ok(FORT, &[("towers", false.into()), ("wall", "stone".into())]);
    assert_eq!(pieces(&g), ["stone", "stone", "stone", "stone", "post"]);
    // The post is docked where the tower was, at the wall's west end.
    let post = &g.assembly.instances[4];
    assert_eq!(post.name, "t");
    let g = ok(FORT, &[("bays", 7.0.into())]);
    assert_eq!(g.assembly.instances.len(), 8);
}

#[test]
fn a_value_of_the_wrong_type_is_one_error_at_the_parameter() {
    // The declarations are on lines 1 to 3.
    for (name, value, line, says) in [
        (
            "bays",
            ParamValue::Number(2.5),
            1,
            "is an `int`, and 2.5 is not one",
        ),
        (
            "bays",
            ParamValue::Text("lots".into()),
            1,
            "\"lots\" is not one",
        ),
        (
            "towers",
            ParamValue::Number(1.0),
            2,
            "is a `bool`, and 1 is not one",
        ),
        (
            "wall",
            ParamValue::Text("brik".into()),
            3,
            "\"brik\" is not one",
        ),
    ] {
        let errs = errors(FORT, &[(name, value.clone())]);
        assert_eq!(errs.len(), 1, "{name}={value}: {errs:#?}");
        let (code, at, message, hints) = &errs[0];
        assert_eq!((code.as_str(), *at), ("E073", line), "{errs:#?}");
        assert!(message.contains(says), "{message}");
        if name == "wall" {
            assert!(hints.contains("did you mean \"brick\"?"), "{hints}");
        }
    }
    // A bool given as the text a command line or a script gives is accepted.
    let g = ok(FORT, &[("towers", ParamValue::parse("false"))]);
    assert_eq!(pieces(&g).last().map(String::as_str), Some("post"));
}

#[test]
fn a_default_or_range_that_does_not_fit_its_type_is_reported_where_it_is_written() {
    for (decl, code, says) in [
        (
            "param n: int = 2.5",
            "E073",
            "the default of `int` parameter `n` is 2.5",
        ),
        (
            "param n: int = 2 in 1..9.5",
            "E073",
            "the high end of `int` parameter `n`",
        ),
        ("param n: seed = -1", "E073", "not a whole number from 0"),
        ("param n: bool = 1", "E073", "does not fit its type `bool`"),
        ("param n: bool = true in 0..1", "E073", "it has no range"),
        (
            "param n: choice(\"a\", \"b\") = \"c\"",
            "E073",
            "not one of its choices",
        ),
        (
            "param n: choice(\"a\", \"b\") = 1",
            "E073",
            "does not fit its type `choice`",
        ),
        (
            "param n: choice(\"a\", \"a\") = \"a\"",
            "E010",
            "listed twice",
        ),
        (
            "param n: integer = 2",
            "E073",
            "unknown parameter type `integer`",
        ),
        ("param n = \"a\"", "E073", "does not fit its type number"),
    ] {
        let source = format!("{decl}\nlet m = 1\n");
        let errs = errors(&source, &[]);
        assert_eq!(errs.len(), 1, "{decl}: {errs:#?}");
        assert_eq!(errs[0].0, code, "{decl}: {errs:#?}");
        assert!(errs[0].2.contains(says), "{decl}: {}", errs[0].2);
    }
    let errs = errors("param n: integer = 2\n", &[]);
    assert!(errs[0].3.contains("did you mean `int`?"), "{errs:#?}");
}

#[test]
fn a_switch_where_a_number_goes_and_a_number_where_a_switch_goes_are_errors() {
    let source = FORT.replace("chain wall x bays", "chain wall x towers");
    let errs = errors(&source, &[]);
    assert_eq!(errs.len(), 1, "{errs:#?}");
    assert_eq!(errs[0].0, "E073");
    assert!(
        errs[0].2.contains("`towers` is a `bool`, not a number"),
        "{errs:#?}"
    );
    let source = FORT.replace("if towers", "if bays");
    let errs = errors(&source, &[]);
    assert_eq!(errs.len(), 1, "{errs:#?}");
    assert!(
        errs[0]
            .2
            .contains("`bays` is an `int` parameter, not a `bool` parameter"),
        "{errs:#?}"
    );
    let source = FORT.replace("if towers", "if tower");
    let errs = errors(&source, &[]);
    assert_eq!(errs.len(), 1, "{errs:#?}");
    assert!(errs[0].2.contains("unknown parameter `tower`"), "{errs:#?}");
    assert!(errs[0].3.contains("did you mean `towers`?"), "{errs:#?}");
}

#[test]
fn a_choice_that_names_no_piece_is_an_error_at_its_string() {
    let source = FORT.replace(
        "choice(\"brick\", \"stone\")",
        "choice(\"brick\", \"stoen\")",
    );
    let errs = errors(&source, &[]);
    assert_eq!(errs.len(), 1, "{errs:#?}");
    assert_eq!((errs[0].0.as_str(), errs[0].1), ("E011", 3), "{errs:#?}");
    assert!(
        errs[0]
            .2
            .contains("unknown piece `stoen` among the choices of `wall`"),
        "{errs:#?}"
    );
    assert!(errs[0].3.contains("did you mean `stone`?"), "{errs:#?}");
}

#[test]
fn every_switch_value_must_compile_and_its_errors_say_which() {
    // Only the `else` branch is broken: the default (towers on) still reports it.
    let source = FORT.replace("t = post", "t = pots");
    let errs = errors(&source, &[]);
    assert_eq!(errs.len(), 1, "{errs:#?}");
    let (code, line, message, hints) = &errs[0];
    assert_eq!(
        (code.as_str(), message.as_str()),
        ("E011", "unknown piece `pots`")
    );
    assert_eq!(
        *line,
        source.lines().position(|l| l.contains("pots")).unwrap() + 1
    );
    assert!(
        hints.contains("this happens with `towers` set to false"),
        "{hints}"
    );
    // A choice whose third piece has no stretch rule: no chain of it can be made.
    let source = FORT.replace("\"stone\")", "\"stone\", \"plank\")").replace(
        "piece post {",
        "piece plank extends post {}\n\npiece post {",
    );
    let errs = errors(&source, &[]);
    assert_eq!(errs.len(), 1, "{errs:#?}");
    assert!(
        errs[0].2.contains("chain of `plank` has no sites"),
        "{errs:#?}"
    );
    assert!(
        errs[0].3.contains("with `wall` set to \"plank\""),
        "{errs:#?}"
    );
}

#[test]
fn a_dock_outside_an_if_on_an_instance_inside_it_says_where_to_move_it() {
    let source = FORT
        .replace(
            "    } else {\n        t = post\n        dock t.east to w[0].west\n    }",
            "    }\n    dock t.east to w[0].west",
        )
        .replace(
            "        t = tower\n        dock t.east to w[0].west\n",
            "        t = tower\n",
        );
    // With towers on, the dock is fine; off, `t` is not in the model.
    let errs = errors(&source, &[]);
    assert_eq!(errs.len(), 1, "{errs:#?}");
    assert!(
        errs[0]
            .2
            .contains("instance `t` is in the model only when `towers` is true"),
        "{errs:#?}"
    );
    assert!(
        errs[0]
            .3
            .contains("move this `dock` into `if towers { ... }`"),
        "{errs:#?}"
    );
}

#[test]
fn what_only_a_switched_off_branch_uses_is_not_unused() {
    // `tower_size` is used by `tower` only, `post` only in the `else`: no W001 or W007
    // with towers off, with towers on.
    for towers in [true, false] {
        let c = with(FORT, &[("towers", towers.into())]).unwrap();
        assert!(c.warnings.is_empty(), "{:#?}", c.warnings.items);
    }
}

#[test]
fn a_seed_draws_each_chain_from_its_variants_at_their_frequencies() {
    let source = FORT
        .replace(
            "let tower_size = 2",
            "let tower_size = 2\nparam look: seed = 1",
        )
        .replace("x bays at", "x 10 at")
        .replace("param bays: int = 4 in 2..12\n", "");
    let order = |seed: f64| {
        let g = ok(&source, &[("look", seed.into())]);
        let p = pieces(&g);
        assert_eq!(p.iter().filter(|p| *p == "brick").count(), 5, "{p:?}");
        assert_eq!(p.iter().filter(|p| *p == "stone").count(), 5, "{p:?}");
        p
    };
    assert_eq!(order(1.0), order(1.0), "a seed gives one order");
    let orders: std::collections::HashSet<Vec<String>> =
        (0..8).map(|s| order(f64::from(s))).collect();
    assert!(orders.len() >= 4, "seeds give other orders: {orders:?}");
    // Without a seed parameter, a chain is its own piece throughout.
    assert_eq!(pieces(&ok(FORT, &[]))[..4], ["brick"; 4]);
}

#[test]
fn typed_parameters_and_if_blocks_format_canonically() {
    let messy = FORT
        .replace("param towers: bool = true", "param   towers :bool=true")
        .replace(
            "choice(\"brick\", \"stone\")",
            "choice( \"brick\",\"stone\" , )",
        )
        .replace("    } else {", "    }\n    // the other way\n    else {");
    let once = format(&messy).unwrap();
    assert!(once.contains("param towers: bool = true\n"), "{once}");
    assert!(
        once.contains("param wall: choice(\"brick\", \"stone\") = \"brick\"\n"),
        "{once}"
    );
    assert!(
        once.contains("    if towers {\n        t = tower\n"),
        "{once}"
    );
    assert!(
        once.contains("        // the other way\n    } else {\n"),
        "{once}"
    );
    assert_eq!(format(&once).unwrap(), once, "formatting is idempotent");
    assert_eq!(ok(&once, &[]), ok(FORT, &[]));
}
