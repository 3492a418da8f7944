//! The Clay editor follows the text editor (docs/editors.md, "The Clay editor follows the text
//! editor"): a [`Focus`] names what the cursor is on (a piece, site, instance, ...), and two
//! small files in a per-user folder carry it between the processes. `clayc lsp` writes
//! [`CURSOR`] when the cursor moves onto another name; `clay-editor --follow` reads it and
//! highlights that part of the model. The other way, the editor writes [`REVEAL`] for the part
//! under the mouse and the server asks the text editor to show its declaration.
//!
//! A file is written whole to a temporary name and renamed over the old one, so a reader
//! never sees half of it. The server writes only while the folder exists (the editor creates
//! it), so a server without a following editor writes nothing.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::{Analysis, SymbolKind};
use crate::syntax::Span;

/// The file the server writes: where the text editor's cursor is.
pub const CURSOR: &str = "cursor.json";
/// The file the Clay editor writes: the declaration to show in the text editor.
pub const REVEAL: &str = "reveal.json";

/// A declared name, as both editors know it: by kind and name, not by position.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Focus {
    /// The grammar file the name is seen in (the text editor's document, or the Clay editor's
    /// grammar).
    pub file: String,
    /// What the name declares: [`SymbolKind::word`] (`piece`, `site`, `instance`, ...).
    pub kind: String,
    pub name: String,
    /// The piece a vertex, site or rest state belongs to, or an instance or chain is made of.
    pub piece: Option<String>,
}

/// The folder of the two files: `$CLAY_FOLLOW_DIR` when set, else `clay-follow` in the user's
/// runtime folder (`$XDG_RUNTIME_DIR`), else in the temporary folder.
pub fn channel() -> PathBuf {
    if let Some(dir) = std::env::var_os("CLAY_FOLLOW_DIR") {
        return PathBuf::from(dir);
    }
    let base = std::env::var_os("XDG_RUNTIME_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(std::env::temp_dir);
    base.join("clay-follow")
}

/// Writes `focus` to `dir/name` atomically (a temporary file renamed over it).
pub fn write(dir: &Path, name: &str, focus: &Focus) -> std::io::Result<()> {
    let json = serde_json::to_vec(focus).map_err(std::io::Error::other)?;
    let tmp = dir.join(format!(".{name}.{}", std::process::id()));
    std::fs::write(&tmp, json)?;
    std::fs::rename(&tmp, dir.join(name))
}

/// The focus in the file at `path`, if it holds one (a named pipe there is not waited on).
pub fn read(path: &Path) -> Option<Focus> {
    let bytes = crate::input::read_input(path, crate::input::MAX_SOURCE_BYTES).ok()?;
    serde_json::from_slice(&bytes).ok()
}

impl Analysis {
    /// What the name at `offset` declares, for the Clay editor to highlight.
    pub fn focus(&self, offset: usize) -> Option<Focus> {
        let syms = &self.symbols().symbols;
        let s = &syms[self.symbol_at(offset)?];
        let piece = match s.kind {
            SymbolKind::Piece => Some(s.name.clone()),
            SymbolKind::Instance | SymbolKind::Chain => s.piece.clone(),
            _ => s.container.map(|c| syms[c].name.clone()),
        };
        Some(Focus {
            file: self.path(0).to_string(),
            kind: s.kind.word().to_string(),
            name: s.name.clone(),
            piece,
        })
    }

    /// The declaration a focus names, in this text or a file it imports (a span of this
    /// analysis, see [`Analysis::place`]). An instance not declared in the model (one a rule
    /// inserted) falls back to its piece.
    pub fn declaration_of(&self, focus: &Focus) -> Option<Span> {
        let syms = &self.symbols().symbols;
        let owner = |s: &super::Symbol| match s.kind {
            SymbolKind::Instance | SymbolKind::Chain => s.piece.clone(),
            SymbolKind::Piece => Some(s.name.clone()),
            _ => s.container.map(|c| syms[c].name.clone()),
        };
        // The Clay editor sees a chain's elements as instances (`wall[3]`).
        let kind_is = |s: &super::Symbol, kind: &str| {
            s.kind.word() == kind || (kind == "instance" && s.kind == SymbolKind::Chain)
        };
        let named = |kind: &str, name: &str| {
            syms.iter().find(|s| {
                s.kind != SymbolKind::Rule
                    && kind_is(s, kind)
                    && s.name == name
                    && (focus.piece.is_none() || owner(s) == focus.piece)
            })
        };
        named(&focus.kind, &focus.name)
            .or_else(|| {
                let piece = focus.piece.as_deref()?;
                syms.iter()
                    .find(|s| s.kind == SymbolKind::Piece && s.name == piece)
            })
            .map(|s| s.span)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_focus_names_the_symbol_and_leads_back_to_its_declaration() {
        let text = "site type joint\npiece brick {\n    vertex a (0, 0)\n    vertex b (1, 0)\n    \
                    vertex c (1, 1)\n    edges a-b-c-a\n    site west: joint [a, c] out (-1, 0)\n}\n\
                    model {\n    wall = chain brick x 3\n}\n";
        let a = Analysis::new(text, "/g/wall.clay");
        let f = a.focus(text.find("west").unwrap()).unwrap();
        assert_eq!(
            f,
            Focus {
                file: "/g/wall.clay".into(),
                kind: "site".into(),
                name: "west".into(),
                piece: Some("brick".into()),
            }
        );
        let wall = a.focus(text.find("wall").unwrap()).unwrap();
        assert_eq!(
            (wall.kind.as_str(), wall.piece.as_deref()),
            ("chain", Some("brick"))
        );
        let decl = a.declaration_of(&f).unwrap();
        assert_eq!(&text[decl.start..decl.end], "west");
        // A chain's element as the Clay editor names it; an instance the model does not
        // declare: its piece.
        let element = Focus {
            kind: "instance".into(),
            ..wall.clone()
        };
        let decl = a.declaration_of(&element).unwrap();
        assert_eq!(&text[decl.start..decl.end], "wall");
        let inserted = Focus {
            kind: "instance".into(),
            name: "brick#7".into(),
            ..wall
        };
        let decl = a.declaration_of(&inserted).unwrap();
        assert_eq!(decl.start, text.find("brick").unwrap());

        let dir = std::env::temp_dir().join(format!("clay-follow-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        write(&dir, CURSOR, &f).unwrap();
        assert_eq!(read(&dir.join(CURSOR)), Some(f));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
