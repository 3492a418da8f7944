//! Syntax errors that say what to do (issue 18): a non-ASCII letter in a name, a stray `;`,
//! and a number run into a letter each get a hint, besides the one error.

use clay_dsl::{CompileOptions, compile};

fn only_error(source: &str) -> clay_dsl::Diagnostic {
    let d = compile(source, "g.clay", &CompileOptions::default()).unwrap_err();
    assert_eq!(
        d.len(),
        1,
        "one error: {:?}",
        d.iter().map(|d| &d.message).collect::<Vec<_>>()
    );
    d.iter().next().unwrap().clone()
}

#[test]
fn a_non_ascii_letter_in_a_name_says_names_are_ascii() {
    let d = only_error("piece clôture {\n}\n");
    assert_eq!(d.code, "E001");
    assert!(
        d.hints
            .iter()
            .any(|h| h.contains("names are ASCII") && h.contains("`ô`")),
        "{:?}",
        d.hints
    );
}

#[test]
fn a_stray_semicolon_says_remove_it() {
    let d = only_error("site type joint;\n");
    assert!(
        d.hints.iter().any(|h| h.contains("remove the `;`")),
        "{:?}",
        d.hints
    );
}

#[test]
fn a_number_followed_by_a_letter_says_what_a_number_is() {
    let d = only_error("piece p {\n    vertex a (2e, 0)\n}\n");
    assert!(
        d.hints.iter().any(|h| h.contains("`2e` is not a number")),
        "{:?}",
        d.hints
    );
}

#[test]
fn an_unclosed_state_points_at_its_brace() {
    let src = "site type joint\npiece p {\n    vertex a (0, 0)\n    vertex b (1, 0)\n    \
               vertex c (0, 1)\n    edges a-b-c-a\n    state up {\n        a (0, 0)\n        \
               b (1, 0.1)\n        c (0, 1)\n    state down {\n        a (0, 0)\n        \
               b (1, -0.1)\n        c (0, 1)\n    }\n}\nmodel {\n    x = p\n}\n";
    let d = only_error(src);
    let brace = src.find("up {").unwrap() + 3;
    assert!(
        d.secondary
            .iter()
            .any(|l| l.span.start == brace && l.message.contains("never closed")),
        "{:?}",
        d.secondary
    );
    assert!(
        d.hints.iter().any(|h| h.contains("line 7 is still open")),
        "{:?}",
        d.hints
    );
}

#[test]
fn a_state_without_a_name_in_a_piece_does_not_blame_the_piece() {
    let d = only_error("site type joint\npiece p {\n    vertex a (0, 0)\n    state {\n    }\n}\n");
    assert!(d.secondary.is_empty(), "{:?}", d.secondary);
}
