//! Expressions and `let` constants (issue 18): values, precedence, degrees, one true error per
//! mistake pointing inside the expression, poisoned constants, and the formatter.

use clay_dsl::{CompileOptions, Diagnostic, compile, format};

/// A one-piece grammar with `lets` above it and the piece's single vertex at `point`.
fn grammar(lets: &str, point: &str) -> String {
    format!(
        "{lets}\nsite type s\npiece p {{\n    vertex a {point}\n    vertex b (5, 5)\n    edges a-b\n}}\nmodel {{\n    x = p\n}}\n"
    )
}

/// The position of vertex `a` when the grammar compiles.
fn vertex_a(lets: &str, point: &str) -> (f64, f64) {
    let c =
        compile(&grammar(lets, point), "t.clay", &CompileOptions::default()).unwrap_or_else(|d| {
            panic!(
                "{point}: {:?}",
                d.iter().map(|d| &d.message).collect::<Vec<_>>()
            )
        });
    let p = c.grammar.pieces[0].states[0].positions[0];
    (p.x, p.y)
}

/// The diagnostics of a grammar that must not compile.
fn errors(lets: &str, point: &str) -> Vec<Diagnostic> {
    let source = grammar(lets, point);
    compile(&source, "t.clay", &CompileOptions::default())
        .unwrap_err()
        .items
}

fn text_at(source: &str, d: &Diagnostic) -> String {
    source[d.primary.span.start..d.primary.span.end].to_string()
}

#[test]
fn arithmetic_follows_the_usual_precedence() {
    assert_eq!(vertex_a("", "(1 + 2 * 3, (1 + 2) * 3)"), (7.0, 9.0));
    assert_eq!(vertex_a("", "(2 - 3 - 4, 8 / 4 / 2)"), (-5.0, 1.0));
    assert_eq!(vertex_a("", "(-2 * 3, 2 * -3 + +1)"), (-6.0, -5.0));
    assert_eq!(vertex_a("", "(- -1, -(1 + 1))"), (1.0, -2.0));
    assert_eq!(vertex_a("", "(1e1 / 4, .5 - 0.25)"), (2.5, 0.25));
}

#[test]
fn functions_take_degrees_and_are_exact_at_right_angles() {
    assert_eq!(vertex_a("", "(cos(90), sin(180))"), (0.0, 0.0));
    assert_eq!(vertex_a("", "(cos(-180), sin(450))"), (-1.0, 1.0));
    let (x, y) = vertex_a("", "(sin(30), cos(60))");
    assert!(
        (x - 0.5).abs() < 1e-15 && (y - 0.5).abs() < 1e-15,
        "{x} {y}"
    );
    let (x, y) = vertex_a("", "(atan2(1, 1), atan(1) + acos(0))");
    assert!(
        (x - 45.0).abs() < 1e-12 && (y - 135.0).abs() < 1e-12,
        "{x} {y}"
    );
    assert_eq!(vertex_a("", "(tan(45), tan(-45))"), (1.0, -1.0));
    assert_eq!(vertex_a("", "(sqrt(16), abs(-3))"), (4.0, 3.0));
    assert_eq!(vertex_a("", "(min(3, 1, 2), max(-1, -4))"), (1.0, -1.0));
    let (x, _) = vertex_a("", "(pi, 0)");
    assert_eq!(x, std::f64::consts::PI);
}

#[test]
fn constants_use_earlier_constants_and_reach_points_and_solver_values() {
    let lets = "let width = 0.4\nlet half = width / 2\nlet h = half * 3";
    let (x, y) = vertex_a(lets, "(half, -h)");
    assert!(
        (x - 0.2).abs() < 1e-15 && (y + 0.6).abs() < 1e-12,
        "{x} {y}"
    );

    let src = "let k = 0.1\nsolver {\n    hysteresis = k * 2\n}\nsite type s\n\
               piece p {\n    vertex a (0, 0)\n    vertex b (1, 0)\n    edges a-b\n}\n\
               model {\n    x = p rotate k * 900\n}\n";
    let c = compile(src, "t.clay", &CompileOptions::default()).unwrap();
    assert!((c.grammar.solver.hysteresis - 0.2).abs() < 1e-15);
    assert!(c.warnings.is_empty(), "{:?}", c.warnings);
}

#[test]
fn an_unknown_constant_is_one_error_with_a_suggestion() {
    let e = errors("let width = 1", "(widht, 0)");
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].code, "E011");
    assert_eq!(e[0].message, "unknown constant `widht`");
    assert!(
        e[0].hints.iter().any(|h| h == "did you mean `width`?"),
        "{e:?}"
    );
    assert_eq!(
        text_at(&grammar("let width = 1", "(widht, 0)"), &e[0]),
        "widht"
    );
}

#[test]
fn a_function_name_used_as_a_constant_says_how_to_call_it() {
    let e = errors("", "(sin, 0)");
    assert_eq!(e.len(), 1, "{e:?}");
    assert!(
        e[0].hints
            .iter()
            .any(|h| h.contains("call it as `sin(degrees)`")),
        "{e:?}"
    );
}

#[test]
fn an_unknown_function_suggests_the_closest() {
    let e = errors("", "(sine(30), 0)");
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].code, "E011");
    assert!(
        e[0].hints.iter().any(|h| h == "did you mean `sin`?"),
        "{e:?}"
    );
}

#[test]
fn a_constant_used_before_its_let_points_at_both() {
    let source = "site type s\npiece p {\n    vertex a (w, 0)\n    vertex b (5, 5)\n    edges a-b\n}\n\
                  let w = 1\nmodel {\n    x = p\n}\n";
    let e = compile(source, "t.clay", &CompileOptions::default())
        .unwrap_err()
        .items;
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].code, "E052");
    assert_eq!(text_at(source, &e[0]), "w");
    assert_eq!(e[0].secondary.len(), 1);
    let s = e[0].secondary[0].span;
    assert_eq!(&source[s.start..s.end], "w");
    assert!(s.start > e[0].primary.span.start);
}

#[test]
fn division_by_zero_points_at_the_divisor() {
    let lets = "let w = 2";
    let e = errors(lets, "(1 / (w - 2), 0)");
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].code, "E050");
    assert_eq!(
        text_at(&grammar(lets, "(1 / (w - 2), 0)"), &e[0]),
        "(w - 2)"
    );
}

#[test]
fn a_non_finite_result_points_at_the_sub_expression() {
    for (point, bad) in [
        ("(1 + sqrt(-1), 0)", "sqrt(-1)"),
        ("(tan(90), 0)", "tan(90)"),
        ("(0, 1e300 * 1e300 - 1)", "1e300 * 1e300"),
        ("(asin(2), 0)", "asin(2)"),
    ] {
        let e = errors("", point);
        assert_eq!(e.len(), 1, "{point}: {e:?}");
        assert_eq!(e[0].code, "E012", "{point}");
        assert_eq!(text_at(&grammar("", point), &e[0]), bad, "{point}");
    }
}

#[test]
fn a_call_with_the_wrong_arguments_says_how_to_call() {
    let e = errors("", "(atan2(1), 0)");
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].code, "E051");
    assert!(
        e[0].hints.iter().any(|h| h == "write `atan2(y, x)`"),
        "{e:?}"
    );
    let e = errors("", "(max(), 0)");
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].code, "E051");
}

#[test]
fn a_failed_constant_is_reported_once_and_its_uses_stay_silent() {
    let source = "let bad = 1 / 0\nlet worse = bad * 2\nsite type s\npiece p {\n    \
                  vertex a (bad, worse)\n    vertex b (bad, 5)\n    edges a-b\n}\n\
                  model {\n    x = p rotate bad\n}\n";
    let e = compile(source, "t.clay", &CompileOptions::default())
        .unwrap_err()
        .items;
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].code, "E050");
}

#[test]
fn constants_cannot_be_declared_twice_or_shadow_built_ins() {
    let e = errors("let w = 1\nlet w = 2", "(w, 0)");
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].code, "E010");
    assert_eq!(e[0].secondary.len(), 1);
    let e = errors("let pi = 3", "(0, 0)");
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].code, "E010");
    assert_eq!(e[0].message, "`pi` is built in");
}

#[test]
fn an_unused_constant_is_a_warning() {
    let c = compile(
        &grammar("let spare = 3", "(0, 0)"),
        "t.clay",
        &CompileOptions::default(),
    )
    .unwrap();
    let w: Vec<_> = c
        .warnings
        .iter()
        .map(|d| (d.code, d.message.clone()))
        .collect();
    assert_eq!(
        w,
        vec![("W007", "constant `spare` is never used".to_string())]
    );
}

#[test]
fn whole_numbers_and_ranges_are_checked_after_folding() {
    let src = |count: &str| {
        format!(
            "let n = 3\nsite type s docks s\npiece p {{\n    vertex a (0, 0)\n    vertex b (1, 0)\n    \
             edges a-b\n    site w: s [a] out (-1, 0)\n    site e: s [b] out (1, 0)\n}}\n\
             model {{\n    c = chain p x {count} along w -> e\n}}\n"
        )
    };
    let c = compile(&src("n * 2"), "t.clay", &CompileOptions::default()).unwrap();
    assert_eq!(c.grammar.assembly.instances.len(), 6);
    let e = compile(&src("n / 2"), "t.clay", &CompileOptions::default())
        .unwrap_err()
        .items;
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].code, "E013");
}

#[test]
fn expressions_too_deep_are_one_error_not_a_crash() {
    let deep = format!("({}1{}, 0)", "(".repeat(254), ")".repeat(254));
    let e = errors("", &deep);
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].code, "E002");
    let long = format!("({}, 0)", vec!["1"; 1000].join(" + "));
    let e = errors("", &long);
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].code, "E002");
    let signs = format!("({}1, 0)", "-".repeat(500));
    let e = errors("", &signs);
    assert_eq!(e.len(), 1, "{e:?}");
    // A long but reasonable sum is fine.
    let sum = format!("({}, 0)", vec!["1"; 100].join(" + "));
    assert_eq!(vertex_a("", &sum), (100.0, 0.0));
}

#[test]
fn the_formatter_keeps_expressions_in_canonical_spacing() {
    let source = "let  w=0.40\nlet h = -( w*2 )+sin( 30 )\nsite type s\npiece p {\n    \
                  vertex a (w/2 , -h)\n    vertex b (5, 5)\n    edges a-b\n}\nmodel {\n    x = p\n}\n";
    let out = format(source).unwrap();
    assert!(
        out.contains("let w = 0.40\nlet h = -(w * 2) + sin(30)\n"),
        "{out}"
    );
    assert!(out.contains("vertex a (w / 2, -h)"), "{out}");
    assert_eq!(format(&out).unwrap(), out, "idempotent");
    let before = compile(source, "t.clay", &CompileOptions::default())
        .unwrap()
        .grammar;
    let after = compile(&out, "t.clay", &CompileOptions::default())
        .unwrap()
        .grammar;
    assert_eq!(before, after, "meaning-preserving");
}

#[test]
fn an_operator_without_an_operand_is_a_syntax_error_with_position() {
    let source = grammar("", "(1 +, 0)");
    let e = compile(&source, "t.clay", &CompileOptions::default())
        .unwrap_err()
        .items;
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].code, "E001");
    assert_eq!(&source[e[0].primary.span.start..e[0].primary.span.end], ",");
}

#[test]
fn the_language_doc_example_of_expressions_compiles_to_the_numbers_it_shows() {
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/language.md"))
        .unwrap();
    let section = &doc[doc
        .find("## Expressions and constants")
        .expect("the section")..];
    let start = section.find("```clay\n").expect("an example") + "```clay\n".len();
    let end = start + section[start..].find("```").unwrap();
    let c = compile(&section[start..end], "doc.clay", &CompileOptions::default()).unwrap();
    assert!(c.warnings.is_empty(), "{:?}", c.warnings);
    let p = &c.grammar.pieces[0];
    let bay = 2.0 * 0.4 + 0.1;
    let pos = &p.states[0].positions;
    assert!((pos[1].x - bay).abs() < 1e-15);
    assert!((pos[2].y - 3f64.sqrt() / 2.0 * bay).abs() < 1e-15);
    let out = p.sites[0].out;
    assert!((out.x - 120f64.to_radians().cos()).abs() < 1e-12, "{out}");
}

#[test]
fn an_expression_node_stays_small() {
    // Most numbers of a large grammar are literals: the rare big variants are boxed so that a
    // 10,000-piece grammar's tree does not grow by a third (issue 18's check budget).
    assert!(
        std::mem::size_of::<clay_dsl::syntax::Expr>() <= 40,
        "{}",
        std::mem::size_of::<clay_dsl::syntax::Expr>()
    );
}

#[test]
fn a_literal_too_large_is_marked_at_its_digits_in_either_form_of_point() {
    // `(x, y)` of two literals is one token (grammar.pest's `plain_point`); with a comment
    // inside, the same point takes the general form. Both mark the same digits.
    for point in [
        "(0,  1e999)",
        "(\t-1e999 , 0)",
        "(0, /* far */ 1e999)",
        "(-1e999, 0 /* x */)",
    ] {
        let source = grammar("", point);
        let d = compile(&source, "t.clay", &CompileOptions::default())
            .unwrap_err()
            .items;
        assert_eq!(d.len(), 1, "{point}: {d:?}");
        assert_eq!(d[0].code, "E012", "{point}");
        let want = if point.contains("-1e999") {
            "-1e999"
        } else {
            "1e999"
        };
        assert_eq!(text_at(&source, &d[0]), want, "{point}");
    }
    assert_eq!(vertex_a("", "( -0.5 ,\t2e1 )"), (-0.5, 20.0));
}
