//! Byte offsets <-> positions for one text, built once per text (O(length)), so each lookup is a
//! binary search plus the length of its own line instead of a scan from the file's start:
//! thousands of diagnostics in one large file stay linear.
//!
//! The compiler's spans are byte offsets. Diagnostics show 1-based lines and columns in
//! characters ([`LineIndex::line_col`], the same as [`crate::line_col`]); the Language Server
//! Protocol counts 0-based columns in UTF-16 code units ([`LineIndex::position`]). Every
//! conversion goes through this index so they never disagree.

/// Line starts of one text, for converting positions both ways.
#[derive(Clone, Debug)]
pub struct LineIndex {
    text: String,
    /// Byte offset where each line starts; the first is 0.
    starts: Vec<usize>,
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
        Self {
            text: text.to_string(),
            starts,
        }
    }

    /// The position of byte `offset` (clamped into the text and back to a char boundary).
    pub fn position(&self, offset: usize) -> LinePos {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        let line = self.starts.partition_point(|&s| s <= offset) - 1;
        let col: usize = self.text[self.starts[line]..offset]
            .chars()
            .map(char::len_utf16)
            .sum();
        LinePos {
            line: line as u32,
            col: col as u32,
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
        let line = self.starts.partition_point(|&s| s <= offset) - 1;
        let col = self.text[self.starts[line]..offset].chars().count();
        (line + 1, col + 1)
    }

    pub fn text(&self) -> &str {
        &self.text
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
}
