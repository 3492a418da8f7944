//! W005: a grammar with nothing to sculpt says so once (issue 18: an empty file, or one with no
//! `model`, checked clean with no word).

use clay_dsl::{CompileOptions, compile};

fn codes(source: &str) -> Vec<&'static str> {
    compile(source, "g.clay", &CompileOptions::default())
        .unwrap()
        .warnings
        .iter()
        .map(|d| d.code)
        .collect()
}

#[test]
fn an_empty_grammar_is_one_warning() {
    assert_eq!(codes(""), ["W005"]);
    assert_eq!(codes("// only a comment\n"), ["W005"]);
}

#[test]
fn pieces_without_a_model_are_one_warning_not_one_per_piece() {
    let piece = |n: &str| {
        format!(
            "piece {n} {{\n    vertex a (0, 0)\n    vertex b (1, 0)\n    vertex c (0, 1)\n    edges a-b-c-a\n}}\n"
        )
    };
    let src = format!("{}{}", piece("one"), piece("two"));
    assert_eq!(codes(&src), ["W005"]);
    // With a model the unused piece is reported as before, and W005 is not.
    let src = format!(
        "{}{}model {{\n    x = one\n}}\n",
        piece("one"),
        piece("two")
    );
    assert_eq!(codes(&src), ["W001"]);
}
