//! Regression tests for what fuzzing found, each with its minimal input: a syntax error after a
//! multi-byte character (a panic slicing inside it) and unclosed block comments (exponential
//! time).

use clay_dsl::analysis::Analysis;
use clay_dsl::{Diagnostic, compile, render};

// ---- 1. syntax errors after multi-byte characters -----------------------------------------------

/// Compiles `text`, which has a syntax error, and checks the diagnostic: E001, its spans on
/// char boundaries, rendered; the formatter and the editor analysis do not panic on it either.
fn syntax_error_on_char_boundaries(text: &str) -> Diagnostic {
    let d = compile(text, "a.clay").expect_err("a syntax error");
    assert_eq!(d.items.len(), 1, "a syntax error stops at the first: {d:?}");
    let e = d.items[0].clone();
    assert_eq!(e.code, "E001", "{text:?}: {e:?}");
    for l in std::iter::once(&e.primary).chain(&e.secondary) {
        let (s, t) = (l.span.start, l.span.end);
        assert!(s <= t && t <= text.len(), "{text:?}: span {s}..{t}");
        assert!(
            text.is_char_boundary(s) && text.is_char_boundary(t),
            "{text:?}: span {s}..{t} inside a character"
        );
    }
    let shown = render(&d, text, "a.clay", false);
    assert!(
        shown.contains("error[E001]") && shown.contains("a.clay:"),
        "{shown}"
    );
    assert!(clay_dsl::format(text).is_err());
    let a = Analysis::new(text, "a.clay");
    assert!(a.diagnostics().has_errors());
    let _ = (a.semantic_tokens(), a.folding_ranges(), a.outline());
    for (i, _) in text.char_indices().chain([(text.len(), ' ')]) {
        let _ = (a.completions(i), a.hover(i), a.definition(i));
    }
    e
}

#[test]
fn a_syntax_error_after_a_superscript_in_a_comment() {
    let text = "solver {\n    merge_distance = // in m²\n}\n";
    let e = syntax_error_on_char_boundaries(text);
    assert_eq!(e.primary.span.start, text.rfind('}').unwrap(), "{e:?}");
    assert!(e.message.contains("found `}`"), "{}", e.message);
}

#[test]
fn a_byte_order_mark_inside_a_declaration() {
    let text = "piece\u{FEFF}x";
    let e = syntax_error_on_char_boundaries(text);
    assert_eq!(e.primary.span.start, text.len(), "at the end: {e:?}");
}

#[test]
fn multi_byte_characters_before_syntax_errors() {
    for text in [
        // In a name, in a string, in comments right before the error.
        "piece bréak {}",
        "piece b {\n    vertex ü (0, 0)\n}\n",
        "import \"é.clay\" x",
        "import \"é",
        "let a = 1 /* ü */ )",
        "let a = 1 // ü\n)",
        "model { w = chain b x 2 // 🧱\n ) }",
        // At the end of the text after a multi-byte character, with and without a newline.
        "piece p { // ü",
        "let a = // é",
        "let a = é",
        "state x { // ²\n",
        // A byte-order mark at the start, then an error; white space the grammar does not skip.
        "\u{FEFF}piece {",
        "\u{FEFF}\u{FEFF}// ü\npiece",
        "piece\u{3000}p {}",
        "let a = 1\u{200B}",
    ] {
        syntax_error_on_char_boundaries(text);
    }
}

#[test]
fn a_character_the_grammar_does_not_skip_is_what_the_error_names() {
    let text = "piece\u{3000}p {}";
    let e = syntax_error_on_char_boundaries(text);
    assert_eq!(e.primary.span.start, "piece".len(), "{e:?}");
    assert!(
        e.message.ends_with(r"found character '\u{3000}'"),
        "{}",
        e.message
    );
}

// ---- 2. unclosed block comments -----------------------------------------------------------------

#[test]
fn thirty_unclosed_block_comments_are_one_error_at_the_first() {
    let text = "/* ".repeat(30);
    let d = compile(&text, "a.clay").expect_err("unclosed");
    assert_eq!(d.items.len(), 1, "{d:?}");
    let e = &d.items[0];
    assert_eq!(
        (e.code, e.message.as_str()),
        ("E001", "unclosed block comment")
    );
    assert_eq!((e.primary.span.start, e.primary.span.end), (0, 2));
    assert!(clay_dsl::format(&text).is_err());
    let a = Analysis::new(&text, "a.clay");
    assert_eq!(a.diagnostics().items[0].message, "unclosed block comment");
}

#[test]
fn ten_thousand_unclosed_block_comments_are_too_deep_and_name_the_first() {
    let text = "/* ".repeat(10_000);
    let d = compile(&text, "a.clay").expect_err("unclosed");
    assert_eq!(d.items.len(), 1, "{d:?}");
    let e = &d.items[0];
    // The nesting guard stops it before pest: at the `*` of the 257th `/*`.
    assert_eq!(e.code, "E002");
    assert_eq!(e.primary.span.start, 256 * 3 + 1);
    let open = &e.secondary[0];
    assert_eq!((open.span.start, open.span.end), (0, 2));
    assert!(open.message.contains("never closed"), "{}", open.message);
}

#[test]
fn an_unclosed_comment_after_the_items_points_at_its_opening() {
    let text = "site type a\n/* one /* two */\npiece p {}\n";
    let d = compile(text, "a.clay").expect_err("unclosed");
    let e = &d.items[0];
    assert_eq!(
        (e.code, e.message.as_str()),
        ("E001", "unclosed block comment")
    );
    assert_eq!(e.primary.span.start, text.find("/*").unwrap());
    // Inside an expression the `/` reads as a division first; still the comment is the error.
    let text = "let a = 1 /* never closed";
    let e = &compile(text, "a.clay").unwrap_err().items[0];
    assert_eq!(
        (e.message.as_str(), e.primary.span.start),
        ("unclosed block comment", 10)
    );
}

#[test]
fn an_earlier_syntax_error_is_still_the_one_reported() {
    let text = "piece p { vertex }\n/* never closed";
    let e = &compile(text, "a.clay").unwrap_err().items[0];
    assert_eq!(e.code, "E001");
    assert!(e.message.starts_with("expected"), "{}", e.message);
    assert!(e.primary.span.start < text.find("/*").unwrap());
}

#[test]
fn comment_openers_inside_strings_are_not_comments() {
    // The scan skips strings as the grammar reads them: no unclosed comment, no bracket.
    let text = "import \"a/*b(.clay\" x";
    let e = &compile(text, "a.clay").unwrap_err().items[0];
    assert!(e.message.starts_with("expected"), "{}", e.message);
    assert!(e.secondary.is_empty(), "{e:?}");
    // And the formatter keeps a `//` inside a string as it is, not as a comment.
    let text = "piece p {\n    mesh \"a//b.obj\"\n}\n";
    assert!(clay_dsl::parse(text).is_ok());
    assert_eq!(clay_dsl::format(text).unwrap(), text);
    assert!(clay_dsl::comment_spans(text).is_empty());
}
