//! The requests: each reads its params (InvalidParams when they do not fit), asks the document's
//! analysis, and converts the answer.

use std::collections::{HashMap, HashSet};

use clay_dsl::analysis::follow::Focus;
use clay_dsl::analysis::{Analysis, CompletionKind};
use clay_dsl::syntax::Span;
use lsp_server::{ErrorCode, ResponseError};
use lsp_types as lsp;
use lsp_types::request::{self as req, Request as _};
use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::Value;

use super::convert;
use super::document::Document;
use super::params;

type Docs = HashMap<String, Document>;
type Answer = Result<Value, ResponseError>;

pub fn error(code: ErrorCode, message: impl Into<String>) -> ResponseError {
    ResponseError {
        code: code as i32,
        message: message.into(),
        data: None,
    }
}

pub fn params<P: DeserializeOwned>(params: Value) -> Result<P, ResponseError> {
    serde_json::from_value(params).map_err(|e| error(ErrorCode::InvalidParams, e.to_string()))
}

pub fn to_value(v: impl Serialize) -> Answer {
    serde_json::to_value(v).map_err(|e| error(ErrorCode::InternalError, e.to_string()))
}

pub fn not_open(uri: &lsp::Uri) -> ResponseError {
    error(
        ErrorCode::InvalidParams,
        format!("`{}` is not open", uri.as_str()),
    )
}

pub fn initialize_result() -> lsp::InitializeResult {
    use lsp::*;
    InitializeResult {
        capabilities: ServerCapabilities {
            position_encoding: Some(PositionEncodingKind::UTF16),
            text_document_sync: Some(TextDocumentSyncCapability::Options(
                TextDocumentSyncOptions {
                    open_close: Some(true),
                    change: Some(TextDocumentSyncKind::FULL),
                    ..Default::default()
                },
            )),
            hover_provider: Some(HoverProviderCapability::Simple(true)),
            definition_provider: Some(OneOf::Left(true)),
            references_provider: Some(OneOf::Left(true)),
            document_highlight_provider: Some(OneOf::Left(true)),
            completion_provider: Some(CompletionOptions {
                trigger_characters: Some(vec![".".into(), ":".into(), "[".into()]),
                ..Default::default()
            }),
            document_formatting_provider: Some(OneOf::Left(true)),
            document_range_formatting_provider: Some(OneOf::Left(true)),
            rename_provider: Some(OneOf::Right(RenameOptions {
                prepare_provider: Some(true),
                work_done_progress_options: Default::default(),
            })),
            document_symbol_provider: Some(OneOf::Left(true)),
            semantic_tokens_provider: Some(
                SemanticTokensServerCapabilities::SemanticTokensOptions(SemanticTokensOptions {
                    legend: convert::legend(),
                    full: Some(SemanticTokensFullOptions::Bool(true)),
                    range: None,
                    work_done_progress_options: Default::default(),
                }),
            ),
            folding_range_provider: Some(FoldingRangeProviderCapability::Simple(true)),
            code_action_provider: Some(CodeActionProviderCapability::Options(CodeActionOptions {
                code_action_kinds: Some(vec![CodeActionKind::QUICKFIX]),
                ..Default::default()
            })),
            ..Default::default()
        },
        server_info: Some(ServerInfo {
            name: "clayc lsp".into(),
            version: Some(env!("CARGO_PKG_VERSION").into()),
        }),
    }
}

/// Answers one request (not `initialize` or `shutdown`, which the server loop answers).
pub fn handle(docs: &Docs, method: &str, p: Value) -> Answer {
    let docs = Open(docs);
    match method {
        req::HoverRequest::METHOD => on::<req::HoverRequest>(p, |p| docs.hover(p)),
        req::GotoDefinition::METHOD => on::<req::GotoDefinition>(p, |p| docs.definition(p)),
        req::References::METHOD => on::<req::References>(p, |p| docs.references(p)),
        req::DocumentHighlightRequest::METHOD => {
            on::<req::DocumentHighlightRequest>(p, |p| docs.highlight(p))
        }
        req::Completion::METHOD => on::<req::Completion>(p, |p| docs.completion(p)),
        req::Formatting::METHOD => on::<req::Formatting>(p, |p| docs.formatting(p)),
        req::RangeFormatting::METHOD => on::<req::RangeFormatting>(p, |p| docs.range_formatting(p)),
        req::PrepareRenameRequest::METHOD => {
            on::<req::PrepareRenameRequest>(p, |p| docs.prepare_rename(p))
        }
        req::Rename::METHOD => on::<req::Rename>(p, |p| docs.rename(p)),
        req::DocumentSymbolRequest::METHOD => {
            on::<req::DocumentSymbolRequest>(p, |p| docs.symbols(p))
        }
        req::SemanticTokensFullRequest::METHOD => {
            on::<req::SemanticTokensFullRequest>(p, |p| docs.tokens(p))
        }
        req::FoldingRangeRequest::METHOD => on::<req::FoldingRangeRequest>(p, |p| docs.folding(p)),
        req::CodeActionRequest::METHOD => on::<req::CodeActionRequest>(p, |p| docs.actions(p)),
        _ => Err(error(
            ErrorCode::MethodNotFound,
            format!("`{method}` is not supported"),
        )),
    }
}

/// Where the declaration a following Clay editor names lies: in the open documents of its
/// file (or any open document that knows it), else in the file read from the disk.
pub fn declaration(docs: &Docs, focus: &Focus) -> Option<lsp::Location> {
    let open = Open(docs);
    let mut all = open.analyses();
    all.sort_by_key(|(_, a)| !super::follow::same_file(a.path(0), &focus.file));
    for (uri, a) in all {
        if let Some(span) = a.declaration_of(focus) {
            return open.location(uri, a, span);
        }
    }
    let text = clay_dsl::read_input_string(
        std::path::Path::new(&focus.file),
        clay_dsl::MAX_SOURCE_BYTES,
    )
    .ok()?;
    let a = Analysis::new(&text, &focus.file);
    let span = a.declaration_of(focus)?;
    open.location(&convert::file_uri(&focus.file)?, &a, span)
}

/// Reads the params of request `R`, runs `f`, writes its result.
fn on<R: req::Request>(
    p: Value,
    f: impl FnOnce(R::Params) -> Result<R::Result, ResponseError>,
) -> Answer {
    to_value(f(params(p)?)?)
}

/// The open documents, as the handlers see them.
struct Open<'a>(&'a Docs);

/// A document's analysis and the byte offset of a position in it.
struct At<'a> {
    a: &'a Analysis,
    offset: usize,
}

impl Open<'_> {
    fn analysis(&self, uri: &lsp::Uri) -> Result<&Analysis, ResponseError> {
        let doc = self.0.get(uri.as_str()).ok_or_else(|| not_open(uri))?;
        doc.analysis.as_deref().ok_or_else(|| {
            error(
                ErrorCode::RequestFailed,
                format!("`{}` could not be analysed", uri.as_str()),
            )
        })
    }

    /// The text of the document's last analysis that parsed, if it has one.
    fn last_parsed_text(&self, uri: &lsp::Uri) -> Option<&str> {
        let doc = self.0.get(uri.as_str())?;
        doc.last_parsed.as_deref().map(Analysis::text)
    }

    fn at(&self, p: &lsp::TextDocumentPositionParams) -> Result<At<'_>, ResponseError> {
        let a = self.analysis(&p.text_document.uri)?;
        let offset = convert::offset(a.line_index(), p.position);
        Ok(At { a, offset })
    }

    /// The open documents' analyses, in order of their URIs.
    fn analyses(&self) -> Vec<(&lsp::Uri, &Analysis)> {
        let mut all: Vec<_> = self
            .0
            .values()
            .filter_map(|d| Some((&d.uri, d.analysis.as_deref()?)))
            .collect();
        all.sort_by(|a, b| a.0.as_str().cmp(b.0.as_str()));
        all
    }

    /// The URI of a file named by an analysis: the open document of that path, else the file.
    fn uri_of(&self, path: &str) -> Option<lsp::Uri> {
        self.analyses()
            .into_iter()
            .find(|(_, a)| a.path(0) == path)
            .map(|(uri, _)| uri.clone())
            .or_else(|| convert::file_uri(path))
    }

    /// Where a span of `a` (the analysis of the document `uri`) lies: in the document or in a
    /// file it imports.
    fn location(&self, uri: &lsp::Uri, a: &Analysis, span: Span) -> Option<lsp::Location> {
        let place = a.place(span);
        let range = convert::range(a.file_index(place.file)?, place.span);
        let uri = match place.file {
            0 => uri.clone(),
            k => self.uri_of(a.path(k))?,
        };
        Some(lsp::Location::new(uri, range))
    }

    /// The symbol at a position as every open document's analysis knows it (the documents
    /// that declare it, import its file, or are imported by the one asked): each analysis with
    /// its index of the symbol, the asked document's first (its refusals name other files).
    fn everywhere(
        &self,
        p: &lsp::TextDocumentPositionParams,
    ) -> Result<Vec<(&lsp::Uri, &Analysis, usize)>, ResponseError> {
        let At { a, offset } = self.at(p)?;
        let Some(sym) = a.symbol_at(offset).map(|i| &a.symbols().symbols[i]) else {
            return Ok(Vec::new());
        };
        let declared = a.place(sym.span);
        let path = a.path(declared.file);
        let asked = &p.text_document.uri;
        let mut all: Vec<_> = self
            .analyses()
            .into_iter()
            .filter_map(|(uri, b)| Some((uri, b, b.declared_at(path, declared.span)?)))
            .collect();
        all.sort_by_key(|(uri, _, _)| *uri != asked);
        Ok(all)
    }

    fn hover(&self, p: lsp::HoverParams) -> Result<Option<lsp::Hover>, ResponseError> {
        let uri = &p.text_document_position_params.text_document.uri;
        let At { a, offset } = self.at(&p.text_document_position_params)?;
        // A parameter's hover adds its value, default and range.
        let param = a.symbol_at(offset).and_then(|i| {
            let (text, name) = params::symbol_param(a, i)?;
            let fallback = self.last_parsed_text(uri).filter(|_| text == a.text());
            let declared = params::declared(text).or_else(|| fallback.and_then(params::declared));
            declared?.into_iter().find(|p| p.name == name)
        });
        Ok(a.hover(offset)
            .map(|(span, mut markdown)| {
                if let Some(p) = &param {
                    markdown += &params::hover(p);
                }
                (span, markdown)
            })
            .map(|(span, markdown)| lsp::Hover {
                contents: lsp::HoverContents::Markup(lsp::MarkupContent {
                    kind: lsp::MarkupKind::Markdown,
                    value: markdown,
                }),
                range: Some(convert::range(a.line_index(), span)),
            }))
    }

    fn definition(
        &self,
        p: lsp::GotoDefinitionParams,
    ) -> Result<Option<lsp::GotoDefinitionResponse>, ResponseError> {
        let pos = &p.text_document_position_params;
        let At { a, offset } = self.at(pos)?;
        Ok(a.definition(offset)
            .and_then(|span| self.location(&pos.text_document.uri, a, span))
            .map(lsp::GotoDefinitionResponse::Scalar))
    }

    fn references(
        &self,
        p: lsp::ReferenceParams,
    ) -> Result<Option<Vec<lsp::Location>>, ResponseError> {
        // Every open document's uses (and those in the files they import), once each.
        let mut seen = HashSet::new();
        let mut out = Vec::new();
        for (uri, b, i) in self.everywhere(&p.text_document_position)? {
            for s in b.references_of(i, p.context.include_declaration) {
                let Some(l) = self.location(uri, b, s) else {
                    continue;
                };
                if seen.insert((l.uri.as_str().to_string(), format!("{:?}", l.range))) {
                    out.push(l);
                }
            }
        }
        Ok(Some(out))
    }

    fn highlight(
        &self,
        p: lsp::DocumentHighlightParams,
    ) -> Result<Option<Vec<lsp::DocumentHighlight>>, ResponseError> {
        let At { a, offset } = self.at(&p.text_document_position_params)?;
        let declaration = a.definition(offset);
        Ok(Some(
            a.references(offset, true)
                .into_iter()
                .filter(|&s| a.place(s).file == 0)
                .map(|s| lsp::DocumentHighlight {
                    range: convert::range(a.line_index(), s),
                    kind: Some(if Some(s) == declaration {
                        lsp::DocumentHighlightKind::WRITE
                    } else {
                        lsp::DocumentHighlightKind::READ
                    }),
                })
                .collect(),
        ))
    }

    fn completion(
        &self,
        p: lsp::CompletionParams,
    ) -> Result<Option<lsp::CompletionResponse>, ResponseError> {
        let At { a, offset } = self.at(&p.text_document_position)?;
        let completions = a.completions(offset);
        // The parameters among the constants offered: their detail gives value and range.
        let visible = if completions
            .iter()
            .any(|c| c.kind == CompletionKind::Constant)
        {
            params::visible(
                a,
                self.last_parsed_text(&p.text_document_position.text_document.uri),
            )
        } else {
            Vec::new()
        };
        let items = completions
            .into_iter()
            .map(|c| lsp::CompletionItem {
                kind: Some(convert::completion_kind(c.kind)),
                detail: (visible.iter())
                    .find(|p| c.kind == CompletionKind::Constant && p.name == c.label)
                    .map(params::detail)
                    .or(c.detail),
                text_edit: Some(lsp::CompletionTextEdit::Edit(lsp::TextEdit::new(
                    convert::range(a.line_index(), c.replace),
                    c.label.clone(),
                ))),
                label: c.label,
                ..Default::default()
            })
            .collect();
        Ok(Some(lsp::CompletionResponse::Array(items)))
    }

    /// The whole document in the canonical style (`clayc fmt`); nothing while it does not parse.
    fn formatting(
        &self,
        p: lsp::DocumentFormattingParams,
    ) -> Result<Option<Vec<lsp::TextEdit>>, ResponseError> {
        let a = self.analysis(&p.text_document.uri)?;
        let Some(formatted) = a.format() else {
            return Ok(None);
        };
        if formatted == a.text() {
            return Ok(Some(Vec::new()));
        }
        let whole = clay_dsl::syntax::Span::new(0, a.text().len());
        Ok(Some(vec![lsp::TextEdit::new(
            convert::range(a.line_index(), whole),
            formatted,
        )]))
    }

    /// The top-level declarations the range touches, each in the canonical style; nothing
    /// while the text does not parse.
    fn range_formatting(
        &self,
        p: lsp::DocumentRangeFormattingParams,
    ) -> Result<Option<Vec<lsp::TextEdit>>, ResponseError> {
        let a = self.analysis(&p.text_document.uri)?;
        let index = a.line_index();
        Ok(a.format_range(convert::span(index, p.range)).map(|edits| {
            edits
                .into_iter()
                .map(|(s, text)| lsp::TextEdit::new(convert::range(index, s), text))
                .collect()
        }))
    }

    fn prepare_rename(
        &self,
        p: lsp::TextDocumentPositionParams,
    ) -> Result<Option<lsp::PrepareRenameResponse>, ResponseError> {
        let At { a, offset } = self.at(&p)?;
        let here = a
            .references(offset, true)
            .into_iter()
            .find(|s| s.start <= offset && offset <= s.end);
        Ok(here.map(|s| lsp::PrepareRenameResponse::Range(convert::range(a.line_index(), s))))
    }

    fn rename(&self, p: lsp::RenameParams) -> Result<Option<lsp::WorkspaceEdit>, ResponseError> {
        // Every file that declares or uses the name and that an open document knows: the open
        // documents and the files they import. A name any of them refuses is not renamed.
        let mut seen = HashSet::new();
        // By URI text (a `Uri` is no key: it caches its parts inside).
        let mut changes: HashMap<String, (lsp::Uri, Vec<lsp::TextEdit>)> = HashMap::new();
        let everywhere = self.everywhere(&p.text_document_position)?;
        if everywhere.is_empty() {
            return Err(error(
                ErrorCode::RequestFailed,
                "there is no name to rename here",
            ));
        }
        for (uri, b, i) in everywhere {
            let edits = b
                .rename_symbol(i, &p.new_name)
                .map_err(|why| error(ErrorCode::RequestFailed, why))?;
            for (s, text) in edits {
                let Some(l) = self.location(uri, b, s) else {
                    continue;
                };
                if seen.insert((l.uri.as_str().to_string(), format!("{:?}", l.range))) {
                    changes
                        .entry(l.uri.as_str().to_string())
                        .or_insert_with(|| (l.uri.clone(), Vec::new()))
                        .1
                        .push(lsp::TextEdit::new(l.range, text));
                }
            }
        }
        Ok(Some(lsp::WorkspaceEdit {
            changes: Some(changes.into_values().collect()),
            ..Default::default()
        }))
    }

    fn symbols(
        &self,
        p: lsp::DocumentSymbolParams,
    ) -> Result<Option<lsp::DocumentSymbolResponse>, ResponseError> {
        let a = self.analysis(&p.text_document.uri)?;
        Ok(Some(lsp::DocumentSymbolResponse::Nested(
            convert::document_symbols(a.line_index(), &a.outline()),
        )))
    }

    fn tokens(
        &self,
        p: lsp::SemanticTokensParams,
    ) -> Result<Option<lsp::SemanticTokensResult>, ResponseError> {
        let a = self.analysis(&p.text_document.uri)?;
        Ok(Some(lsp::SemanticTokensResult::Tokens(
            lsp::SemanticTokens {
                result_id: None,
                data: convert::semantic_tokens(a.line_index(), &a.semantic_tokens()),
            },
        )))
    }

    fn folding(
        &self,
        p: lsp::FoldingRangeParams,
    ) -> Result<Option<Vec<lsp::FoldingRange>>, ResponseError> {
        let a = self.analysis(&p.text_document.uri)?;
        Ok(Some(convert::folding_ranges(
            a.line_index(),
            &a.folding_ranges(),
        )))
    }

    /// Quick fixes for the request's diagnostics that are this text's (same code and range).
    fn actions(
        &self,
        p: lsp::CodeActionParams,
    ) -> Result<Option<lsp::CodeActionResponse>, ResponseError> {
        let uri = &p.text_document.uri;
        let a = self.analysis(uri)?;
        let index = a.line_index();
        let mut out = Vec::new();
        for asked in &p.context.diagnostics {
            let Some(lsp::NumberOrString::String(code)) = &asked.code else {
                continue;
            };
            let ours = a
                .diagnostics()
                .iter()
                .filter(|d| d.code == code && convert::range(index, d.primary.span) == asked.range);
            for d in ours {
                let fixes = a.fixes(d);
                let one = fixes.len() == 1;
                for fix in fixes {
                    out.push(lsp::CodeActionOrCommand::CodeAction(lsp::CodeAction {
                        title: fix.title,
                        kind: Some(lsp::CodeActionKind::QUICKFIX),
                        diagnostics: Some(vec![asked.clone()]),
                        edit: Some(convert::workspace_edit(uri, index, &fix.edits)),
                        is_preferred: Some(one),
                        ..Default::default()
                    }));
                }
            }
        }
        Ok(Some(out))
    }
}
