//! The source map: every file of a compilation (the main file and the files it imports) owns a
//! disjoint range of global byte positions, as in rustc. The main file starts at 0, so a grammar
//! without imports has spans that are plain byte offsets into its text; each imported file
//! starts one past the end of the previous one. [`Span`] stays `{start, end}` everywhere; the
//! renderers map a span back to its file and local offset through [`SourceMap::locate`].
//!
//! The map holds the imported files only: the main file's text and path are what the caller of
//! `render` and `to_json` pass, as before imports existed.

use std::sync::Arc;

use crate::syntax::Span;

/// An imported file: the path it is shown under, its text, and where its global positions start.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SourceFile {
    /// The path as resolved from the importing file (`grammars/lib/roads.clay`).
    pub path: String,
    pub text: Arc<str>,
    /// Global position of the file's first byte; its bytes are `base..base + text.len()`.
    pub base: usize,
}

impl SourceFile {
    /// One past the file's last global position.
    pub fn end(&self) -> usize {
        self.base + self.text.len()
    }
}

/// The imported files of a compilation, in order of their global positions.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SourceMap {
    pub files: Vec<SourceFile>,
}

/// A span mapped back to its file: the file's path and text, and local byte offsets into it
/// (clamped into the text, on character boundaries).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Located<'a> {
    pub path: &'a str,
    pub text: &'a str,
    /// Index of the file: 0 for the main file, `k + 1` for `SourceMap::files[k]`.
    pub file: usize,
    pub start: usize,
    pub end: usize,
}

impl SourceMap {
    pub fn is_empty(&self) -> bool {
        self.files.is_empty()
    }

    /// The global position where the next imported file starts, after a main file of
    /// `main_len` bytes and the files already in the map.
    pub fn next_base(&self, main_len: usize) -> usize {
        self.files.last().map_or(main_len, SourceFile::end) + 1
    }

    /// Maps a global span back to its file: the main file (`source`, shown as `path`) for
    /// positions up to its end, else the imported file whose range holds `span.start`. The end
    /// is clamped into the same file.
    pub fn locate<'a>(&'a self, source: &'a str, path: &'a str, span: Span) -> Located<'a> {
        let (file, path, text, base) = match self
            .files
            .iter()
            .enumerate()
            .rev()
            .find(|(_, f)| f.base <= span.start && span.start > source.len())
        {
            Some((k, f)) => (k + 1, f.path.as_str(), &*f.text, f.base),
            None => (0, path, source, 0),
        };
        let mut start = span.start.saturating_sub(base).min(text.len());
        let mut end = span.end.saturating_sub(base).min(text.len()).max(start);
        while !text.is_char_boundary(start) {
            start -= 1;
        }
        while !text.is_char_boundary(end) {
            end += 1;
        }
        Located {
            path,
            text,
            file,
            start,
            end,
        }
    }

    /// The file, 1-based line and column (in chars) of a global position.
    pub fn line_col<'a>(
        &'a self,
        source: &'a str,
        path: &'a str,
        pos: usize,
    ) -> (&'a str, usize, usize) {
        let at = self.locate(source, path, Span::new(pos, pos));
        let (line, col) = line_col(at.text, at.start);
        (at.path, line, col)
    }
}

/// 1-based line and column (in chars) of byte offset `byte` of `source`; offsets past the end
/// or inside a UTF-8 sequence are clamped back to the nearest valid position.
pub fn line_col(source: &str, byte: usize) -> (usize, usize) {
    let mut byte = byte.min(source.len());
    while !source.is_char_boundary(byte) {
        byte -= 1;
    }
    let before = &source[..byte];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let col = source[line_start..byte].chars().count() + 1;
    (line, col)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map() -> SourceMap {
        // main: "abc\n" (0..4); lib: base 5.
        SourceMap {
            files: vec![SourceFile {
                path: "lib.clay".into(),
                text: Arc::from("xy\nzé\n"),
                base: 5,
            }],
        }
    }

    #[test]
    fn main_positions_stay_local_and_imported_ones_map_to_their_file() {
        let m = map();
        let main = m.locate("abc\n", "main.clay", Span::new(1, 3));
        assert_eq!(
            (main.path, main.file, main.start, main.end),
            ("main.clay", 0, 1, 3)
        );
        // The main file's end-of-file position is still the main file.
        assert_eq!(m.locate("abc\n", "main.clay", Span::new(4, 4)).file, 0);
        let lib = m.locate("abc\n", "main.clay", Span::new(8, 9));
        assert_eq!(
            (lib.path, lib.file, lib.start, lib.end),
            ("lib.clay", 1, 3, 4)
        );
        assert_eq!(m.line_col("abc\n", "main.clay", 8), ("lib.clay", 2, 1));
        assert_eq!(m.next_base(4), 13);
    }

    #[test]
    fn spans_are_clamped_into_their_file_on_char_boundaries() {
        let m = map();
        // Inside `é` (bytes 4..6 of lib) and past the end.
        let l = m.locate("abc\n", "main.clay", Span::new(10, 100));
        assert_eq!((l.start, l.end), (4, 7));
        assert!(l.text.is_char_boundary(l.start) && l.text.is_char_boundary(l.end));
    }
}
