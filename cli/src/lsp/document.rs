//! An open document of the language server: its text and version, its analyses (the latest,
//! and the last whose text parsed), and the background analysis that outlasted its timeout.

use std::sync::Arc;
use std::time::Duration;

use clay_dsl::Loader;
use clay_dsl::analysis::Analysis;
use lsp_types as lsp;

use super::{convert, worker};

/// An open document.
pub struct Document {
    pub uri: lsp::Uri,
    pub text: String,
    pub version: i32,
    /// The analysis of `text` (of an earlier text while `dirty` or `late`).
    pub analysis: Option<Arc<Analysis>>,
    /// The last analysis whose text parsed: it answers for what lies after a syntax error.
    pub last_parsed: Option<Arc<Analysis>>,
    pub dirty: bool,
    /// An analysis that outlasted the timeout and runs on (of `text` unless `dirty`).
    pub(super) late: Option<worker::Job>,
}

impl Document {
    pub(super) fn new(uri: lsp::Uri, text: String, version: i32) -> Self {
        Self {
            uri,
            text,
            version,
            analysis: None,
            last_parsed: None,
            dirty: true,
            late: None,
        }
    }

    /// Starts analysing the present text, imports read through `loader`.
    pub(super) fn start(&mut self, loader: Arc<dyn Loader + Send + Sync>) -> worker::Job {
        self.dirty = false;
        worker::Job::start(worker::Work {
            text: self.text.clone(),
            path: convert::file_path(self.uri.as_str()),
            previous: self.last_parsed.clone(),
            loader,
        })
    }

    /// Takes the finished analysis of the present text; gives what to publish.
    pub(super) fn finished(&mut self, a: Box<Analysis>) -> Published {
        let a = Arc::new(*a);
        if a.parses() {
            self.last_parsed = Some(a.clone());
        }
        let diagnostics = convert::diagnostics(&self.uri, a.line_index(), a.diagnostics());
        self.analysis = Some(a);
        (self.uri.clone(), diagnostics, self.version)
    }

    /// What to publish when the analysis outlasts `timeout`: one warning at the start.
    pub(super) fn timed_out(&self, timeout: Duration) -> Published {
        let message = format!(
            "analysis timed out after {} ms: it goes on in the background and its diagnostics \
             replace this one when it ends; until then, answers are about the last text analysed",
            timeout.as_millis()
        );
        let warning = lsp::Diagnostic {
            severity: Some(lsp::DiagnosticSeverity::WARNING),
            source: Some("clay".into()),
            message,
            ..Default::default()
        };
        (self.uri.clone(), vec![warning], self.version)
    }
}

/// Diagnostics to publish: the document, its diagnostics and the version they are of.
pub(super) type Published = (lsp::Uri, Vec<lsp::Diagnostic>, i32);
