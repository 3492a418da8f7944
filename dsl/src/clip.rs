//! The source a human diagnostic shows, with long lines clipped: codespan prints every
//! labelled line whole, so one mistake on a 270 KB line printed 270 KB (13.5 MB for fifty).
//! A line longer than [`MAX_SHOWN_LINE`] bytes is shown as a window around the diagnostic's
//! first label on it (`…` where it was cut); the line and column numbers stay the original
//! file's, answered by its [`LineIndex`] (the one conversion of offsets to positions).

use std::borrow::Cow;
use std::ops::Range;

use codespan_reporting::files::{Error, Files};

use crate::line_index::LineIndex;

/// The longest line a human diagnostic shows whole, in bytes.
pub const MAX_SHOWN_LINE: usize = 240;

/// The mark where a shown line was cut.
const CUT: &str = "…";

/// One file as a diagnostic shows it: the original, or a copy with its long lines clipped and
/// the map from the copy's bytes back to the original's.
pub(crate) struct ShownFile<'a> {
    name: &'a str,
    original: &'a LineIndex,
    /// The text shown and its lines: the original's, or the clipped copy's.
    shown: Cow<'a, LineIndex>,
    /// Runs of bytes copied, `(shown start, original start, length)`, in order.
    runs: Vec<(usize, usize, usize)>,
}

/// Whether any line of the text is longer than [`MAX_SHOWN_LINE`] bytes.
pub(crate) fn has_long_line(index: &LineIndex) -> bool {
    let starts = index.line_starts();
    let ends = starts
        .iter()
        .skip(1)
        .copied()
        .chain([index.text().len() + 1]);
    starts
        .iter()
        .zip(ends)
        .any(|(&s, e)| e - s - 1 > MAX_SHOWN_LINE)
}

impl<'a> ShownFile<'a> {
    /// The file as it is.
    pub(crate) fn whole(name: &'a str, original: &'a LineIndex) -> Self {
        Self {
            name,
            original,
            shown: Cow::Borrowed(original),
            runs: vec![(0, 0, original.text().len())],
        }
    }

    /// The file with every line longer than [`MAX_SHOWN_LINE`] clipped to a window around
    /// the first of `labels` (byte ranges into it) that starts on it, or to its start.
    pub(crate) fn clipped(name: &'a str, original: &'a LineIndex, labels: &[Range<usize>]) -> Self {
        let text = original.text();
        let starts = original.line_starts();
        let mut shown = String::with_capacity(text.len().min(1 << 16));
        let mut runs: Vec<(usize, usize, usize)> = Vec::new();
        let mut copy = |shown: &mut String, from: usize, to: usize| {
            if from >= to {
                return;
            }
            match runs.last_mut() {
                Some(r) if r.0 + r.2 == shown.len() && r.1 + r.2 == from => r.2 += to - from,
                _ => runs.push((shown.len(), from, to - from)),
            }
            shown.push_str(&text[from..to]);
        };
        for (k, &start) in starts.iter().enumerate() {
            let next = starts.get(k + 1).copied().unwrap_or(text.len());
            let end = next - usize::from(text[start..next].ends_with('\n'));
            if end - start <= MAX_SHOWN_LINE {
                copy(&mut shown, start, next);
                continue;
            }
            let at = (labels.iter())
                .map(|l| l.start)
                .filter(|&s| s >= start && s <= end)
                .min()
                .unwrap_or(start);
            let from = floor_boundary(text, at.saturating_sub(MAX_SHOWN_LINE / 3).max(start));
            let to = floor_boundary(text, (from + MAX_SHOWN_LINE).min(end));
            if from > start {
                shown.push_str(CUT);
            }
            copy(&mut shown, from, to);
            if to < end {
                shown.push_str(CUT);
            }
            copy(&mut shown, end, next);
        }
        Self {
            name,
            original,
            shown: Cow::Owned(LineIndex::new(&shown)),
            runs,
        }
    }

    /// The shown byte of original byte `b` (the nearest shown one where it was cut away).
    pub(crate) fn to_shown(&self, b: usize) -> usize {
        let k = self.runs.partition_point(|r| r.1 + r.2 < b);
        match self.runs.get(k) {
            Some(&(s, o, n)) => s + b.saturating_sub(o).min(n),
            None => self.shown.text().len(),
        }
    }

    /// The original byte of shown byte `b`.
    fn to_original(&self, b: usize) -> usize {
        let k = self.runs.partition_point(|r| r.0 + r.2 < b);
        match self.runs.get(k) {
            Some(&(s, o, n)) => o + b.saturating_sub(s).min(n),
            None => self.original.text().len(),
        }
    }
}

/// The largest char boundary of `text` at or before `b`.
fn floor_boundary(text: &str, mut b: usize) -> usize {
    b = b.min(text.len());
    while !text.is_char_boundary(b) {
        b -= 1;
    }
    b
}

/// The files a diagnostic shows, by the ids its labels use.
pub(crate) struct Shown<'a>(pub(crate) Vec<ShownFile<'a>>);

impl<'a> Shown<'a> {
    fn file(&self, id: usize) -> Result<&ShownFile<'a>, Error> {
        self.0.get(id).ok_or(Error::FileMissing)
    }
}

impl<'a> Files<'a> for Shown<'a> {
    type FileId = usize;
    type Name = &'a str;
    type Source = &'a str;

    fn name(&'a self, id: usize) -> Result<&'a str, Error> {
        Ok(self.file(id)?.name)
    }

    fn source(&'a self, id: usize) -> Result<&'a str, Error> {
        Ok(self.file(id)?.shown.text())
    }

    fn line_index(&'a self, id: usize, byte_index: usize) -> Result<usize, Error> {
        let starts = self.file(id)?.shown.line_starts();
        Ok(starts
            .partition_point(|&s| s <= byte_index)
            .saturating_sub(1))
    }

    fn line_range(&'a self, id: usize, line_index: usize) -> Result<Range<usize>, Error> {
        let shown = &self.file(id)?.shown;
        let starts = shown.line_starts();
        let start = *starts.get(line_index).ok_or(Error::LineTooLarge {
            given: line_index,
            max: starts.len().saturating_sub(1),
        })?;
        let end = starts
            .get(line_index + 1)
            .copied()
            .unwrap_or(shown.text().len());
        Ok(start..end)
    }

    /// The original file's column (its [`LineIndex`]), however the line was clipped.
    fn column_number(&'a self, id: usize, _line: usize, byte_index: usize) -> Result<usize, Error> {
        let f = self.file(id)?;
        Ok(f.original.line_col(f.to_original(byte_index)).1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_line_is_shown_around_its_label_with_the_original_column() {
        let text = format!("a\n{}X{}\nb\n", "y".repeat(5000), "z".repeat(5000));
        let at = text.find('X').unwrap();
        let index = LineIndex::new(&text);
        assert!(has_long_line(&index));
        let label = at..at + 1;
        let file = ShownFile::clipped("f", &index, std::slice::from_ref(&label));
        let shown = file.shown.text().to_string();
        assert!(
            shown.len() < 2 * MAX_SHOWN_LINE + 20,
            "{} bytes shown",
            shown.len()
        );
        assert!(shown.contains('X') && shown.contains(CUT));
        let files = Shown(vec![file]);
        let b = files.0[0].to_shown(at);
        assert_eq!(&shown[b..b + 1], "X");
        let line = files.line_index(0, b).unwrap();
        assert_eq!(line, 1);
        assert_eq!(files.column_number(0, line, b).unwrap(), 5001);
        assert_eq!(files.line_number(0, line).unwrap(), 2);
    }

    #[test]
    fn short_lines_are_shown_as_they_are() {
        let text = "one\ntwo é\nthree";
        let index = LineIndex::new(text);
        assert!(!has_long_line(&index));
        let file = ShownFile::clipped("f", &index, &[]);
        assert_eq!(file.shown.text(), text);
        assert_eq!(file.to_shown(8), 8);
    }
}
