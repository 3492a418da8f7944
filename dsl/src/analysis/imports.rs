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
/// `k`th imported file ([`super::Analysis::path`]); `span` is local to that file.
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

#[cfg(test)]
mod tests {
    use super::super::Analysis;

    #[test]
    fn an_imported_piece_answers_also_while_the_text_does_not_parse() {
        let dir =
            std::env::temp_dir().join(format!("clay-analysis-imports-{}", std::process::id()));
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
}
