//! `clay-editor --follow` driven headless from both ends: the language server's side (the
//! analysis' focus of a cursor position, written to the channel as `clayc lsp` writes it) makes
//! the editor highlight the right instances and sites; `G` over a part writes the reveal the
//! server reads.

mod common;

use std::path::{Path, PathBuf};

use clay_dsl::analysis::Analysis;
use clay_dsl::analysis::follow::{self, Focus};
use clay_editor::EditorApp;
use clay_editor::sculpt::follow::Follow;
use egui_kittest::kittest::Queryable;

use common::{harness, settle};

/// A copy of `grammars/wall.clay` (a chain `wall` of 8 `brick`s) and a channel folder, both
/// in a fresh folder; removed when dropped.
struct Setup {
    dir: PathBuf,
    grammar: PathBuf,
    text: String,
}

impl Setup {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("clay-follow-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../grammars/wall.clay"
        ))
        .unwrap();
        let grammar = dir.join("wall.clay");
        std::fs::write(&grammar, &text).unwrap();
        Self { dir, grammar, text }
    }

    fn channel(&self) -> PathBuf {
        self.dir.join("channel")
    }

    /// What the server writes when the cursor is `into` bytes into the first `needle` of the
    /// text.
    fn cursor_at(&self, needle: &str, into: usize) -> Focus {
        let a = Analysis::new(&self.text, &self.grammar.display().to_string());
        let offset = self.text.find(needle).unwrap() + into;
        let focus = a.focus(offset).expect("a name at the cursor");
        follow::write(&self.channel(), follow::CURSOR, &focus).unwrap();
        focus
    }
}

impl Drop for Setup {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

fn following(s: &Setup) -> EditorApp {
    let mut app = EditorApp::open(&s.grammar);
    app.follow = Some(Follow::new(s.channel()));
    assert!(s.channel().is_dir(), "following creates the channel");
    app
}

/// Steps until the editor has read the cursor file (it looks a few times a second).
fn until_followed(h: &mut egui_kittest::Harness<'_, EditorApp>, focus: &Focus) {
    let until = std::time::Instant::now() + std::time::Duration::from_secs(30);
    while h.state().follow.as_ref().unwrap().focus.as_ref() != Some(focus) {
        assert!(std::time::Instant::now() < until, "the focus was not read");
        std::thread::sleep(std::time::Duration::from_millis(20));
        h.step();
    }
}

#[test]
fn the_cursor_on_a_piece_a_site_or_the_chain_highlights_it_in_the_preview() {
    let s = Setup::new("cursor");
    let mut h = harness(following(&s));
    settle(&mut h);
    let instances = h.state().sculpt.data().instances.len();
    assert_eq!(instances, 8);

    let piece = s.cursor_at("piece brick", 6);
    assert_eq!(
        (piece.kind.as_str(), piece.name.as_str()),
        ("piece", "brick")
    );
    until_followed(&mut h, &piece);
    let lit = h.state().followed();
    assert_eq!(lit.instances, (0..8).collect::<Vec<_>>());
    assert!(lit.sites.is_empty());

    // The site `west` (its declaration): the site on every brick.
    let site = s.cursor_at("site west", 5);
    until_followed(&mut h, &site);
    let lit = h.state().followed();
    assert_eq!(lit.sites.len(), 8, "{lit:?}");
    assert!(
        lit.instances.is_empty(),
        "a site is ringed, its pieces are not outlined"
    );
    let west = h.state().sculpt.grammar().pieces[0]
        .sites
        .iter()
        .position(|x| x.name == "west")
        .unwrap();
    assert!(lit.sites.iter().all(|&(_, k)| k == west));

    // The chain in the model: its elements.
    let chain = s.cursor_at("wall = chain", 0);
    assert_eq!(chain.kind, "chain");
    until_followed(&mut h, &chain);
    assert_eq!(h.state().followed().instances.len(), 8);

    // A cursor in another grammar lights nothing here.
    let elsewhere = Focus {
        file: "/elsewhere/town.clay".into(),
        ..piece.clone()
    };
    follow::write(&s.channel(), follow::CURSOR, &elsewhere).unwrap();
    until_followed(&mut h, &elsewhere);
    assert_eq!(h.state().followed(), Default::default());
    h.step();
}

#[test]
fn g_over_a_part_asks_the_text_editor_to_show_its_declaration() {
    let s = Setup::new("reveal");
    let mut h = harness(following(&s));
    settle(&mut h);
    let at = h.get_by_label("part 0").rect().center();
    h.hover_at(at);
    h.step();
    assert_eq!(h.state().canvas.hovered, Some(0));
    h.key_press(egui::Key::G);
    h.step();
    let reveal = follow::read(&s.channel().join(follow::REVEAL)).expect("a reveal written");
    let real = |p: &Path| std::fs::canonicalize(p).unwrap().display().to_string();
    assert_eq!(
        reveal,
        Focus {
            file: real(&s.grammar),
            kind: "instance".into(),
            name: "wall".into(),
            piece: Some("brick".into()),
        }
    );
    // What the server does with it: the chain's declaration in the grammar.
    let a = Analysis::new(&s.text, &s.grammar.display().to_string());
    let decl = a.declaration_of(&reveal).unwrap();
    assert_eq!(decl.start, s.text.find("wall = chain").unwrap());
    assert!(h.state().message.as_deref().unwrap().contains("`wall`"));
}
