//! Diagnostics: the one error/warning type of the compiler, its collection, and its two
//! renderings (rustc-style text through codespan-reporting, and JSON for tools).

use codespan_reporting::diagnostic as cs;
use codespan_reporting::files::SimpleFile;
use codespan_reporting::term;
use codespan_reporting::term::termcolor::{Buffer, ColorChoice, StandardStream};
use serde::Serialize;

use crate::syntax::Span;

/// How bad a diagnostic is: errors stop compilation, warnings travel with the result.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Severity {
    Error,
    Warning,
}

/// A span with a short message shown under it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Label {
    pub span: Span,
    pub message: String,
}

/// One error or warning about the source text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic {
    pub severity: Severity,
    /// Stable code (`E001`, `W001`, ...), listed in docs/language.md.
    pub code: &'static str,
    pub message: String,
    pub primary: Label,
    pub secondary: Vec<Label>,
    /// Notes shown after the source excerpt ("help: ...").
    pub hints: Vec<String>,
}

impl Diagnostic {
    pub fn error(
        code: &'static str,
        message: impl Into<String>,
        span: Span,
        label: impl Into<String>,
    ) -> Self {
        Self::new(Severity::Error, code, message, span, label)
    }

    pub fn warning(
        code: &'static str,
        message: impl Into<String>,
        span: Span,
        label: impl Into<String>,
    ) -> Self {
        Self::new(Severity::Warning, code, message, span, label)
    }

    fn new(
        severity: Severity,
        code: &'static str,
        message: impl Into<String>,
        span: Span,
        label: impl Into<String>,
    ) -> Self {
        Self {
            severity,
            code,
            message: message.into(),
            primary: Label {
                span,
                message: label.into(),
            },
            secondary: Vec::new(),
            hints: Vec::new(),
        }
    }

    /// Adds a secondary span with its label.
    pub fn with_secondary(mut self, span: Span, label: impl Into<String>) -> Self {
        self.secondary.push(Label {
            span,
            message: label.into(),
        });
        self
    }

    /// Adds a hint (rendered as a note after the excerpt).
    pub fn with_hint(mut self, hint: impl Into<String>) -> Self {
        self.hints.push(hint.into());
        self
    }

    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }

    /// Clamps every span into `0..=len` on char boundaries, so rendering never fails.
    fn clamped(&self, source: &str) -> Diagnostic {
        let fix = |s: Span| {
            let mut start = s.start.min(source.len());
            let mut end = s.end.min(source.len()).max(start);
            while !source.is_char_boundary(start) {
                start -= 1;
            }
            while !source.is_char_boundary(end) {
                end += 1;
            }
            Span { start, end }
        };
        let mut d = self.clone();
        d.primary.span = fix(d.primary.span);
        for l in &mut d.secondary {
            l.span = fix(l.span);
        }
        d
    }

    fn to_codespan(&self) -> cs::Diagnostic<()> {
        let severity = match self.severity {
            Severity::Error => cs::Severity::Error,
            Severity::Warning => cs::Severity::Warning,
        };
        let mut labels = vec![
            cs::Label::primary((), self.primary.span.start..self.primary.span.end)
                .with_message(&self.primary.message),
        ];
        for l in &self.secondary {
            labels
                .push(cs::Label::secondary((), l.span.start..l.span.end).with_message(&l.message));
        }
        cs::Diagnostic::new(severity)
            .with_code(self.code)
            .with_message(&self.message)
            .with_labels(labels)
            .with_notes(self.hints.iter().map(|h| format!("help: {h}")).collect())
    }
}

/// An ordered collection of diagnostics.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Diagnostics {
    pub items: Vec<Diagnostic>,
}

impl Diagnostics {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn push(&mut self, d: Diagnostic) {
        self.items.push(d);
    }

    pub fn extend(&mut self, other: Diagnostics) {
        self.items.extend(other.items);
    }

    pub fn has_errors(&self) -> bool {
        self.items.iter().any(Diagnostic::is_error)
    }

    pub fn error_count(&self) -> usize {
        self.items.iter().filter(|d| d.is_error()).count()
    }

    pub fn warning_count(&self) -> usize {
        self.items.len() - self.error_count()
    }

    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    pub fn len(&self) -> usize {
        self.items.len()
    }

    pub fn iter(&self) -> std::slice::Iter<'_, Diagnostic> {
        self.items.iter()
    }

    /// Sorts by position (errors and warnings interleaved as in the file), keeping the
    /// emission order for equal positions.
    pub fn sort(&mut self) {
        self.items.sort_by_key(|d| d.primary.span.start);
    }
}

impl From<Diagnostic> for Diagnostics {
    fn from(d: Diagnostic) -> Self {
        Self { items: vec![d] }
    }
}

impl<'a> IntoIterator for &'a Diagnostics {
    type Item = &'a Diagnostic;
    type IntoIter = std::slice::Iter<'a, Diagnostic>;
    fn into_iter(self) -> Self::IntoIter {
        self.items.iter()
    }
}

/// 1-based line and column (in chars) of byte offset `byte` of `source`; offsets past the end
/// or inside a UTF-8 sequence are clamped back to the nearest valid position. O(byte): for many
/// positions in one source, use a [`LineIndex`].
pub fn line_col(source: &str, byte: usize) -> (usize, usize) {
    let byte = clamp_to_char(source, byte);
    let before = &source[..byte];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let col = source[line_start..byte].chars().count() + 1;
    (line, col)
}

fn clamp_to_char(source: &str, byte: usize) -> usize {
    let mut byte = byte.min(source.len());
    while !source.is_char_boundary(byte) {
        byte -= 1;
    }
    byte
}

/// The line starts of a source, built once (O(length)), so that each [`LineIndex::line_col`]
/// costs a binary search and the length of its own line instead of a scan from the file's
/// start: thousands of diagnostics in one large file stay linear.
pub struct LineIndex<'a> {
    source: &'a str,
    /// Byte offset of the start of every line (the first is 0).
    starts: Vec<usize>,
}

impl<'a> LineIndex<'a> {
    pub fn new(source: &'a str) -> Self {
        let starts = std::iter::once(0)
            .chain(source.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        Self { source, starts }
    }

    /// The same as [`line_col`]`(source, byte)`.
    pub fn line_col(&self, byte: usize) -> (usize, usize) {
        let byte = clamp_to_char(self.source, byte);
        // Lines starting at or before `byte`; a line starts after each '\n' before `byte`.
        let line = self.starts.partition_point(|&s| s <= byte);
        let line_start = self.starts[line - 1];
        let col = self.source[line_start..byte].chars().count() + 1;
        (line, col)
    }
}

fn term_config() -> term::Config {
    term::Config::default()
}

/// Renders diagnostics rustc-style (`error[E011]: ...`, `--> file:line:col`, source line,
/// labels, help notes). `color` adds ANSI colours; the caller decides (terminal, NO_COLOR).
pub fn render(diagnostics: &Diagnostics, source: &str, path: &str, color: bool) -> String {
    let file = SimpleFile::new(path, source);
    let mut buffer = if color {
        Buffer::ansi()
    } else {
        Buffer::no_color()
    };
    let config = term_config();
    for d in diagnostics {
        let d = d.clamped(source);
        // Emitting into a memory buffer with clamped spans cannot fail; if it ever does, fall
        // back to a plain line so the diagnostic is not lost.
        if term::emit(&mut buffer, &config, &file, &d.to_codespan()).is_err() {
            let (line, col) = line_col(source, d.primary.span.start);
            buffer_push(
                &mut buffer,
                &format!(
                    "{}[{}]: {}\n --> {path}:{line}:{col}\n",
                    sev_word(d.severity),
                    d.code,
                    d.message
                ),
            );
        }
    }
    String::from_utf8_lossy(buffer.as_slice()).into_owned()
}

fn buffer_push(buffer: &mut Buffer, text: &str) {
    use std::io::Write;
    let _ = buffer.write_all(text.as_bytes());
}

fn sev_word(s: Severity) -> &'static str {
    match s {
        Severity::Error => "error",
        Severity::Warning => "warning",
    }
}

/// Writes diagnostics straight to stderr, coloured when `color` (the caller checks for a
/// terminal and NO_COLOR).
pub fn emit_to_stderr(diagnostics: &Diagnostics, source: &str, path: &str, color: bool) {
    let choice = if color {
        ColorChoice::Always
    } else {
        ColorChoice::Never
    };
    let mut stream = StandardStream::stderr(choice);
    let file = SimpleFile::new(path, source);
    let config = term_config();
    for d in diagnostics {
        let d = d.clamped(source);
        let _ = term::emit(&mut stream, &config, &file, &d.to_codespan());
    }
}

/// A position in the JSON form: 1-based line and column.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct JsonPos {
    pub line: usize,
    pub column: usize,
}

/// A label in the JSON form.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct JsonLabel {
    pub message: String,
    pub primary: bool,
    pub start: JsonPos,
    pub end: JsonPos,
    /// Byte offsets into the file.
    pub byte_start: usize,
    pub byte_end: usize,
}

/// One diagnostic in the JSON form (`clayc check --format json`).
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct JsonDiagnostic {
    pub code: &'static str,
    pub severity: Severity,
    pub message: String,
    pub file: String,
    /// Where the primary span starts.
    pub line: usize,
    pub column: usize,
    /// Where the primary span ends.
    pub end: JsonPos,
    pub labels: Vec<JsonLabel>,
    pub hints: Vec<String>,
}

/// The JSON form of diagnostics, one object per diagnostic.
pub fn to_json(diagnostics: &Diagnostics, source: &str, path: &str) -> Vec<JsonDiagnostic> {
    let lines = LineIndex::new(source);
    let pos = |b: usize| {
        let (line, column) = lines.line_col(b);
        JsonPos { line, column }
    };
    let label = |l: &Label, primary: bool| JsonLabel {
        message: l.message.clone(),
        primary,
        start: pos(l.span.start),
        end: pos(l.span.end),
        byte_start: l.span.start,
        byte_end: l.span.end,
    };
    diagnostics
        .iter()
        .map(|d| {
            let d = d.clamped(source);
            let start = pos(d.primary.span.start);
            let mut labels = vec![label(&d.primary, true)];
            labels.extend(d.secondary.iter().map(|l| label(l, false)));
            JsonDiagnostic {
                code: d.code,
                severity: d.severity,
                message: d.message.clone(),
                file: path.to_string(),
                line: start.line,
                column: start.column,
                end: pos(d.primary.span.end),
                labels,
                hints: d.hints.clone(),
            }
        })
        .collect()
}
