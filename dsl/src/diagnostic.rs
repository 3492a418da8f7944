//! Diagnostics: the one error/warning type of the compiler, its collection, and its two
//! renderings (rustc-style text through codespan-reporting, and JSON for tools).

use codespan_reporting::diagnostic as cs;
use codespan_reporting::term;
use codespan_reporting::term::termcolor::Buffer;
use serde::Serialize;

use crate::clip;
use crate::line_index::LineIndex;
use crate::source_map::{Located, SourceMap, line_col};
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

    /// The same diagnostic with every span moved `by` bytes later (a file parsed on its own,
    /// placed at its position in the source map).
    pub(crate) fn shifted(mut self, by: usize) -> Diagnostic {
        let shift = |s: &mut Span| *s = Span::new(s.start + by, s.end + by);
        shift(&mut self.primary.span);
        for l in &mut self.secondary {
            shift(&mut l.span);
        }
        self
    }

    /// Maps every span back to its file (clamped into it on char boundaries, so rendering
    /// never fails): the label spans become local offsets, paired with their file's index.
    fn located<'a>(
        &self,
        map: &'a SourceMap,
        source: &'a str,
        path: &'a str,
    ) -> (Located<'a>, Vec<Located<'a>>) {
        let at = |s: Span| map.locate(source, path, s);
        (
            at(self.primary.span),
            self.secondary.iter().map(|l| at(l.span)).collect(),
        )
    }

    fn to_codespan(&self, primary: &Located, secondary: &[Located]) -> cs::Diagnostic<usize> {
        let severity = match self.severity {
            Severity::Error => cs::Severity::Error,
            Severity::Warning => cs::Severity::Warning,
        };
        let mut labels = vec![
            cs::Label::primary(primary.file, primary.start..primary.end)
                .with_message(&self.primary.message),
        ];
        for (l, at) in self.secondary.iter().zip(secondary) {
            labels.push(cs::Label::secondary(at.file, at.start..at.end).with_message(&l.message));
        }
        cs::Diagnostic::new(severity)
            .with_code(self.code)
            .with_message(&self.message)
            .with_labels(labels)
            .with_notes(self.hints.iter().map(|h| format!("help: {h}")).collect())
    }
}

/// An ordered collection of diagnostics, with the imported files their spans may point into.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Diagnostics {
    pub items: Vec<Diagnostic>,
    /// The files the main file imported (empty without imports); the renderers show a label
    /// in an imported file against that file's text.
    pub sources: SourceMap,
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
        if self.sources.is_empty() {
            self.sources = other.sources;
        }
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
        Self {
            items: vec![d],
            sources: SourceMap::default(),
        }
    }
}

impl<'a> IntoIterator for &'a Diagnostics {
    type Item = &'a Diagnostic;
    type IntoIter = std::slice::Iter<'a, Diagnostic>;
    fn into_iter(self) -> Self::IntoIter {
        self.items.iter()
    }
}

fn term_config() -> term::Config {
    term::Config::default()
}

/// Most diagnostics a human rendering shows ([`render`]); one closing line
/// counts the rest ([`omitted_line`]). A file with thousands of mistakes has one cause more
/// often than thousands, and each diagnostic prints its source line. The JSON form keeps all.
pub const MAX_HUMAN_DIAGNOSTICS: usize = 50;

/// Renders diagnostics rustc-style (`error[E011]: ...`, `--> file:line:col`, source line,
/// labels, help notes): the first [`MAX_HUMAN_DIAGNOSTICS`], then [`omitted_line`] if there
/// are more. `color` adds ANSI colours; the caller decides (terminal, NO_COLOR).
pub fn render(diagnostics: &Diagnostics, source: &str, path: &str, color: bool) -> String {
    let mut buffer = if color {
        Buffer::ansi()
    } else {
        Buffer::no_color()
    };
    render_into(&mut buffer, diagnostics, source, path);
    String::from_utf8_lossy(buffer.as_slice()).into_owned()
}

/// The line that ends a human rendering of more than [`MAX_HUMAN_DIAGNOSTICS`] diagnostics
/// (`... and 2950 more errors (use `clayc check --format json` for all)`), or `None` when all
/// are shown.
pub fn omitted_line(diagnostics: &Diagnostics) -> Option<String> {
    let rest = diagnostics
        .items
        .get(MAX_HUMAN_DIAGNOSTICS..)
        .filter(|rest| !rest.is_empty())?;
    let errors = rest.iter().filter(|d| d.is_error()).count();
    let warnings = rest.len() - errors;
    let plural = |n: usize, w: &str| format!("{n} more {w}{}", if n == 1 { "" } else { "s" });
    let counts = match (errors, warnings) {
        (e, 0) => plural(e, "error"),
        (0, w) => plural(w, "warning"),
        (e, w) => format!("{} and {}", plural(e, "error"), plural(w, "warning")),
    };
    Some(format!(
        "... and {counts} (use `clayc check --format json` for all)\n"
    ))
}

/// The human rendering into a colour buffer: the files' line index is built once, and each
/// shown diagnostic costs the length of its own lines.
fn render_into(buffer: &mut Buffer, diagnostics: &Diagnostics, source: &str, path: &str) {
    let files = all_files(&diagnostics.sources, source, path);
    let indexes: Vec<LineIndex> = files.iter().map(|f| LineIndex::new(f.1)).collect();
    let long: Vec<bool> = indexes.iter().map(clip::has_long_line).collect();
    let config = term_config();
    for d in diagnostics.iter().take(MAX_HUMAN_DIAGNOSTICS) {
        let (primary, secondary) = d.located(&diagnostics.sources, source, path);
        let mut shown = d.to_codespan(&primary, &secondary);
        // long lines shown as a window round the labels (`clip.rs`), the spans moved there
        let clipped = clip::Shown(
            (files.iter().zip(&indexes).zip(&long).enumerate())
                .map(|(id, ((&(name, _), index), &long))| {
                    if !long {
                        return clip::ShownFile::whole(name, index);
                    }
                    let labels: Vec<std::ops::Range<usize>> = (shown.labels.iter())
                        .filter(|l| l.file_id == id)
                        .map(|l| l.range.clone())
                        .collect();
                    clip::ShownFile::clipped(name, index, &labels)
                })
                .collect(),
        );
        for l in &mut shown.labels {
            if let Some(f) = clipped.0.get(l.file_id) {
                l.range = f.to_shown(l.range.start)..f.to_shown(l.range.end);
            }
        }
        // Emitting into a memory buffer with clamped spans cannot fail; if it ever does, fall
        // back to a plain line so the diagnostic is not lost.
        if term::emit(buffer, &config, &clipped, &shown).is_err() {
            let (line, col) = line_col(primary.text, primary.start);
            buffer_push(
                buffer,
                &format!(
                    "{}[{}]: {}\n --> {}:{line}:{col}\n",
                    sev_word(d.severity),
                    d.code,
                    d.message,
                    primary.path
                ),
            );
        }
    }
    if let Some(line) = omitted_line(diagnostics) {
        buffer_push(buffer, &line);
    }
}

/// The main file (id 0) and the imported files (ids 1..), `(name, text)`, for codespan.
fn all_files<'a>(map: &'a SourceMap, source: &'a str, path: &'a str) -> Vec<(&'a str, &'a str)> {
    std::iter::once((path, source))
        .chain(map.files.iter().map(|f| (f.path.as_str(), &*f.text)))
        .collect()
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
    /// The file the label is in: the checked file, or a file it imports.
    pub file: String,
    pub start: JsonPos,
    pub end: JsonPos,
    /// Byte offsets into the label's file.
    pub byte_start: usize,
    pub byte_end: usize,
}

/// One diagnostic in the JSON form (`clayc check --format json`).
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct JsonDiagnostic {
    pub code: &'static str,
    pub severity: Severity,
    pub message: String,
    /// The file of the primary span: the checked file, or a file it imports.
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
    let main = LineIndex::new(source);
    let imported: Vec<LineIndex> = diagnostics
        .sources
        .files
        .iter()
        .map(|f| LineIndex::new(&f.text))
        .collect();
    let pos = |at: &Located, b: usize| {
        let index = match at.file {
            0 => &main,
            k => &imported[k - 1],
        };
        let (line, column) = index.line_col(b);
        JsonPos { line, column }
    };
    let label = |l: &Label, at: &Located, primary: bool| JsonLabel {
        message: l.message.clone(),
        primary,
        file: at.path.to_string(),
        start: pos(at, at.start),
        end: pos(at, at.end),
        byte_start: at.start,
        byte_end: at.end,
    };
    diagnostics
        .iter()
        .map(|d| {
            let (primary, secondary) = d.located(&diagnostics.sources, source, path);
            let start = pos(&primary, primary.start);
            let mut labels = vec![label(&d.primary, &primary, true)];
            labels.extend(
                d.secondary
                    .iter()
                    .zip(&secondary)
                    .map(|(l, at)| label(l, at, false)),
            );
            JsonDiagnostic {
                code: d.code,
                severity: d.severity,
                message: d.message.clone(),
                file: primary.path.to_string(),
                line: start.line,
                column: start.column,
                end: pos(&primary, primary.end),
                labels,
                hints: d.hints.clone(),
            }
        })
        .collect()
}
