//! The analysis layer's answers (byte spans, its own kinds) as protocol types. Every position
//! goes through the text's [`LineIndex`] (UTF-16 columns), nowhere else.
//!
//! Self-contained (only `clay_dsl` and `lsp_types`), so `benches/lsp.rs` measures the same
//! conversion the server runs.

use std::collections::HashMap;
use std::str::FromStr;

use clay_dsl::analysis::{
    CompletionKind, LineIndex, LinePos, Outline, SemanticToken, SymbolKind, TokenKind,
};
use clay_dsl::syntax::Span;
use clay_dsl::{Diagnostic, Severity, SourceMap};
use lsp_types as lsp;

/// The file-system path of a document, for the compiler (its folder is where `import`s are
/// read from): a `file://` URI percent-decoded, anything else as it is.
pub fn file_path(uri: &str) -> String {
    match uri.strip_prefix("file://") {
        Some(rest) => percent_encoding::percent_decode_str(rest)
            .decode_utf8_lossy()
            .into_owned(),
        None => uri.to_string(),
    }
}

pub fn position(index: &LineIndex, offset: usize) -> lsp::Position {
    let p = index.position(offset);
    lsp::Position::new(p.line, p.col)
}

pub fn offset(index: &LineIndex, pos: lsp::Position) -> usize {
    index.offset(LinePos {
        line: pos.line,
        col: pos.character,
    })
}

pub fn range(index: &LineIndex, span: Span) -> lsp::Range {
    lsp::Range::new(position(index, span.start), position(index, span.end))
}

/// The byte span of a range (its ends in order).
pub fn span(index: &LineIndex, range: lsp::Range) -> Span {
    let (a, b) = (offset(index, range.start), offset(index, range.end));
    Span::new(a.min(b), a.max(b))
}

/// Characters escaped when a file path becomes a `file://` URI.
const PATH_ESCAPES: &percent_encoding::AsciiSet = &percent_encoding::CONTROLS
    .add(b' ')
    .add(b'"')
    .add(b'#')
    .add(b'%')
    .add(b'<')
    .add(b'>')
    .add(b'?')
    .add(b'`')
    .add(b'{')
    .add(b'}');

/// Where a span of the compiled text lies: in the open document, or in a file it imports (the
/// diagnostics' source map gives that file's path and text).
fn location(uri: &lsp::Uri, index: &LineIndex, sources: &SourceMap, span: Span) -> lsp::Location {
    let at = sources.locate(index.text(), "", span);
    if at.file == 0 {
        return lsp::Location::new(uri.clone(), range(index, span));
    }
    let file_index = LineIndex::new(at.text);
    let local = range(&file_index, Span::new(at.start, at.end));
    let file_uri = file_uri(at.path).unwrap_or_else(|| uri.clone());
    lsp::Location::new(file_uri, local)
}

/// The `file://` URI of a path (its unsafe characters escaped); `None` when that is no URI.
pub fn file_uri(path: &str) -> Option<lsp::Uri> {
    let path = percent_encoding::utf8_percent_encode(path, PATH_ESCAPES).to_string();
    lsp::Uri::from_str(&format!("file://{path}")).ok()
}

/// The `import` line of the document that brought in `path` (or the first import): where a
/// diagnostic inside an imported file is shown in the document.
fn import_range(index: &LineIndex, path: &str) -> lsp::Range {
    let text = index.text();
    let mut first = None;
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let trimmed = line.trim_start();
        if let Some(rest) = trimmed.strip_prefix("import") {
            let start = offset + (line.len() - trimmed.len());
            let span = Span::new(start, start + trimmed.trim_end().len());
            let named = rest.trim().trim_matches('"');
            if !named.is_empty() && path.ends_with(named.trim_start_matches("./")) {
                return range(index, span);
            }
            first.get_or_insert(span);
        }
        offset += line.len();
    }
    range(index, first.unwrap_or_default())
}

/// One compiler diagnostic: the message with its hints (`help: ...`) appended, the code with
/// its link, the secondary spans as related information. A diagnostic inside an imported file
/// is shown on the document's `import` line, its message naming where it is, with that place
/// as related information.
pub fn diagnostic(
    uri: &lsp::Uri,
    index: &LineIndex,
    sources: &SourceMap,
    d: &Diagnostic,
) -> lsp::Diagnostic {
    let mut message = d.message.clone();
    for hint in &d.hints {
        message.push_str("\nhelp: ");
        message.push_str(hint);
    }
    let mut related: Vec<lsp::DiagnosticRelatedInformation> = d
        .secondary
        .iter()
        .map(|l| lsp::DiagnosticRelatedInformation {
            location: location(uri, index, sources, l.span),
            message: l.message.clone(),
        })
        .collect();
    let primary = sources.locate(index.text(), "", d.primary.span);
    let shown = if primary.file == 0 {
        range(index, d.primary.span)
    } else {
        let (line, col) = clay_dsl::line_col(primary.text, primary.start);
        message = format!("in {}:{line}:{col}: {message}", primary.path);
        related.insert(
            0,
            lsp::DiagnosticRelatedInformation {
                location: location(uri, index, sources, d.primary.span),
                message: d.primary.message.clone(),
            },
        );
        import_range(index, primary.path)
    };
    // Unused declarations: editors grey them out.
    let unnecessary = matches!(d.code, "W001" | "W007");
    lsp::Diagnostic {
        range: shown,
        severity: Some(match d.severity {
            Severity::Error => lsp::DiagnosticSeverity::ERROR,
            Severity::Warning => lsp::DiagnosticSeverity::WARNING,
        }),
        code: Some(lsp::NumberOrString::String(d.code.to_string())),
        // No link: Clay has no public address its docs could be linked at (issue 40).
        code_description: None,
        source: Some("clay".into()),
        message,
        related_information: (!related.is_empty()).then_some(related),
        tags: unnecessary.then(|| vec![lsp::DiagnosticTag::UNNECESSARY]),
        data: None,
    }
}

pub fn diagnostics(
    uri: &lsp::Uri,
    index: &LineIndex,
    ds: &clay_dsl::Diagnostics,
) -> Vec<lsp::Diagnostic> {
    ds.iter()
        .map(|d| diagnostic(uri, index, &ds.sources, d))
        .collect()
}

pub fn completion_kind(k: CompletionKind) -> lsp::CompletionItemKind {
    use lsp::CompletionItemKind as K;
    match k {
        CompletionKind::Keyword => K::KEYWORD,
        CompletionKind::Piece => K::CLASS,
        CompletionKind::SiteType => K::INTERFACE,
        CompletionKind::Vertex => K::FIELD,
        CompletionKind::Site => K::PROPERTY,
        CompletionKind::State => K::ENUM_MEMBER,
        CompletionKind::Constant => K::CONSTANT,
        CompletionKind::Function => K::FUNCTION,
        CompletionKind::Instance => K::VARIABLE,
        CompletionKind::Parameter => K::PROPERTY,
    }
}

pub fn symbol_kind(k: Option<SymbolKind>) -> lsp::SymbolKind {
    use lsp::SymbolKind as K;
    match k {
        None => K::MODULE,
        Some(SymbolKind::Constant) => K::CONSTANT,
        Some(SymbolKind::SiteType) => K::INTERFACE,
        Some(SymbolKind::Piece) => K::CLASS,
        Some(SymbolKind::Vertex) => K::FIELD,
        Some(SymbolKind::Site) => K::PROPERTY,
        Some(SymbolKind::State) => K::ENUM_MEMBER,
        Some(SymbolKind::Rule) => K::EVENT,
        Some(SymbolKind::Instance) => K::VARIABLE,
        Some(SymbolKind::Chain) => K::ARRAY,
    }
}

/// The outline as nested document symbols.
pub fn document_symbols(index: &LineIndex, outline: &[Outline]) -> Vec<lsp::DocumentSymbol> {
    outline
        .iter()
        .map(|o| {
            let range = range(index, o.span);
            let mut selection = self::range(index, o.selection);
            // The protocol wants the selection inside the range.
            if selection.start < range.start || selection.end > range.end {
                selection = range;
            }
            #[allow(deprecated)] // `deprecated` is a field every literal must name.
            lsp::DocumentSymbol {
                name: o.name.clone(),
                detail: Some(o.kind.map_or("model", SymbolKind::word).to_string()),
                kind: symbol_kind(o.kind),
                tags: None,
                deprecated: None,
                range,
                selection_range: selection,
                children: (!o.children.is_empty()).then(|| document_symbols(index, &o.children)),
            }
        })
        .collect()
}

/// The token types of the legend, in the order [`token_type`] indexes them.
const TOKEN_TYPES: &[lsp::SemanticTokenType] = &[
    lsp::SemanticTokenType::KEYWORD,
    lsp::SemanticTokenType::COMMENT,
    lsp::SemanticTokenType::NUMBER,
    lsp::SemanticTokenType::STRING,
    lsp::SemanticTokenType::OPERATOR,
    lsp::SemanticTokenType::FUNCTION,
    lsp::SemanticTokenType::PARAMETER,
    lsp::SemanticTokenType::VARIABLE,
    lsp::SemanticTokenType::TYPE,
    lsp::SemanticTokenType::CLASS,
    lsp::SemanticTokenType::PROPERTY,
    lsp::SemanticTokenType::INTERFACE,
    lsp::SemanticTokenType::ENUM_MEMBER,
];

/// Bit 0: the name in its declaration; bit 1: a constant.
const TOKEN_MODIFIERS: &[lsp::SemanticTokenModifier] = &[
    lsp::SemanticTokenModifier::DECLARATION,
    lsp::SemanticTokenModifier::READONLY,
];

pub fn legend() -> lsp::SemanticTokensLegend {
    lsp::SemanticTokensLegend {
        token_types: TOKEN_TYPES.to_vec(),
        token_modifiers: TOKEN_MODIFIERS.to_vec(),
    }
}

/// The legend index of a token kind: keywords, comments, numbers, colours (`string`),
/// operators, functions, solver parameters (`parameter`), constants, instances and chains
/// (`variable`), site types (`type`), pieces (`class`), vertices (`property`), sites
/// (`interface`), rest states (`enumMember`).
pub fn token_type(k: TokenKind) -> u32 {
    match k {
        TokenKind::Keyword => 0,
        TokenKind::Comment => 1,
        TokenKind::Number => 2,
        TokenKind::Colour => 3,
        TokenKind::Operator => 4,
        TokenKind::Function => 5,
        TokenKind::Parameter => 6,
        TokenKind::Symbol(s) => match s {
            SymbolKind::Constant | SymbolKind::Instance | SymbolKind::Chain => 7,
            SymbolKind::SiteType => 8,
            SymbolKind::Piece => 9,
            SymbolKind::Vertex => 10,
            SymbolKind::Site => 11,
            SymbolKind::State => 12,
            // A rule has no name of its own to colour; its words are keywords.
            SymbolKind::Rule => 0,
        },
    }
}

/// The tokens in the protocol's relative encoding (each against the one before it).
pub fn semantic_tokens(index: &LineIndex, tokens: &[SemanticToken]) -> Vec<lsp::SemanticToken> {
    let mut out = Vec::with_capacity(tokens.len());
    let mut prev = LinePos { line: 0, col: 0 };
    for t in tokens {
        let (start, end) = (index.position(t.span.start), index.position(t.span.end));
        // Tokens never span a line; one that does (or is empty, or out of order) is skipped
        // rather than sent broken.
        if start.line != end.line || end.col <= start.col || start < prev {
            continue;
        }
        let delta_line = start.line - prev.line;
        let mut modifiers = u32::from(t.declaration);
        if t.kind == TokenKind::Symbol(SymbolKind::Constant) {
            modifiers |= 2;
        }
        out.push(lsp::SemanticToken {
            delta_line,
            delta_start: if delta_line == 0 {
                start.col - prev.col
            } else {
                start.col
            },
            length: end.col - start.col,
            token_type: token_type(t.kind),
            token_modifiers_bitset: modifiers,
        });
        prev = start;
    }
    out
}

/// Folding ranges by line. A block keeps its closing `}` line visible.
pub fn folding_ranges(index: &LineIndex, spans: &[Span]) -> Vec<lsp::FoldingRange> {
    let text = index.text();
    spans
        .iter()
        .filter_map(|s| {
            let comment = text.get(s.start..).is_some_and(|t| t.starts_with("/*"));
            let start = index.position(s.start).line;
            let end = index.position(s.end).line;
            let end = if comment { end } else { end.saturating_sub(1) };
            (end > start).then_some(lsp::FoldingRange {
                start_line: start,
                start_character: None,
                end_line: end,
                end_character: None,
                kind: Some(if comment {
                    lsp::FoldingRangeKind::Comment
                } else {
                    lsp::FoldingRangeKind::Region
                }),
                collapsed_text: None,
            })
        })
        .collect()
}

/// Edits of one document as a workspace edit.
pub fn workspace_edit(
    uri: &lsp::Uri,
    index: &LineIndex,
    edits: &[(Span, String)],
) -> lsp::WorkspaceEdit {
    let edits = edits
        .iter()
        .map(|(s, text)| lsp::TextEdit::new(range(index, *s), text.clone()))
        .collect();
    lsp::WorkspaceEdit {
        changes: Some(HashMap::from([(uri.clone(), edits)])),
        ..Default::default()
    }
}

#[cfg(test)]
mod path_tests {
    #[test]
    fn a_file_uri_becomes_a_path_with_its_escapes_decoded() {
        assert_eq!(
            super::file_path("file:///work/my%20grammars/wall.clay"),
            "/work/my grammars/wall.clay"
        );
        assert_eq!(
            super::file_path("file:///tmp/caf%C3%A9.clay"),
            "/tmp/café.clay"
        );
        assert_eq!(
            super::file_path("untitled:Untitled-1"),
            "untitled:Untitled-1"
        );
    }
}
