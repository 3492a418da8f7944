//! A stretch rule's piece and variants are chain elements, whose own alternative rest states
//! could never become active: each such piece is one E047, and nothing else is reported for it.

use clay_dsl::{CompileOptions, Diagnostics, compile, line_col};

/// Two pieces of one shape, `brick` (in a chain) and `long` (alone), with `states_b` and
/// `states_l` inside them and the `rules` after.
fn grammar(states_b: &str, states_l: &str, rules: &str) -> String {
    let shape = "    vertex sw (0, 0)\n    vertex se (1, 0)\n    vertex ne (1, 0.5)\n    vertex nw (0, 0.5)\n    edges sw-se-ne-nw-sw\n    site west: joint [nw, sw] out (-1, 0)\n    site east: joint [se, ne] out (1, 0)\n";
    format!(
        "site type joint\npiece brick {{\n{shape}{states_b}}}\npiece long {{\n{shape}{states_l}}}\n{rules}\nmodel {{\n    wall = chain brick x 3\n    l = long at (0, 5)\n}}\n"
    )
}

const LEFT: &str = "    state left { sw (0, 0) se (1, 0) ne (0.8, 0.5) nw (-0.2, 0.5) }\n";
const RIGHT: &str = "    state right { sw (0, 0) se (1, 0) ne (1.2, 0.5) nw (0.2, 0.5) }\n";

/// (code, line of the primary span) of every diagnostic.
fn found(src: &str) -> Vec<(&'static str, usize)> {
    let d: Diagnostics = match compile(src, "t.clay", &CompileOptions::default()) {
        Ok(c) => c.warnings,
        Err(d) => d,
    };
    d.iter()
        .map(|d| (d.code, line_col(src, d.primary.span.start).0))
        .collect()
}

fn line_of(src: &str, needle: &str) -> usize {
    line_col(src, src.find(needle).expect("needle")).0
}

#[test]
fn a_stretch_piece_with_two_states_is_one_error_at_the_first() {
    let src = grammar(
        &format!("{LEFT}{RIGHT}"),
        "",
        "stretch brick from west to east",
    );
    assert_eq!(found(&src), [("E047", line_of(&src, "state left"))]);
}

#[test]
fn a_variant_with_states_is_a_chain_element_too() {
    let rule = "stretch brick from west to east { variants { brick 0.5, long 0.5 } }";
    let src = grammar("", RIGHT, rule);
    assert_eq!(found(&src), [("E047", line_of(&src, "state right"))]);
    let d = compile(&src, "t.clay", &CompileOptions::default()).unwrap_err();
    let e = &d.items[0];
    assert_eq!(
        e.secondary[0].message,
        "this rule makes `long` a chain element"
    );
    assert_eq!(
        line_col(&src, e.secondary[0].span.start).0,
        line_of(&src, "stretch")
    );
}

#[test]
fn a_piece_in_two_rules_gets_one_state_error() {
    let rules = "stretch brick from west to east\nstretch brick from east to west";
    let src = grammar(LEFT, "", rules);
    let mut codes: Vec<&str> = found(&src).iter().map(|(c, _)| *c).collect();
    codes.sort();
    assert_eq!(codes, ["E045", "E047"]);
}

#[test]
fn states_outside_any_stretch_rule_are_fine() {
    let src = grammar(
        "",
        &format!("{LEFT}{RIGHT}"),
        "stretch brick from west to east",
    );
    let c = compile(&src, "t.clay", &CompileOptions::default()).expect("compiles");
    assert_eq!(c.grammar.pieces[1].states.len(), 3);
    assert!(c.warnings.is_empty(), "{:?}", c.warnings);
}
