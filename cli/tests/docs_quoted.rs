//! What the docs quote of `clayc`'s output is what it prints today (issue 40): the README's
//! `clayc check` transcript, run again; the E011 position `docs/editors.md` quotes for
//! `grammars/wall.clay` with a typo, and `docs/neovim-session.txt`'s capture of that file.

use std::path::PathBuf;
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

fn read(path: &str) -> String {
    std::fs::read_to_string(root().join(path)).unwrap()
}

/// The text block after `heading` in `doc`: its lines, fences excluded.
fn block_after<'a>(doc: &'a str, heading: &str) -> Vec<&'a str> {
    let at = doc
        .find(heading)
        .unwrap_or_else(|| panic!("no `{heading}`"));
    doc[at..]
        .lines()
        .skip_while(|l| !l.starts_with("```"))
        .skip(1)
        .take_while(|l| !l.starts_with("```"))
        .collect()
}

/// A word of a quoted command with `*` in it, expanded as the shell does (sorted).
fn glob(word: &str) -> Vec<String> {
    let Some((dir, pattern)) = word.rsplit_once('/') else {
        return vec![word.to_string()];
    };
    let Some((prefix, suffix)) = pattern.split_once('*') else {
        return vec![word.to_string()];
    };
    let mut found: Vec<String> = std::fs::read_dir(root().join(dir))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(prefix) && n.ends_with(suffix))
        .map(|n| format!("{dir}/{n}"))
        .collect();
    found.sort();
    assert!(!found.is_empty(), "`{word}` matches nothing");
    found
}

#[test]
fn the_readmes_check_transcript_is_what_clayc_prints() {
    let readme = read("README.md");
    let block = block_after(&readme, "`clayc check` example:");
    let mut commands: Vec<(&str, Vec<&str>)> = Vec::new();
    for line in block {
        match line.strip_prefix("$ ") {
            Some(command) => commands.push((command, Vec::new())),
            None => commands.last_mut().expect("a `$` line first").1.push(line),
        }
    }
    assert_eq!(
        commands.len(),
        2,
        "the check of every grammar and of a typo"
    );
    for (command, quoted) in commands {
        let mut words = command.split_whitespace();
        assert_eq!(words.next(), Some("clayc"), "{command}");
        let args: Vec<String> = words.flat_map(glob).collect();
        let out = Command::new(env!("CARGO_BIN_EXE_clayc"))
            .args(&args)
            .current_dir(root())
            .env("NO_COLOR", "1")
            .output()
            .unwrap();
        let printed = format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(
            printed.trim_end(),
            quoted.join("\n"),
            "the README quotes `{command}` as clayc printed it once; it prints this now"
        );
    }
}

/// `grammars/wall.clay` with the typo the editor docs use (`jiont` for `joint`).
fn wall_with_typo() -> String {
    let wall = read("grammars/wall.clay");
    let typo = wall.replace("site west: joint", "site west: jiont");
    assert_ne!(typo, wall, "the typo applies");
    typo
}

/// The 1-based line of the first `needle` in `text`.
fn line_of(text: &str, needle: &str) -> usize {
    let at = text.find(needle).unwrap_or_else(|| panic!("no `{needle}`"));
    text[..at].matches('\n').count() + 1
}

/// The numbers after the first `before` in `doc`, up to `after`: `E011 ` ... ` unknown`.
fn quoted<'a>(doc: &'a str, before: &str, after: &str) -> &'a str {
    let start = doc.find(before).unwrap_or_else(|| panic!("no `{before}`")) + before.len();
    let len = doc[start..]
        .find(after)
        .unwrap_or_else(|| panic!("no `{after}`"));
    &doc[start..start + len]
}

#[test]
fn the_positions_docs_editors_md_quotes_are_the_diagnostics_and_declarations() {
    let typo = wall_with_typo();
    let diags =
        clay_dsl::compile(&typo, "wall.clay", &clay_dsl::CompileOptions::default()).unwrap_err();
    assert_eq!(diags.len(), 1, "one error for one typo");
    let d = diags.iter().next().unwrap();
    assert_eq!(d.code, "E011");
    let (line, col) = clay_dsl::line_col(&typo, d.primary.span.start);
    let doc = read("docs/editors.md");
    // The Neovim test's line, as it prints it (`cli/tests/lsp.rs`).
    assert_eq!(
        quoted(&doc, "`E011 ", " unknown site type"),
        format!("{line}:{col}"),
        "docs/editors.md quotes where Neovim shows the E011 of wall.clay's typo"
    );
    // Emacs's go to definition on `chain brick`.
    assert_eq!(
        quoted(&doc, "go to definition landed on line ", ", `piece brick`"),
        line_of(&typo, "piece brick {").to_string()
    );
}

#[test]
fn the_neovim_session_shows_todays_wall_clay() {
    let typo = wall_with_typo();
    let file: Vec<&str> = typo.lines().collect();
    let (typo_line, chain_line) = (line_of(&typo, "jiont"), line_of(&typo, "chain brick"));
    let session = read("docs/neovim-session.txt");
    let heading = format!("== the diagnostic (cursor on line {typo_line})");
    assert!(session.contains(&heading), "no `{heading}`");
    let hover = format!("== the hover on `chain brick` (line {chain_line}, K)");
    assert!(session.contains(&hover), "no `{hover}`");
    // The first screen shows the file from its top: two columns of signs, then its lines.
    let screen: Vec<&str> = session[session.find(&heading).unwrap()..]
        .lines()
        .skip(2)
        .take_while(|l| !l.starts_with("wall.clay "))
        .collect();
    assert!(screen.len() > typo_line, "the typo's line is on the screen");
    for (i, row) in screen.iter().enumerate() {
        let row = format!("{row:<2}");
        let (sign, text) = row.split_at(2);
        if i + 1 == typo_line {
            assert_eq!(sign, "E ", "the error's sign on line {typo_line}");
            assert!(
                text.starts_with(&format!("{}     ■ unknown site type `jiont`", file[i])),
                "{text}"
            );
        } else {
            assert_eq!(sign, "  ", "line {}: {row}", i + 1);
            assert_eq!(text.trim_end(), file[i].trim_end(), "line {}", i + 1);
        }
    }
    // The status lines: the cursor where the capture put it.
    let status = |after: &str| -> String {
        session[session.find(after).unwrap()..]
            .lines()
            .find(|l| l.starts_with("wall.clay "))
            .unwrap()
            .split_whitespace()
            .nth(1)
            .unwrap()
            .to_string()
    };
    assert_eq!(status(&heading), format!("{typo_line},1"));
    assert_eq!(status(&hover), format!("{chain_line},19"));
    // Column 19 (1-based) is on `brick` of `chain brick`, where K hovers.
    let chain = file[chain_line - 1];
    let brick = chain.find("chain brick").unwrap() + "chain ".len();
    assert!((brick..brick + "brick".len()).contains(&18), "{chain}");
}

#[test]
fn the_cut_gesture_the_example_grammars_name_is_the_editors() {
    // docs/editor.md's gestures table is the editor's (editor/tests/view.rs keeps them equal).
    let doc = read("docs/editor.md");
    let gesture = doc
        .lines()
        .find_map(|l| l.strip_suffix(" | cut that connection |"))
        .and_then(|l| l.strip_prefix("| "))
        .expect("the cut's row in docs/editor.md")
        .replace(' ', "");
    let mut named = 0;
    for path in glob("grammars/*.clay") {
        let text = read(&path);
        let joined = text.replace("\n// ", " ");
        for (at, _) in joined.match_indices("Cut (") {
            let inside = &joined[at + "Cut (".len()..];
            let inside = &inside[..inside.find(')').unwrap()];
            assert_eq!(inside, gesture, "{path} names the cut gesture `{inside}`");
            named += 1;
        }
    }
    assert!(named >= 2, "streets.clay and junction.clay say how to cut");
}
