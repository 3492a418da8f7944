//! The analysis layer for editors (issue 19): definitions, references, hovers, completion,
//! outline, rename, semantic tokens, folding, fixes, and answers while the text is broken.

use clay_dsl::analysis::{Analysis, CompletionKind, SymbolKind, TokenKind};

fn wall() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../grammars/wall.clay"
    ))
    .unwrap()
}

/// The offset of the `nth` occurrence of `needle` (0-based), plus `into` bytes.
fn at(text: &str, needle: &str, nth: usize, into: usize) -> usize {
    text.match_indices(needle)
        .nth(nth)
        .unwrap_or_else(|| panic!("no {nth}th `{needle}`"))
        .0
        + into
}

fn slice(text: &str, s: clay_dsl::syntax::Span) -> &str {
    &text[s.start..s.end]
}

#[test]
fn definition_and_references_of_a_piece() {
    let text = wall();
    let a = Analysis::new(&text, "wall.clay");
    let use_in_stretch = at(&text, "stretch brick", 0, "stretch b".len());
    let def = a.definition(use_in_stretch).expect("a definition");
    assert_eq!(def.start, at(&text, "piece brick", 0, "piece ".len()));
    assert_eq!(slice(&text, def), "brick");
    let refs = a.references(def.start, false);
    assert_eq!(refs.len(), 2, "stretch and chain: {refs:?}");
    assert!(refs.iter().all(|r| slice(&text, *r) == "brick"));
    assert_eq!(a.references(def.start, true).len(), 3);
}

#[test]
fn definitions_of_vertices_sites_and_site_types() {
    let text = wall();
    let a = Analysis::new(&text, "wall.clay");
    // `nw` in the site's vertex list -> `vertex nw`.
    let nw = at(&text, "[nw, sw]", 0, 1);
    assert_eq!(
        a.definition(nw).unwrap().start,
        at(&text, "vertex nw", 0, 7)
    );
    // `west` in the stretch rule -> `site west`.
    let west = at(&text, "from west", 0, 5);
    assert_eq!(
        a.definition(west).unwrap().start,
        at(&text, "site west", 0, 5)
    );
    // `joint` in a site -> `site type joint`.
    let joint = at(&text, ": joint", 0, 2);
    assert_eq!(
        a.definition(joint).unwrap().start,
        at(&text, "site type joint", 0, 10)
    );
}

#[test]
fn a_piece_hover_lists_vertices_sites_states_and_rules() {
    let text = wall();
    let a = Analysis::new(&text, "wall.clay");
    let (span, hover) = a.hover(at(&text, "chain brick", 0, 7)).expect("a hover");
    assert_eq!(slice(&text, span), "brick");
    assert!(hover.contains("piece brick"), "{hover}");
    assert!(
        hover.contains("**4 vertices**: `sw`, `se`, `ne`, `nw`"),
        "{hover}"
    );
    assert!(
        hover.contains("`west: joint [nw, sw] out (-1, 0)`"),
        "{hover}"
    );
    assert!(hover.contains("**rest states**: `base`"), "{hover}");
    assert!(
        hover.contains("- `stretch brick from west to east { min 2 }`"),
        "{hover}"
    );
}

#[test]
fn a_constant_hover_shows_its_value() {
    let text = "let w = 0.5 * 3\nsite type s\npiece p {\n    vertex a (w, 0)\n    vertex b (0, 1)\n    edges a-b\n}\nmodel {\n    x = p\n}\n";
    let a = Analysis::new(text, "t.clay");
    let (_, hover) = a.hover(at(text, "(w", 0, 1)).unwrap();
    assert!(hover.contains("let w = 0.5 * 3"), "{hover}");
    assert!(hover.contains("= `1.5`"), "{hover}");
}

fn labels(a: &Analysis, offset: usize) -> Vec<String> {
    a.completions(offset).into_iter().map(|c| c.label).collect()
}

#[test]
fn completion_offers_what_fits_the_position() {
    let text = wall();
    let a = Analysis::new(&text, "wall.clay");
    // After `site west: ` a site type.
    let l = labels(&a, at(&text, "site west: ", 0, "site west: ".len()));
    assert_eq!(l, vec!["joint"]);
    // After `from ` a site of the stretch rule's piece.
    let l = labels(&a, at(&text, "from west", 0, 5));
    assert_eq!(l, vec!["west", "east"]);
    // In a vertex list, the piece's vertices.
    let l = labels(&a, at(&text, "[nw, sw]", 0, 1));
    assert_eq!(l, vec!["sw", "se", "ne", "nw"]);
    // After `chain ` the pieces.
    let l = labels(&a, at(&text, "chain brick", 0, 6));
    assert_eq!(l, vec!["brick"]);
    // At the start of a line in a piece, the piece statements.
    let l = labels(&a, at(&text, "    vertex se", 0, 4));
    assert!(
        l.contains(&"vertex".to_string()) && l.contains(&"state".to_string()),
        "{l:?}"
    );
    // At the top level, the items.
    let l = labels(&a, at(&text, "site type joint", 0, 0));
    assert!(
        l.contains(&"piece".to_string()) && l.contains(&"model".to_string()),
        "{l:?}"
    );
}

#[test]
fn completion_after_a_dot_and_in_expressions() {
    let text = "let width = 2\nsite type s\npiece p {\n    vertex a (0, 0)\n    vertex b (1, 0)\n    edges a-b\n    site w: s [a] out (-1, 0)\n    site e: s [b] out (1, 0)\n}\nmerge p.\nmodel {\n    x = p at (wi, 0)\n    dock x.\n}\n";
    // While `dock x.` is being typed the model does not parse: the instance comes from the
    // text before the edit.
    let previous = Analysis::new(
        &text.replace("merge p.\n", "").replace("    dock x.\n", ""),
        "t.clay",
    );
    let a = Analysis::with_previous(&text.replace("merge p.\n", ""), "t.clay", &previous);
    let typing = text.replace("merge p.\n", "");
    assert_eq!(labels(&a, at(&typing, "dock x.", 0, 7)), vec!["w", "e"]);
    let a = Analysis::new(text, "t.clay");
    assert_eq!(labels(&a, at(text, "merge p.", 0, 8)), vec!["w", "e"]);
    let c = a.completions(at(text, "(wi", 0, 3));
    assert!(
        c.iter()
            .any(|c| c.label == "width" && c.kind == CompletionKind::Constant)
    );
    assert!(
        c.iter()
            .any(|c| c.label == "sin" && c.kind == CompletionKind::Function)
    );
    let w = c.iter().find(|c| c.label == "width").unwrap();
    assert_eq!(slice(text, w.replace), "wi");
}

#[test]
fn the_outline_nests_members_under_their_piece() {
    let text = wall();
    let a = Analysis::new(&text, "wall.clay");
    let outline = a.outline();
    let names: Vec<&str> = outline.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, vec!["joint", "brick", "stretch brick", "model"]);
    let brick = &outline[1];
    let members: Vec<&str> = brick.children.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(members, vec!["sw", "se", "ne", "nw", "west", "east"]);
    assert_eq!(outline[3].children[0].name, "wall");
    assert_eq!(outline[3].children[0].kind, Some(SymbolKind::Chain));
}

#[test]
fn rename_changes_every_use_and_the_result_checks_clean() {
    let text = wall();
    let a = Analysis::new(&text, "wall.clay");
    let edits = a.rename(at(&text, "piece brick", 0, 7), "block").unwrap();
    assert_eq!(edits.len(), 3);
    let mut renamed = text.clone();
    let mut spans: Vec<_> = edits.iter().map(|(s, _)| *s).collect();
    spans.sort_by_key(|s| std::cmp::Reverse(s.start));
    for s in spans {
        renamed.replace_range(s.start..s.end, "block");
    }
    let c = clay_dsl::compile(&renamed, "wall.clay", &clay_dsl::CompileOptions::default())
        .expect("the renamed grammar compiles");
    assert!(c.warnings.is_empty(), "{:?}", c.warnings);
    assert_eq!(c.grammar.pieces[0].name, "block");
    // Refused: a keyword, a clash, not a name.
    let sw = at(&text, "vertex sw", 0, 7);
    assert!(a.rename(sw, "piece").unwrap_err().contains("keyword"));
    assert!(a.rename(sw, "se").unwrap_err().contains("already exists"));
    assert!(a.rename(sw, "2x").is_err());
    assert!(a.rename(sw, "sw2").is_ok());
}

#[test]
fn queries_answer_before_a_syntax_error_and_after_it_from_the_last_good_text() {
    let good = wall();
    let previous = Analysis::new(&good, "wall.clay");
    // Break the stretch rule: everything before it still parses.
    let broken = good.replace(
        "stretch brick from west to east { min 2 }",
        "stretch brick from west to { min 2 }",
    );
    let a = Analysis::with_previous(&broken, "wall.clay", &previous);
    assert!(a.diagnostics().iter().any(|d| d.code == "E001"));
    let (_, hover) = a
        .hover(at(&broken, "piece brick", 0, 7))
        .expect("hover before the error");
    assert!(hover.contains("4 vertices"), "{hover}");
    // The model after the error comes from the last good text, at its new place.
    let wall_at = at(&broken, "wall = chain", 0, 0);
    let def = a
        .definition(wall_at + 1)
        .expect("the chain after the error");
    assert_eq!(def.start, wall_at);
    // Its use of `brick` still resolves to the piece before the error.
    let brick_use = at(&broken, "chain brick", 0, 7);
    assert_eq!(
        a.definition(brick_use).unwrap().start,
        at(&broken, "piece brick", 0, 6)
    );
    // Without a previous analysis, the declarations before the error still answer.
    let alone = Analysis::new(&broken, "wall.clay");
    assert!(alone.hover(at(&broken, "piece brick", 0, 7)).is_some());
    assert!(alone.definition(wall_at + 1).is_none());
}

#[test]
fn semantic_tokens_tell_keywords_names_numbers_colours_and_comments_apart() {
    let text = wall();
    let a = Analysis::new(&text, "wall.clay");
    let tokens = a.semantic_tokens();
    let kind_at = |offset: usize| {
        tokens
            .iter()
            .find(|t| t.span.start == offset)
            .map(|t| (t.kind, t.declaration))
    };
    assert_eq!(
        kind_at(at(&text, "piece brick", 0, 0)),
        Some((TokenKind::Keyword, false))
    );
    assert_eq!(
        kind_at(at(&text, "piece brick", 0, 6)),
        Some((TokenKind::Symbol(SymbolKind::Piece), true))
    );
    assert_eq!(
        kind_at(at(&text, "chain brick", 0, 6)),
        Some((TokenKind::Symbol(SymbolKind::Piece), false))
    );
    assert_eq!(
        kind_at(at(&text, "#b5651d", 0, 0)),
        Some((TokenKind::Colour, false))
    );
    assert_eq!(
        kind_at(at(&text, "0.97", 0, 0)),
        Some((TokenKind::Number, false))
    );
    assert_eq!(
        kind_at(at(&text, "hysteresis", 0, 0)),
        Some((TokenKind::Parameter, false))
    );
    assert_eq!(
        kind_at(at(&text, "// a darker", 0, 0)),
        Some((TokenKind::Comment, false))
    );
    // In order, not overlapping, never across a line.
    for w in tokens.windows(2) {
        assert!(w[0].span.end <= w[1].span.start);
    }
    assert!(
        tokens
            .iter()
            .all(|t| !text[t.span.start..t.span.end].contains('\n'))
    );
}

#[test]
fn folding_covers_multi_line_blocks() {
    let text = wall();
    let a = Analysis::new(&text, "wall.clay");
    let folds = a.folding_ranges();
    let piece_open = at(&text, "piece brick {", 0, "piece brick ".len());
    assert!(
        folds
            .iter()
            .any(|f| f.start == piece_open && text[..f.end].ends_with('}'))
    );
    // The one-line stretch block is not folded.
    let stretch_open = at(&text, "{ min 2 }", 0, 0);
    assert!(!folds.iter().any(|f| f.start == stretch_open));
}

#[test]
fn a_did_you_mean_hint_is_a_fix_that_compiles() {
    let text = wall().replace("site west: joint", "site west: jiont");
    let a = Analysis::new(&text, "wall.clay");
    let d = a
        .diagnostics()
        .iter()
        .next()
        .expect("the typo's error")
        .clone();
    let fixes = a.fixes(&d);
    assert_eq!(fixes.len(), 1, "{fixes:?}");
    let (span, with) = &fixes[0].edits[0];
    let mut fixed = text.clone();
    fixed.replace_range(span.start..span.end, with);
    assert_eq!(fixed, wall());
}

#[test]
fn parses_tells_a_whole_parse_from_a_prefix() {
    let good = wall();
    assert!(Analysis::new(&good, "wall.clay").parses());
    let broken = good.replace("min 2 }", "min }");
    let a = Analysis::new(&broken, "wall.clay");
    assert!(!a.parses());
    // Borrowing the tail from a previous analysis does not make the text parse.
    let previous = Analysis::new(&good, "wall.clay");
    assert!(!Analysis::with_previous(&broken, "wall.clay", &previous).parses());
}

/// An imported piece's place (file and span) answers, also from the last good text while the
/// text does not parse (moved from analysis/imports.rs, which no longer reaches its parent).
#[test]
fn an_imported_piece_answers_also_while_the_text_does_not_parse() {
    let dir = std::env::temp_dir().join(format!("clay-analysis-imports-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let lib = "site type joint\npiece brick {\n    vertex a (0, 0)\n    vertex b (1, 0)\n    \
               vertex c (1, 1)\n    edges a-b-c-a\n}\n";
    std::fs::write(dir.join("lib.clay"), lib).unwrap();
    let path = dir.join("main.clay").display().to_string();
    let main = "import \"lib.clay\"\n\nmodel {\n    b = brick\n}\n";
    let good = Analysis::new(main, &path);
    let use_at = main.find("= brick").unwrap() + 2;
    let def = good.definition(use_at).unwrap();
    let place = good.place(def);
    assert_eq!(place.file, 1);
    assert!(good.path(1).ends_with("/lib.clay"), "{}", good.path(1));
    let decl = lib.find("brick").unwrap();
    assert_eq!((place.span.start, place.span.end), (decl, decl + 5));
    assert_eq!(
        good.declared_at(good.path(1), place.span),
        good.symbol_at(use_at)
    );

    // A syntax error before the model: the imports of the last good text still answer.
    let broken = main.replace("\n\nmodel", "\npiece {\n\nmodel");
    let a = Analysis::with_previous(&broken, &path, &good);
    assert!(!a.parses());
    let use_at = broken.find("= brick").unwrap() + 2;
    let place = a.place(a.definition(use_at).expect("the imported brick"));
    assert_eq!((place.file, place.span.start), (1, decl));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn typed_parameters_complete_and_resolve() {
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../grammars/keep.clay"),
    )
    .unwrap();
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../grammars/keep.clay");
    let path = path.to_string_lossy();
    let a = Analysis::new(&text, &path);
    assert!(a.diagnostics().is_empty(), "{:?}", a.diagnostics());
    // After `if ` the bool parameters, after `NAME = ` in the model the choices too.
    let l = labels(&a, at(&text, "if donjon", 0, 3));
    assert_eq!(l, vec!["donjon"]);
    let l = labels(&a, at(&text, "gatehouse = gate", 0, "gatehouse = ".len()));
    assert!(
        l.contains(&"gate".to_string()) && l.contains(&"tower".to_string()),
        "{l:?}"
    );
    // After `param NAME: ` the types.
    let typing = text.replace("param donjon: bool", "param donjon: ");
    let b = Analysis::new(&typing, &path);
    let l = labels(&b, at(&typing, "param donjon: ", 0, "param donjon: ".len()));
    assert_eq!(l, vec!["number", "int", "bool", "seed", "choice"]);
    // The choice's strings go to their pieces; the `if` to its parameter.
    let def = a
        .definition(at(&text, "\"gatehouse\")", 0, 1))
        .expect("a definition");
    assert_eq!(def.start, at(&text, "piece gatehouse", 0, 6));
    let def = a
        .definition(at(&text, "if donjon", 0, 4))
        .expect("a definition");
    assert_eq!(def.start, at(&text, "param donjon", 0, 6));
}
