//! Byte offsets <-> positions for one text, built once per text (O(length)), so each lookup is a
//! binary search plus at most [`STRIDE`] bytes of counting from the nearest mark before it,
//! however long its line: thousands of diagnostics in one large file, or every semantic token
//! of a 200 KB line, stay linear (issue 47: the tokens of such a line took 29 s).
//!
//! The compiler's spans are byte offsets. Diagnostics show 1-based lines and columns in
//! characters ([`LineIndex::line_col`], the same as [`crate::line_col`]); the Language Server
//! Protocol counts 0-based columns in UTF-16 code units ([`LineIndex::position`]). Every
//! conversion goes through this index so they never disagree.

/// Bytes between two marks: the most a lookup counts.
const STRIDE: usize = 256;

/// Line starts of one text, for converting positions both ways.
#[derive(Clone, Debug)]
pub struct LineIndex {
    text: String,
    /// Byte offset where each line starts; the first is 0.
    starts: Vec<usize>,
    /// A mark at the first char boundary of every [`STRIDE`] bytes, in order.
    marks: Vec<Mark>,
}

/// The columns within its line of a char boundary: a lookup counts from the nearest mark.
#[derive(Clone, Copy, Debug)]
struct Mark {
    byte: usize,
    utf16: u32,
    chars: u32,
}

/// A 0-based line and a 0-based column in UTF-16 code units (the protocol's position).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct LinePos {
    pub line: u32,
    pub col: u32,
}

impl LineIndex {
    pub fn new(text: &str) -> Self {
        let mut starts = vec![0];
        starts.extend(text.match_indices('\n').map(|(i, _)| i + 1));
        let mut marks = Vec::with_capacity(text.len() / STRIDE + 1);
        let (mut utf16, mut chars) = (0u32, 0u32);
        for (i, c) in text.char_indices() {
            if i >= marks.len() * STRIDE {
                marks.push(Mark {
                    byte: i,
                    utf16,
                    chars,
                });
            }
            if c == '\n' {
                (utf16, chars) = (0, 0);
            } else {
                utf16 += c.len_utf16() as u32;
                chars += 1;
            }
        }
        Self {
            text: text.to_string(),
            starts,
            marks,
        }
    }

    /// The line of a char boundary `offset`, and its columns (UTF-16 units, chars) there:
    /// counted from the nearest mark at or before it on its line, or from the line's start.
    fn locate(&self, offset: usize) -> (usize, u32, u32) {
        let line = self.starts.partition_point(|&s| s <= offset) - 1;
        let start = self.starts[line];
        let k = self.marks.partition_point(|m| m.byte <= offset);
        let (from, mut utf16, mut chars) = match k.checked_sub(1).map(|k| self.marks[k]) {
            Some(m) if m.byte >= start => (m.byte, m.utf16, m.chars),
            _ => (start, 0, 0),
        };
        for c in self.text[from..offset].chars() {
            utf16 += c.len_utf16() as u32;
            chars += 1;
        }
        (line, utf16, chars)
    }

    /// The position of byte `offset` (clamped into the text and back to a char boundary).
    pub fn position(&self, offset: usize) -> LinePos {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        let (line, col, _) = self.locate(offset);
        LinePos {
            line: line as u32,
            col,
        }
    }

    /// The byte offset of a position; a line past the end gives the end of the text, a column
    /// past the end of its line gives the end of that line, and a column inside a character's
    /// UTF-16 pair gives the start of that character.
    pub fn offset(&self, pos: LinePos) -> usize {
        let Some(&start) = self.starts.get(pos.line as usize) else {
            return self.text.len();
        };
        let end = self
            .starts
            .get(pos.line as usize + 1)
            .map_or(self.text.len(), |&next| next - 1);
        let mut units = 0u32;
        for (i, c) in self.text[start..end].char_indices() {
            let next = units + c.len_utf16() as u32;
            if next > pos.col {
                return start + i;
            }
            units = next;
        }
        end
    }

    /// 1-based line and column in characters of byte `offset` (clamped as [`Self::position`]):
    /// what diagnostics show, the same as [`crate::line_col`].
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        let (line, _, col) = self.locate(offset);
        (line + 1, col as usize + 1)
    }

    pub fn text(&self) -> &str {
        &self.text
    }

    /// Byte offset where each line starts; the first is 0.
    pub fn line_starts(&self) -> &[usize] {
        &self.starts
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_through_utf16_columns() {
        let text = "ab\n// é😀x\n\nlast";
        let idx = LineIndex::new(text);
        for (i, _) in text.char_indices() {
            assert_eq!(idx.offset(idx.position(i)), i, "offset {i}");
        }
        let x = text.find('x').unwrap();
        // `// ` is 3 units, `é` 1, the emoji 2.
        assert_eq!(idx.position(x), LinePos { line: 1, col: 6 });
        assert_eq!(idx.offset(LinePos { line: 9, col: 0 }), text.len());
        assert_eq!(idx.offset(LinePos { line: 0, col: 99 }), 2);
    }

    /// Columns counted from the marks agree with counting from the line's start, on long
    /// lines of several-byte characters that straddle the marks.
    #[test]
    fn marks_give_the_columns_counting_from_the_line_start_gives() {
        let line = "é😀ab ".repeat(300);
        let text = format!("{line}\nx{line}\n\n{line}");
        let idx = LineIndex::new(&text);
        for (i, _) in text.char_indices() {
            let start = text[..i].rfind('\n').map_or(0, |n| n + 1);
            let utf16: usize = text[start..i].chars().map(char::len_utf16).sum();
            let chars = text[start..i].chars().count();
            let line = text[..i].matches('\n').count();
            assert_eq!(
                idx.position(i),
                LinePos {
                    line: line as u32,
                    col: utf16 as u32
                },
                "offset {i}"
            );
            assert_eq!(idx.line_col(i), (line + 1, chars + 1), "offset {i}");
            assert_eq!(idx.offset(idx.position(i)), i, "offset {i}");
        }
    }
}
