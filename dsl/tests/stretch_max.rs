//! `max N` in a stretch block (docs/language.md, `stretch`): it compiles into
//! `StretchRule::max`, is checked like `min` (a whole number of at least 2, at most once) and
//! against `min`, coexists with the built-in function `max(a, b)`, and the formatter and the
//! editor analysis know it.

use clay_dsl::Diagnostic;
use clay_dsl::analysis::{Analysis, TokenKind};
use clay_dsl::{CompileOptions, CompiledGrammar, comment_spans, compile, format, print_file};

fn wall() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../grammars/wall.clay"
    ))
    .unwrap()
}

/// wall.clay with its stretch rule's `{ min 2 }` replaced by `body`.
fn wall_with(body: &str) -> String {
    let src = wall().replace("stretch brick from west to east { min 2 }", body);
    assert_ne!(src, wall(), "the fixture edit applies");
    src
}

fn ok(source: &str) -> CompiledGrammar {
    match compile(source, "wall.clay", &CompileOptions::default()) {
        Ok(c) => {
            assert!(c.warnings.is_empty(), "{:?}", c.warnings);
            c.grammar
        }
        Err(d) => panic!("{}", clay_dsl::render(&d, source, "wall.clay", false)),
    }
}

fn errors(source: &str) -> Vec<Diagnostic> {
    compile(source, "wall.clay", &CompileOptions::default())
        .expect_err("the grammar must not compile")
        .iter()
        .cloned()
        .collect()
}

fn text(source: &str, s: clay_dsl::syntax::Span) -> &str {
    &source[s.start..s.end]
}

#[test]
fn max_compiles_into_the_stretch_rule() {
    let g = ok(&wall());
    assert_eq!(g.stretch_rules[0].max, None, "no `max`: no bound");
    for (body, min, max) in [
        ("stretch brick from west to east { min 2 max 10 }", 2, 10),
        ("stretch brick from west to east { max 10 }", 2, 10),
        (
            "stretch brick from west to east {\n    max 12\n    min 3\n}",
            3,
            12,
        ),
        // `max` equal to `min` is allowed: a chain of a fixed length.
        ("stretch brick from west to east { min 4 max 4 }", 4, 4),
        // The keyword, then the built-in function; `min min(..)` works the same way.
        ("stretch brick from west to east { max max(3, 4) }", 2, 4),
        (
            "stretch brick from west to east { min min(3, 5) max max (2 * 5, 4) }",
            3,
            10,
        ),
    ] {
        let rule = &ok(&wall_with(body)).stretch_rules[0];
        assert_eq!((rule.min, rule.max), (min, Some(max)), "{body}");
    }
    // A constant may give the bound (and counts as used: no W007); `max(..)` stays a function
    // in every other expression.
    let src = wall_with("let most = 12\nstretch brick from west to east { max most }")
        .replace("vertex ne (1, 0.5)", "vertex ne (max(1, 0.5), 0.5)");
    assert_eq!(ok(&src).stretch_rules[0].max, Some(12));
}

#[test]
fn a_model_chain_longer_than_max_is_allowed() {
    // wall.clay's chain has 8 bricks: `max` only bounds growth.
    let g = ok(&wall_with("stretch brick from west to east { max 4 }"));
    assert_eq!(g.stretch_rules[0].max, Some(4));
    assert_eq!(g.assembly.chains[0].instances.len(), 8);
}

#[test]
fn max_below_min_is_one_error_naming_both() {
    for body in [
        "stretch brick from west to east { min 5 max 3 }",
        "stretch brick from west to east {\n    max 3\n    min 5\n}",
    ] {
        let src = wall_with(body);
        let e = errors(&src);
        assert_eq!(e.len(), 1, "{body}: {e:?}");
        let d = &e[0];
        assert_eq!(d.code, "E013", "{d:?}");
        assert!(d.message.contains("`max` 3 is below `min` 5"), "{d:?}");
        assert_eq!(text(&src, d.primary.span), "3", "primary on `max`");
        assert_eq!(d.secondary.len(), 1, "{d:?}");
        assert_eq!(text(&src, d.secondary[0].span), "5", "secondary on `min`");
        assert!(!d.hints.is_empty(), "{d:?}");
    }
    // Below the default `min` 2: the range check of `max` itself, as for `min 1`.
    let e = errors(&wall_with("stretch brick from west to east { max 1 }"));
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].code, "E013");
    assert!(e[0].secondary.is_empty(), "{e:?}");
    // A `min` already reported is not compared again.
    let e = errors(&wall_with(
        "stretch brick from west to east { min 1 max 3 }",
    ));
    assert_eq!(e.len(), 1, "{e:?}");
    assert!(e[0].message.contains("`min`"), "{e:?}");
}

#[test]
fn max_must_be_a_whole_number_of_at_least_two() {
    for bad in ["2.5", "-3", "0", "1"] {
        let src = wall_with(&format!("stretch brick from west to east {{ max {bad} }}"));
        let e = errors(&src);
        assert_eq!(e.len(), 1, "max {bad}: {e:?}");
        assert_eq!(e[0].code, "E013", "max {bad}: {e:?}");
        assert!(
            e[0].message.contains("`max` must be a whole number"),
            "{e:?}"
        );
        assert_eq!(text(&src, e[0].primary.span), bad);
    }
}

#[test]
fn a_second_max_is_reported_once() {
    let src = wall_with("stretch brick from west to east { min 2 max 10 max 12 }");
    let e = errors(&src);
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].code, "E010");
    assert!(
        e[0].message.contains("setting `max` is defined twice"),
        "{e:?}"
    );
    assert_eq!(text(&src, e[0].primary.span), "12");
    assert_eq!(text(&src, e[0].secondary[0].span), "10");
}

#[test]
fn formatting_keeps_min_max_their_order_and_comments() {
    let messy = wall_with(
        "stretch   brick from west to east{ // the bounds\n  max   10 /* at most */\nmin 3\n}",
    );
    let once = format(&messy).unwrap();
    assert!(
        once.contains(
            "stretch brick from west to east { // the bounds\n    max 10 /* at most */\n    min 3\n}\n"
        ),
        "{once}"
    );
    assert_eq!(format(&once).unwrap(), once, "idempotent");
    let comments = |s: &str| -> Vec<String> {
        comment_spans(s)
            .iter()
            .map(|c| s[c.start..c.end].trim_end().to_string())
            .collect()
    };
    assert_eq!(comments(&once), comments(&messy));
    assert_eq!(
        ok(&once).stretch_rules,
        ok(&messy).stretch_rules,
        "meaning kept"
    );

    // `min` and `max` together take a line each; one of them alone stays on the rule's line.
    let both = format(&wall_with("stretch brick from west to east {min 2 max 10}")).unwrap();
    assert!(
        both.contains("stretch brick from west to east {\n    min 2\n    max 10\n}\n"),
        "{both}"
    );
    let alone = format(&wall_with("stretch brick from west to east {max   10}")).unwrap();
    assert!(
        alone.contains("stretch brick from west to east { max 10 }\n"),
        "{alone}"
    );
    let call = format(&wall_with("stretch brick from west to east {max max(3,4)}")).unwrap();
    assert!(
        call.contains("stretch brick from west to east { max max(3, 4) }\n"),
        "{call}"
    );

    // Printed from the tree (no source): `min`, `max`, then `variants`.
    let tree = clay_dsl::parse(&wall_with(
        "stretch brick from west to east { variants { brick 1 } max 10 min 3 }",
    ))
    .unwrap();
    let printed = print_file(&tree);
    assert!(
        printed.contains(
            "stretch brick from west to east {\n    min 3\n    max 10\n    variants { brick 1 }\n}\n"
        ),
        "{printed}"
    );
    assert_eq!(ok(&printed).stretch_rules[0].max, Some(10));
}

#[test]
fn completion_offers_max_in_a_stretch_block() {
    let src = wall_with("stretch brick from west to east {\n    min 2\n    \n}");
    let a = Analysis::new(&src, "wall.clay");
    let offset = src.find("min 2\n    \n").unwrap() + "min 2\n    ".len();
    let labels: Vec<String> = a.completions(offset).into_iter().map(|c| c.label).collect();
    for k in ["min", "max", "variants"] {
        assert!(labels.contains(&k.to_string()), "{k}: {labels:?}");
    }
    // After `max ` a number is expected: constants and functions, not keywords.
    let src = wall_with("let most = 9\nstretch brick from west to east {\n    max \n}");
    let a = Analysis::new(&src, "wall.clay");
    let offset = src.find("max \n").unwrap() + "max ".len();
    let labels: Vec<String> = a.completions(offset).into_iter().map(|c| c.label).collect();
    assert!(labels.contains(&"most".to_string()), "{labels:?}");
    assert!(!labels.contains(&"variants".to_string()), "{labels:?}");
}

#[test]
fn max_is_a_keyword_token_and_max_of_a_call_a_function() {
    let src = wall_with("stretch brick from west to east { max max(3, 4) }");
    let a = Analysis::new(&src, "wall.clay");
    let tokens = a.semantic_tokens();
    let kind_at = |offset: usize| {
        tokens
            .iter()
            .find(|t| t.span.start == offset)
            .map(|t| t.kind)
    };
    let keyword = src.find("max max").unwrap();
    assert_eq!(kind_at(keyword), Some(TokenKind::Keyword));
    assert_eq!(kind_at(keyword + 4), Some(TokenKind::Function));
}
