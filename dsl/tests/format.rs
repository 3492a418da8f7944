//! The canonical formatter: it never changes what a grammar means (the compiled grammar of the
//! formatted text equals the original's), it is idempotent, it keeps every comment, and it does
//! not care how the input was spaced.

use clay_dsl::{CompileOptions, CompiledGrammar, Diagnostics, compile};
use clay_dsl::{comment_spans, format, format_number, print_file};
use proptest::prelude::*;

fn grammar_files() -> Vec<(String, String)> {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../grammars");
    let mut files: Vec<(String, String)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "clay"))
        .map(|p| {
            (
                p.display().to_string(),
                std::fs::read_to_string(&p).unwrap(),
            )
        })
        .collect();
    files.sort();
    assert!(files.len() >= 6, "expected the example grammars in {dir}");
    files
}

/// The ```clay example of docs/language.md.
fn language_example() -> String {
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/language.md"))
        .unwrap();
    let start = doc
        .find("```clay\n")
        .expect("docs/language.md has a ```clay example")
        + "```clay\n".len();
    let len = doc[start..].find("```").unwrap();
    doc[start..start + len].to_string()
}

fn all_sources() -> Vec<(String, String)> {
    let mut v = grammar_files();
    v.push(("docs/language.md example".into(), language_example()));
    v
}

/// What a compile means, independent of where things were written: the grammar without its
/// source path, or the diagnostics' codes and messages.
#[derive(Debug, PartialEq)]
enum Meaning {
    Grammar(Box<CompiledGrammar>),
    Errors(Vec<(String, String)>),
}

fn meaning(source: &str) -> Meaning {
    meaning_at(source, "x.clay")
}

/// [`meaning`] of a file at `path` (where its `mesh` assets are found).
fn meaning_at(source: &str, path: &str) -> Meaning {
    match compile(source, path, &CompileOptions::default()) {
        Ok(c) => {
            let mut g = c.grammar;
            g.source.clear();
            Meaning::Grammar(Box::new(g))
        }
        Err(d) => Meaning::Errors(codes(&d)),
    }
}

fn codes(d: &Diagnostics) -> Vec<(String, String)> {
    d.iter()
        .map(|d| (d.code.to_string(), d.message.clone()))
        .collect()
}

fn comment_texts(source: &str) -> Vec<String> {
    comment_spans(source)
        .iter()
        .map(|s| source[s.start..s.end].trim_end().to_string())
        .collect()
}

#[test]
fn formatting_keeps_the_compiled_grammar_of_every_example() {
    for (path, source) in all_sources() {
        let formatted = format(&source).unwrap_or_else(|d| panic!("{path} does not parse: {d:?}"));
        let before = meaning_at(&source, &path);
        assert!(
            matches!(before, Meaning::Grammar(_)),
            "{path} should compile clean: {before:?}"
        );
        assert_eq!(
            before,
            meaning_at(&formatted, &path),
            "{path}: formatting changed the compiled grammar"
        );
    }
}

#[test]
fn formatting_twice_changes_nothing() {
    for (path, source) in all_sources() {
        let once = format(&source).unwrap();
        let twice = format(&once).unwrap();
        assert_eq!(once, twice, "{path}: format is not idempotent");
    }
}

#[test]
fn every_comment_survives_in_order() {
    let mut total = 0;
    for (path, source) in all_sources() {
        let formatted = format(&source).unwrap();
        let (a, b) = (comment_texts(&source), comment_texts(&formatted));
        assert_eq!(a, b, "{path}: comments lost, added or reordered");
        total += a.len();
    }
    assert!(total > 50, "the examples hold many comments, found {total}");
}

#[test]
fn the_examples_are_already_nearly_canonical() {
    // The hand-written grammars were written in the house style before the formatter existed;
    // it keeps almost all of their lines, so it formalises the style rather than inventing one.
    for (path, source) in grammar_files() {
        let formatted = format(&source).unwrap();
        let kept = formatted
            .lines()
            .filter(|l| source.lines().any(|s| s == *l))
            .count();
        let share = kept as f64 / formatted.lines().count() as f64;
        assert!(
            share > 0.97,
            "{path}: only {:.0}% of the formatted lines were in the source",
            share * 100.0
        );
    }
}

const MESSY: &str = "// header comment\n\n\n\nsolver{merge_distance=0.30 norm = 0.5}\nsite type a\n\n\nsite type b docks a // b docks a\nsite   type c\npiece   p{ // the piece\n  vertex sw(0,0)  vertex se ( 1 , 0 ) // trailing on se\n\n\n\n  vertex /* inside */ ne (1,0.5)\n  vertex nw (0, 0.5)\n  edges sw-se-ne-nw-sw,sw-ne\n  site west : a[nw,sw]out(-1,0)\n  site east: a [se, ne] out (1, 0)\n  polygon skinned fill #B5651D { (0.03, 0.03) // first point\n   (0.97, 0.03)\n   /* before the third */ (0.97, 0.47) (0.03, 0.47)\n   hole { (0.4, 0.2) (0.6, 0.2) (0.5, 0.3) }\n  }\n}\npiece t{ vertex sw(0,0) vertex se(1,0) vertex ne(1,0.5) vertex nw(0,0.5) edges sw-se-ne-nw-sw\n  state tall { sw (0, 0) se (1, 0) ne (1, 1) nw (0, 1)\n    polygon fill #00000080 { (0,0) (1,0) (1,1) }\n    /* dangling in state */\n  }\n  // dangling in piece\n}\nstretch p from west to east{min 2}\nmodel{w=chain p x 3 at(0,0)\n/* before q */ q = p at (10, 0) rotate 90\nr = t at (0, 5)\n}\n/* end of file */\n";

#[test]
fn a_messy_file_keeps_meaning_and_comments_and_reaches_a_fixed_point() {
    let formatted = format(MESSY).unwrap();
    assert_eq!(meaning(MESSY), meaning(&formatted));
    assert!(
        matches!(meaning(MESSY), Meaning::Grammar(_)),
        "{:?}",
        meaning(MESSY)
    );
    assert_eq!(comment_texts(MESSY), comment_texts(&formatted));
    assert_eq!(
        format(&formatted).unwrap(),
        formatted,
        "not idempotent:\n{formatted}"
    );
    // The layout rules, one by one.
    let lines: Vec<&str> = formatted.lines().collect();
    assert!(
        lines.contains(&"    vertex se (1, 0) // trailing on se"),
        "trailing comment moved:\n{formatted}"
    );
    assert!(
        lines.contains(&"piece p { // the piece"),
        "header comment moved:\n{formatted}"
    );
    assert!(lines.contains(&"site type b docks a // b docks a"));
    assert!(lines.contains(&"    site west: a [nw, sw] out (-1, 0)"));
    assert!(lines.contains(&"    edges sw-se-ne-nw-sw, sw-ne"));
    assert!(
        lines.contains(&"    merge_distance = 0.30"),
        "numbers keep their text:\n{formatted}"
    );
    assert!(lines.contains(&"    polygon skinned fill #b5651d {"));
    assert!(lines.contains(&"        (0.03, 0.03) // first point"));
    assert!(lines.contains(&"stretch p from west to east { min 2 }"));
    assert!(lines.contains(&"    w = chain p x 3 at (0, 0)"));
    assert!(lines.contains(&"    q = p at (10, 0) rotate 90"));
    assert!(lines.contains(&"        /* dangling in state */"));
    assert!(lines.contains(&"    // dangling in piece"));
    assert_eq!(lines.last(), Some(&"/* end of file */"));
    // A comment inside a statement moves to its own line just before it.
    let inside = lines.iter().position(|l| *l == "    /* inside */").unwrap();
    assert_eq!(lines[inside + 1], "    vertex ne (1, 0.5)");
    // At most one blank line anywhere; none at the start of a block; blank lines the author
    // left between statements are kept (one), none are invented inside blocks.
    assert!(!formatted.contains("\n\n\n"), "{formatted}");
    assert!(!formatted.contains("{\n\n"), "{formatted}");
    assert!(
        formatted.contains("// trailing on se\n\n    /* inside */"),
        "{formatted}"
    );
    assert!(
        formatted.contains("    vertex sw (0, 0)\n    vertex se"),
        "{formatted}"
    );
    // Site types stay together unless the author separated them; other items get a blank line.
    assert!(
        formatted
            .contains("site type a\n\nsite type b docks a // b docks a\nsite type c\n\npiece p"),
        "{formatted}"
    );
    // No trailing whitespace, no tabs, 4-space indentation.
    for l in &lines {
        assert_eq!(l.trim_end(), *l);
        assert!(!l.contains('\t'));
        let indent = l.len() - l.trim_start().len();
        assert_eq!(indent % 4, 0, "{l:?}");
    }
}

#[test]
fn derived_states_keep_their_form_with_canonical_spacing() {
    let piece = "site type lane
piece road {
    vertex s (0, -0.5)
    vertex e (2, -0.5)
    vertex n (1, 0.5)
    edges s-e-n-s
    site west: lane [s] out (-1, 0)
    site east: lane [e] out (1, 0)
    axis west -> east
    polygon skinned fill #4b4f56 { (0, -0.5) (2, -0.5) (1, 0.5) }
STATES
}
model { r = road }
";
    let messy = piece.replace(
        "STATES",
        "state   left   bend    90.0   {  }\n   state right mirror   left\n\
         state  own bend -45 {   polyline width 0.1 fill #FFFFFF { (0,0)  (1,0) } }\n\
         state c bend 10 { // keep me\n}",
    );
    let once = format(&messy).unwrap();
    let expected = piece.replace(
        "STATES",
        "    state left bend 90.0
    state right mirror left
    state own bend -45 {
        polyline width 0.1 fill #ffffff {
            (0, 0) (1, 0)
        }
    }
    state c bend 10 { // keep me
    }",
    );
    let expected = format(&expected).unwrap();
    assert_eq!(once, expected);
    assert!(once.contains("\n    state left bend 90.0\n"), "{once}");
    assert_eq!(format(&once).unwrap(), once, "idempotent");
    assert_eq!(meaning(&once), meaning(&messy), "meaning kept");
    assert!(matches!(meaning(&once), Meaning::Grammar(_)));
    // A tree built in code prints derived states too.
    let printed = print_file(&clay_dsl::parse(&messy).unwrap());
    assert_eq!(meaning(&printed), meaning(&messy));
    assert!(printed.contains("state right mirror left"), "{printed}");
}

#[test]
fn text_that_does_not_parse_is_reported_not_formatted() {
    let d = format("piece p { vertex a (0, }").unwrap_err();
    assert!(d.has_errors());
    assert_eq!(d.iter().next().unwrap().code, "E001");
}

#[test]
fn printing_the_parsed_tree_without_source_keeps_the_meaning() {
    // `print_file` is what code-built trees go through: no comments, numbers by value.
    for (path, source) in all_sources() {
        let tree = clay_dsl::parse(&source).unwrap();
        let printed = print_file(&tree);
        assert_eq!(
            meaning_at(&source, &path),
            meaning_at(&printed, &path),
            "{path}: print_file changed the meaning"
        );
        assert!(comment_spans(&printed).is_empty());
        // Idempotent in the sense that matters: printing the re-parsed tree gives the same text.
        assert_eq!(
            print_file(&clay_dsl::parse(&printed).unwrap()),
            printed,
            "{path}"
        );
    }
}

#[test]
fn numbers_print_as_the_shortest_text_that_reads_back() {
    for x in [
        0.0,
        0.5,
        -0.5,
        1.0,
        12.0,
        0.1 + 0.2,
        1e-7,
        -3.0e-12,
        1.2345678901234567e15,
        2.5e20,
        1e9,
        -0.0,
    ] {
        let t = format_number(x);
        assert_eq!(t.parse::<f64>().unwrap(), x, "{t}");
        let tree = clay_dsl::parse(&format!("solver {{ norm = {t} }}"));
        assert!(tree.is_ok(), "{t} is not a clay number");
    }
    assert_eq!(format_number(0.5), "0.5");
    assert_eq!(format_number(8.0), "8");
    assert_eq!(format_number(f64::NAN), "0");
}

/// A deterministic generator of whitespace choices (xorshift64*).
struct Rng(u64);

impl Rng {
    fn below(&mut self, n: usize) -> usize {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 33) as usize % n
    }
}

/// Respaces `source` without changing its tokens, its comments' line positions (a comment that
/// started its own line still does; a trailing one still trails) or where blank lines are.
fn perturb(source: &str, seed: u64) -> String {
    let comments = comment_spans(source);
    let mut rng = Rng(seed | 1);
    let mut out = String::new();
    let b = source.as_bytes();
    let mut i = 0;
    let spaces = [" ", "  ", "\t", "   ", " \t "];
    while i < b.len() {
        if let Some(c) = comments.iter().find(|c| c.start == i) {
            out.push_str(&source[c.start..c.end]);
            i = c.end;
            continue;
        }
        if b[i].is_ascii_whitespace() {
            let start = i;
            while i < b.len() && b[i].is_ascii_whitespace() {
                i += 1;
            }
            let run = &source[start..i];
            let newlines = run.matches('\n').count();
            let before_comment = comments.iter().any(|c| c.start == i);
            let after_line_comment = comments
                .iter()
                .any(|c| c.end == start && source[c.start..].starts_with("//"));
            let pick = |rng: &mut Rng| spaces[rng.below(spaces.len())];
            match newlines {
                0 if !before_comment && rng.below(4) == 0 => {
                    out.push_str(&format!("{}\n{}", pick(&mut rng), pick(&mut rng)))
                }
                0 => out.push_str(pick(&mut rng)),
                1 if !before_comment && !after_line_comment && rng.below(3) == 0 => {
                    out.push_str(pick(&mut rng))
                }
                1 => out.push_str(&format!("{}\n{}", pick(&mut rng), pick(&mut rng))),
                _ => out.push_str(&format!(
                    "{}\n{}\n{}",
                    pick(&mut rng),
                    ["", "\n", "  \n"][rng.below(3)],
                    pick(&mut rng)
                )),
            }
            continue;
        }
        let ch = source[i..].chars().next().unwrap();
        out.push(ch);
        i += ch.len_utf8();
        // Punctuation the grammar allows spacing around (never inside `->` or a number).
        let next_is_space = b.get(i).is_some_and(|c| c.is_ascii_whitespace());
        if matches!(ch, '(' | ',' | '[' | '{' | ':' | '=')
            && !next_is_space
            && i < b.len()
            && rng.below(2) == 0
        {
            out.push_str(spaces[rng.below(spaces.len())]);
        }
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn respacing_a_grammar_does_not_change_its_formatted_text(seed in any::<u64>()) {
        for (path, source) in all_sources() {
            let messy = perturb(&source, seed);
            prop_assert_eq!(comment_texts(&messy), comment_texts(&source));
            let expected = format(&source).unwrap();
            let got = format(&messy).map_err(|d| TestCaseError::fail(format!("{path}: perturbed text does not parse: {d:?}\n{messy}")))?;
            prop_assert_eq!(got, expected, "{} seed {}", path, seed);
        }
    }
}

/// Serves the libraries of [`REUSE`].
struct Libs;

impl clay_dsl::Loader for Libs {
    fn load(&self, path: &str) -> std::io::Result<Vec<u8>> {
        let text = match path {
            "lib/types.clay" => "site type joint\n",
            "lib/brick.clay" => {
                "import \"types.clay\"\npiece brick { vertex a (0, 0) vertex b (1, 0) edges a-b site east: joint [b] out (1, 0) }\n"
            }
            _ => return Err(std::io::ErrorKind::NotFound.into()),
        };
        Ok(text.as_bytes().to_vec())
    }
}

const REUSE: &str = "import   \"lib/types.clay\"\nimport \"lib/brick.clay\" // the brick\npiece  capped   extends\n  brick{ // child\n vertex top(0.5,1) edges a-top }\npiece bare extends brick{}\nmodel{c=capped b = bare at (0, 3)}\n";

#[test]
fn imports_and_extends_keep_their_form_and_meaning() {
    let formatted = format(REUSE).unwrap();
    let compiled = |s: &str| {
        let mut g = clay_dsl::compile(s, "x.clay", &clay_dsl::CompileOptions::with_loader(&Libs))
            .map_err(|d| clay_dsl::render(&d, s, "x.clay", false))
            .unwrap()
            .grammar;
        g.source.clear();
        g
    };
    assert_eq!(compiled(REUSE), compiled(&formatted));
    assert_eq!(format(&formatted).unwrap(), formatted, "not idempotent");
    assert!(
        formatted.starts_with(
            "import \"lib/types.clay\"\nimport \"lib/brick.clay\" // the brick\n\npiece capped extends brick { // child\n    vertex top (0.5, 1)\n"
        ),
        "{formatted}"
    );
    assert!(
        formatted.contains("\npiece bare extends brick {\n}\n"),
        "{formatted}"
    );
    let tree = clay_dsl::parse(REUSE).unwrap();
    assert_eq!(compiled(&print_file(&tree)), compiled(REUSE));
}

/// Issue 47: `fmt` was not idempotent with a comment after `variants` (the first run moved it
/// out of the block and kept the block split, the second joined it). A comment placed after
/// every token of every example (where whitespace follows it) keeps `fmt` idempotent, keeps
/// every comment and keeps the grammar's meaning.
#[test]
fn a_comment_after_any_token_keeps_fmt_idempotent() {
    let mut tried = 0;
    for (path, source) in all_sources() {
        let spans = comment_spans(&source);
        let in_comment = |i: usize| spans.iter().any(|s| s.start <= i && i < s.end);
        let b = source.as_bytes();
        let before = meaning(&source);
        for i in 1..b.len() {
            let boundary = b[i].is_ascii_whitespace() && !b[i - 1].is_ascii_whitespace();
            if !boundary || in_comment(i) || in_comment(i - 1) {
                continue;
            }
            let text = format!("{} // c\n{}", &source[..i], &source[i..]);
            let Ok(once) = format(&text) else { continue };
            tried += 1;
            let twice = format(&once).unwrap();
            if once != twice {
                let at = (once.lines().zip(twice.lines()))
                    .position(|(x, y)| x != y)
                    .unwrap_or(0);
                panic!(
                    "{path}: a comment at byte {i} ({:?}): not idempotent from line {}:\n{}\n---\n{}",
                    String::from_utf8_lossy(&b[i.saturating_sub(30)..i]),
                    at + 1,
                    once.lines().skip(at).take(4).collect::<Vec<_>>().join("\n"),
                    twice
                        .lines()
                        .skip(at)
                        .take(4)
                        .collect::<Vec<_>>()
                        .join("\n"),
                );
            }
            assert_eq!(
                comment_texts(&text),
                comment_texts(&once),
                "{path}: a comment at byte {i}: comments lost, added or reordered"
            );
            // the meaning, at every 16th place (a compile each is the slow part)
            if tried % 16 == 0 {
                assert_eq!(before, meaning(&once), "{path}: a comment at byte {i}");
            }
        }
    }
    assert!(tried > 1000, "only {tried} places tried");
}
