//! Regression tests for what fuzzing found, each with its minimal input: a syntax error after a
//! multi-byte character (a panic slicing inside it), unclosed block comments (exponential time),
//! a `.mtl` colour line with fewer than three numbers (a panic inside tobj), named pipes where
//! the compiler reads a file (a wait for ever), and thousands of diagnostics rendered for a
//! terminal (minutes and megabytes).

use std::path::{Path, PathBuf};

use clay_dsl::analysis::Analysis;
use clay_dsl::{CompileOptions, Diagnostic, Diagnostics, MAX_HUMAN_DIAGNOSTICS, compile, render};

// ---- 1. syntax errors after multi-byte characters -----------------------------------------------

/// Compiles `text`, which has a syntax error, and checks the diagnostic: E001, its spans on
/// char boundaries, rendered; the formatter and the editor analysis do not panic on it either.
fn syntax_error_on_char_boundaries(text: &str) -> Diagnostic {
    let d = compile(text, "a.clay", &CompileOptions::default()).expect_err("a syntax error");
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
    let d = compile(&text, "a.clay", &CompileOptions::default()).expect_err("unclosed");
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
    let d = compile(&text, "a.clay", &CompileOptions::default()).expect_err("unclosed");
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
    let d = compile(text, "a.clay", &CompileOptions::default()).expect_err("unclosed");
    let e = &d.items[0];
    assert_eq!(
        (e.code, e.message.as_str()),
        ("E001", "unclosed block comment")
    );
    assert_eq!(e.primary.span.start, text.find("/*").unwrap());
    // Inside an expression the `/` reads as a division first; still the comment is the error.
    let text = "let a = 1 /* never closed";
    let e = &compile(text, "a.clay", &CompileOptions::default())
        .unwrap_err()
        .items[0];
    assert_eq!(
        (e.message.as_str(), e.primary.span.start),
        ("unclosed block comment", 10)
    );
}

#[test]
fn an_earlier_syntax_error_is_still_the_one_reported() {
    let text = "piece p { vertex }\n/* never closed";
    let e = &compile(text, "a.clay", &CompileOptions::default())
        .unwrap_err()
        .items[0];
    assert_eq!(e.code, "E001");
    assert!(e.message.starts_with("expected"), "{}", e.message);
    assert!(e.primary.span.start < text.find("/*").unwrap());
}

#[test]
fn comment_openers_inside_strings_are_not_comments() {
    // The scan skips strings as the grammar reads them: no unclosed comment, no bracket.
    let text = "import \"a/*b(.clay\" x";
    let e = &compile(text, "a.clay", &CompileOptions::default())
        .unwrap_err()
        .items[0];
    assert!(e.message.starts_with("expected"), "{}", e.message);
    assert!(e.secondary.is_empty(), "{e:?}");
    // And the formatter keeps a `//` inside a string as it is, not as a comment.
    let text = "piece p {\n    mesh \"a//b.obj\"\n}\n";
    assert!(clay_dsl::parse(text).is_ok());
    assert_eq!(clay_dsl::format(text).unwrap(), text);
    assert!(clay_dsl::comment_spans(text).is_empty());
}

// ---- 3. and 4. files read on the grammar's behalf -----------------------------------------------

/// A fresh folder for one test.
fn folder(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("clay-fuzz-finds-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A grammar of one triangle piece carrying `stmt` (a `mesh`), and a model of it.
fn hut(stmt: &str) -> String {
    format!(
        "piece hut {{\n    vertex a (0, 0)\n    vertex b (1, 0)\n    vertex c (0, 1)\n    \
         edges a-b-c-a\n    {stmt}\n}}\nmodel {{\n    h = hut\n}}\n"
    )
}

/// Writes `grammar` as `hut.clay` in `dir` and compiles it from the file system: the one error.
fn one_error(dir: &Path, grammar: &str) -> Diagnostic {
    let path = dir.join("hut.clay").to_string_lossy().into_owned();
    std::fs::write(&path, grammar).unwrap();
    let d = compile(grammar, &path, &CompileOptions::default()).expect_err("refused");
    assert_eq!(d.items.len(), 1, "one error per mistake: {d:?}");
    let e = d.items[0].clone();
    let (line, _) = clay_dsl::line_col(grammar, e.primary.span.start);
    assert!(line >= 1 && !e.hints.is_empty(), "{e:?}");
    assert!(render(&d, grammar, &path, false).contains(&format!("hut.clay:{line}:")));
    e
}

const TRIANGLE_OBJ: &str = "mtllib hut.mtl\nv 0 0 0\nv 1 0 0\nv 0 0 -1\nusemtl red\nf 1 2 3\n";

#[test]
fn an_mtl_colour_with_one_number_is_an_error_naming_its_line() {
    let dir = folder("mtl");
    std::fs::write(dir.join("hut.obj"), TRIANGLE_OBJ).unwrap();
    std::fs::write(dir.join("hut.mtl"), "newmtl red\n  Kd 0.5\n").unwrap();
    let grammar = hut("mesh \"hut.obj\"");
    let e = one_error(&dir, &grammar);
    assert_eq!(e.code, "E066");
    assert_eq!(e.primary.span.start, grammar.find("\"hut.obj\"").unwrap());
    assert!(
        e.message.contains("hut.mtl`, line 2, column 3"),
        "{}",
        e.message
    );
    assert!(e.message.contains("`Kd`"), "{}", e.message);
    for line in ["Ka", "Ks 1 0", "Ke 1 x 0"] {
        std::fs::write(dir.join("hut.mtl"), format!("newmtl red\n{line}\n")).unwrap();
        let e = one_error(&dir, &grammar);
        assert!(
            e.message.contains("line 2, column 1"),
            "{line}: {}",
            e.message
        );
    }
    // Three numbers read; a missing `.mtl` only loses the colour.
    std::fs::write(dir.join("hut.mtl"), "newmtl red\nKd 1 0 0\n").unwrap();
    assert!(
        compile(
            &grammar,
            &dir.join("hut.clay").to_string_lossy(),
            &CompileOptions::default()
        )
        .is_ok()
    );
    std::fs::remove_file(dir.join("hut.mtl")).unwrap();
    assert!(
        compile(
            &grammar,
            &dir.join("hut.clay").to_string_lossy(),
            &CompileOptions::default()
        )
        .is_ok()
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// Makes a named pipe at `path`; false (with a note) where `mkfifo` is missing.
fn mkfifo(path: &Path) -> bool {
    match std::process::Command::new("mkfifo").arg(path).status() {
        Ok(s) if s.success() => true,
        other => {
            println!("note: no named pipe made ({other:?}); the pipe case is skipped");
            false
        }
    }
}

/// A glTF triangle whose buffer is the file `uri`, and that buffer's bytes.
fn gltf_with_buffer(uri: &str) -> (String, Vec<u8>) {
    let mut bin: Vec<u8> = [0f32, 0., 0., 1., 0., 0., 0., 0., -1.]
        .iter()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    bin.extend([0u16, 1, 2, 0].iter().flat_map(|i| i.to_le_bytes()));
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
        "buffers":[{{"byteLength":44,"uri":"{uri}"}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":8}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,-1],"max":[1,0,0]}},
                     {{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}]}}"#
    );
    (json, bin)
}

#[test]
fn named_pipes_are_refused_before_they_are_opened() {
    let dir = folder("fifo");
    if !mkfifo(&dir.join("pipe")) {
        return;
    }
    let not_regular = |e: &Diagnostic| {
        assert!(e.message.contains("is not a regular file"), "{}", e.message);
        assert!(e.message.contains("named pipe"), "{}", e.message);
    };
    // Imported, directly and through a symbolic link.
    std::os::unix::fs::symlink(dir.join("pipe"), dir.join("link.clay")).unwrap();
    for target in ["pipe", "link.clay"] {
        let grammar = format!("import \"{target}\"\n");
        let e = one_error(&dir, &grammar);
        assert_eq!((e.code, e.primary.span.start), ("E060", 7), "{e:?}");
        not_regular(&e);
    }
    // A mesh asset.
    std::fs::rename(dir.join("pipe"), dir.join("pipe.glb")).unwrap();
    let grammar = hut("mesh \"pipe.glb\"");
    let e = one_error(&dir, &grammar);
    assert_eq!(e.code, "E065");
    assert_eq!(e.primary.span.start, grammar.find("\"pipe.glb\"").unwrap());
    not_regular(&e);
    // A glTF's buffer.
    std::fs::rename(dir.join("pipe.glb"), dir.join("pipe.bin")).unwrap();
    let (json, bin) = gltf_with_buffer("pipe.bin");
    std::fs::write(dir.join("tri.gltf"), json).unwrap();
    let e = one_error(&dir, &hut("mesh \"tri.gltf\""));
    assert_eq!(e.code, "E065");
    assert!(e.message.contains("pipe.bin"), "{}", e.message);
    not_regular(&e);
    // An OBJ's materials.
    std::fs::rename(dir.join("pipe.bin"), dir.join("hut.mtl")).unwrap();
    std::fs::write(dir.join("hut.obj"), TRIANGLE_OBJ).unwrap();
    let e = one_error(&dir, &hut("mesh \"hut.obj\""));
    assert_eq!(e.code, "E065");
    assert!(e.message.contains("hut.mtl"), "{}", e.message);
    not_regular(&e);
    // The same files as regular files compile.
    std::fs::remove_file(dir.join("hut.mtl")).unwrap();
    std::fs::write(dir.join("tri.bin"), bin).unwrap();
    let (json, _) = gltf_with_buffer("tri.bin");
    std::fs::write(dir.join("tri.gltf"), json).unwrap();
    for mesh in ["tri.gltf", "hut.obj"] {
        let grammar = hut(&format!("mesh \"{mesh}\""));
        let path = dir.join("hut.clay").to_string_lossy().into_owned();
        assert!(
            compile(&grammar, &path, &CompileOptions::default()).is_ok(),
            "{mesh}"
        );
    }
    std::fs::remove_dir_all(dir).unwrap();
}

// ---- 5. many diagnostics for a terminal ---------------------------------------------------------

/// A model of `n` instances of an unknown piece, all on one line when `one_line`: `n` errors.
fn unknown_pieces(n: usize, one_line: bool) -> String {
    let sep = if one_line { " " } else { "\n" };
    let body: Vec<String> = (0..n).map(|i| format!("i{i} = nope")).collect();
    format!("model {{{sep}{}{sep}}}\n", body.join(sep))
}

#[test]
fn a_human_rendering_stops_after_its_limit_and_counts_the_rest() {
    let text = unknown_pieces(3_000, true);
    let d: Diagnostics = compile(&text, "a.clay", &CompileOptions::default()).unwrap_err();
    assert_eq!(d.error_count(), 3_000);
    let shown = render(&d, &text, "a.clay", false);
    assert_eq!(shown.matches("error[E011]").count(), MAX_HUMAN_DIAGNOSTICS);
    let more = 3_000 - MAX_HUMAN_DIAGNOSTICS;
    assert!(
        shown.ends_with(&format!(
            "... and {more} more errors (use `clayc check --format json` for all)\n"
        )),
        "{}",
        &shown[shown.len() - 200..]
    );
    // Each shown diagnostic prints its (long) source line once or twice, no more.
    assert!(
        shown.len() < MAX_HUMAN_DIAGNOSTICS * 3 * text.len(),
        "{}",
        shown.len()
    );
    // The JSON form keeps them all.
    assert_eq!(clay_dsl::to_json(&d, &text, "a.clay").len(), 3_000);
}

#[test]
fn the_closing_line_counts_errors_and_warnings_and_is_absent_within_the_limit() {
    let text = unknown_pieces(MAX_HUMAN_DIAGNOSTICS, false);
    let mut d = compile(&text, "a.clay", &CompileOptions::default()).unwrap_err();
    assert_eq!(d.len(), MAX_HUMAN_DIAGNOSTICS);
    assert_eq!(clay_dsl::omitted_line(&d), None);
    assert!(!render(&d, &text, "a.clay", false).contains("... and"));
    let warning = Diagnostic::warning("W001", "unused", d.items[0].primary.span, "here");
    d.push(warning.clone());
    assert_eq!(
        clay_dsl::omitted_line(&d).as_deref(),
        Some("... and 1 more warning (use `clayc check --format json` for all)\n")
    );
    d.items.insert(0, d.items[1].clone());
    d.push(warning);
    assert_eq!(
        clay_dsl::omitted_line(&d).as_deref(),
        Some(
            "... and 1 more error and 2 more warnings (use `clayc check --format json` for all)\n"
        )
    );
}
