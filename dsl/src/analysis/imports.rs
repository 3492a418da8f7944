//! The files an analysed text imports, for queries across files. The compiler already loaded
//! them (through the caller's loader) into its source map; here each is parsed again at its
//! place in the global positions, so its declarations join the one symbol table: a use in the
//! analysed text resolves to a piece declared in `lib.clay` like to one declared beside it.
//!
//! A span past the end of the analysed text lies in an imported file; [`Place`] is a span
//! mapped back to its file.

use crate::line_index::LineIndex;
use crate::source_map::{SourceFile, SourceMap};
use crate::syntax::{Item, Span};

/// A span in one of the files of an analysis: `file` 0 is the analysed text, `k + 1` its
/// `k`th imported file (`Analysis::path`); `span` is local to that file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Place {
    pub file: usize,
    pub span: Span,
}

/// The imported files: where their positions lie, and a line index of each.
#[derive(Clone, Debug, Default)]
pub(super) struct Imported {
    pub sources: SourceMap,
    pub indexes: Vec<LineIndex>,
}

impl Imported {
    /// The files of `sources` placed after a main text of `main_len` bytes (their places in
    /// an earlier analysis may overlap a longer text), and their declarations: what an import
    /// brings, so no `model`, `solver` or further `import` (those files are in `sources` too).
    pub fn of(sources: &SourceMap, main_len: usize) -> (Self, Vec<Item>) {
        let mut placed = Imported::default();
        let mut items = Vec::new();
        for f in &sources.files {
            let base = placed.sources.next_base(main_len);
            placed.sources.files.push(SourceFile {
                path: f.path.clone(),
                text: f.text.clone(),
                base,
            });
            placed.indexes.push(LineIndex::new(&f.text));
            // A file that does not parse brought nothing (the compiler reported it).
            if let Ok(file) = crate::parse::parse_at(&f.text, base) {
                items.extend(
                    file.items.into_iter().filter(|i| {
                        !matches!(i, Item::Model(_) | Item::Solver(_) | Item::Import(_))
                    }),
                );
            }
        }
        (placed, items)
    }
}
