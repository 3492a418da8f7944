//! `clayc lsp`: a Language Server Protocol server over stdio for `.clay` files (docs/editors.md).
//!
//! The questions are answered by `clay_dsl::analysis`; this module only speaks the protocol:
//! `transport` frames JSON-RPC, `convert` turns byte spans into UTF-16 positions and the
//! analysis' kinds into the protocol's, `handlers` answers requests (`params` adds a grammar
//! parameter's value, default and range to its hover and completions). Protocol types live here
//! and nowhere else (docs/architecture.md).
//!
//! One thread answers everything in order. Documents are synced whole; a change only stores
//! the text, and the analysis (and its published diagnostics) waits until no change has come
//! for [`DEBOUNCE`] (at most [`MAX_DELAY`] after the first unchecked change) or until a
//! request needs it, so a burst of typing is checked once. Each analysis runs on a thread of
//! its own (`worker`), waited for at most the analysis timeout: a document that takes longer
//! gets a diagnostic saying so and the server answers on, taking the late analysis when it
//! ends. A panic in a handler or in the analysis becomes an error response (or a log line)
//! and the server goes on. The server stops at `exit` or when its input ends.

mod convert;
mod document;
mod follow;
mod handlers;
mod params;
mod transport;
mod worker;

use std::collections::HashMap;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::sync::mpsc::RecvTimeoutError;
use std::time::{Duration, Instant};

use clay_dsl::analysis::LineIndex;
use clay_dsl::{FsLoader, Loader};
use lsp_server::{ErrorCode, Message, Notification, Request, RequestId, Response, ResponseError};
use lsp_types as lsp;
use lsp_types::notification::Notification as _;

use document::{Document, Published};
use transport::{Input, Writer};

/// Quiet time after a change before the document is checked.
pub const DEBOUNCE: Duration = Duration::from_millis(100);
/// Longest wait for a check while changes keep coming.
pub const MAX_DELAY: Duration = Duration::from_millis(300);

#[derive(clap::Args)]
pub struct LspArgs {
    /// Talk over standard input and output (the only transport; accepted because editor
    /// clients pass it).
    #[arg(long)]
    pub stdio: bool,
    /// How long to wait for the analysis of a document, in milliseconds, before answering
    /// without it (it goes on in the background).
    #[arg(long, value_name = "MS", default_value_t = worker::DEFAULT_TIMEOUT_MS)]
    pub analysis_timeout_ms: u64,
}

/// Runs the server until `exit` (0 after `shutdown`, 1 without it) or until its input ends (0:
/// the client is gone and nothing failed here).
pub fn lsp(args: LspArgs) -> u8 {
    serve(
        std::io::BufReader::new(std::io::stdin()),
        std::io::stdout().lock(),
        Duration::from_millis(args.analysis_timeout_ms),
        clay_dsl::analysis::follow::channel(),
    )
}

/// The server reading `input` and writing `output` (what [`lsp()`] runs over stdio, and what
/// `tests/fuzz_lsp.rs` drives in process), waiting `timeout` for an analysis, following a Clay
/// editor through the folder `follow`. Gives the exit code.
pub fn serve<R: std::io::BufRead + Send + 'static, W: std::io::Write>(
    input: R,
    output: W,
    timeout: Duration,
    follow: std::path::PathBuf,
) -> u8 {
    let input = transport::spawn_reader(input);
    let mut server = Server::new(Writer::new(output), timeout, follow);
    loop {
        // Wake for the debounce's deadline, and every so often for the Clay editor's reveals.
        let wait = server
            .deadline
            .map_or(follow::POLL, |d| {
                d.saturating_duration_since(Instant::now())
            })
            .min(follow::POLL);
        let next = match input.recv_timeout(wait) {
            Ok(m) => Some(m),
            Err(RecvTimeoutError::Timeout) => {
                let done = server.poll_late().and_then(|()| {
                    let due = server.deadline.is_some_and(|d| d <= Instant::now());
                    if due { server.check_changed() } else { Ok(()) }
                });
                if let Err(e) = done.and_then(|()| server.reveal()) {
                    errln!("clayc lsp: cannot write to the client: {e}");
                    return 1;
                }
                continue;
            }
            Err(RecvTimeoutError::Disconnected) => None,
        };
        let Some(next) = next else {
            errln!("clayc lsp: the input ended without `exit`; stopping");
            return 0;
        };
        match server.handle(next) {
            Ok(Some(code)) => return code,
            Ok(None) => {}
            Err(e) => {
                errln!("clayc lsp: cannot write to the client: {e}");
                return 1;
            }
        }
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum State {
    Uninitialised,
    Running,
    ShutDown,
}

struct Server<W: std::io::Write> {
    out: Writer<W>,
    state: State,
    /// By uri (as text: `Uri` caches its parts inside, so it is no key).
    docs: HashMap<String, Document>,
    /// When the changed documents are to be checked.
    deadline: Option<Instant>,
    /// When the oldest unchecked change came.
    first_change: Option<Instant>,
    /// What the cursor is on, for a following Clay editor.
    cursor: follow::Cursor,
    reveals: follow::Reveals,
    /// Requests sent to the client (`window/showDocument`), for their ids.
    sent: u64,
    /// How long an analysis is waited for.
    timeout: Duration,
}

type Flow = std::io::Result<Option<u8>>;

impl<W: std::io::Write> Server<W> {
    fn new(out: Writer<W>, timeout: Duration, channel: std::path::PathBuf) -> Self {
        Self {
            out,
            state: State::Uninitialised,
            docs: HashMap::new(),
            deadline: None,
            first_change: None,
            cursor: follow::Cursor::new(channel.clone()),
            reveals: follow::Reveals::new(&channel),
            sent: 0,
            timeout,
        }
    }

    /// Publishes what the cursor is on when a request tells where it is (`documentHighlight`
    /// and `hover` come as it moves).
    fn follow_cursor(&mut self, method: &str, params: &serde_json::Value) {
        use lsp::request::{DocumentHighlightRequest, HoverRequest, Request as _};
        if method != DocumentHighlightRequest::METHOD && method != HoverRequest::METHOD {
            return;
        }
        let docs = &self.docs;
        let focus = catch_unwind(AssertUnwindSafe(|| {
            let p: lsp::TextDocumentPositionParams = serde_json::from_value(params.clone()).ok()?;
            let a = docs
                .get(p.text_document.uri.as_str())?
                .analysis
                .as_deref()?;
            a.focus(convert::offset(a.line_index(), p.position))
        }));
        self.cursor.publish(focus.ok().flatten());
    }

    /// Asks the client to show the declaration the Clay editor asked for, if one came.
    fn reveal(&mut self) -> std::io::Result<()> {
        let Some(focus) = self.reveals.poll() else {
            return Ok(());
        };
        let docs = &self.docs;
        let found = catch_unwind(AssertUnwindSafe(|| handlers::declaration(docs, &focus)));
        let Ok(Some(at)) = found else {
            errln!(
                "clayc lsp: no declaration of {} `{}` to show",
                focus.kind,
                focus.name
            );
            return Ok(());
        };
        self.sent += 1;
        let params = lsp::ShowDocumentParams {
            uri: at.uri,
            external: Some(false),
            take_focus: Some(true),
            selection: Some(at.range),
        };
        self.out.send(Request::new(
            RequestId::from(format!("clay-reveal-{}", self.sent)),
            "window/showDocument".to_string(),
            params,
        ))
    }

    fn handle(&mut self, input: Input) -> Flow {
        match input {
            Input::Malformed { id, code, message } => {
                errln!("clayc lsp: {message}");
                self.out.send_error(id, code, message)?;
                Ok(None)
            }
            Input::Message(Message::Request(r)) => {
                let flow = self.request(r);
                self.reveal()?;
                flow
            }
            Input::Message(Message::Notification(n)) => self.notification(n),
            // We send no requests, so no response is awaited.
            Input::Message(Message::Response(_)) => Ok(None),
        }
    }

    fn request(&mut self, r: Request) -> Flow {
        let id = r.id.clone();
        let refuse = |code: ErrorCode, message: &str| {
            Response::new_err(id.clone(), code as i32, message.to_string())
        };
        let response = match (self.state, r.method.as_str()) {
            (State::Uninitialised, "initialize") => {
                // The client's capabilities change nothing here, so they are not read: a
                // client newer than lsp-types may send values it does not know.
                let reply = respond(r.id, || handlers::to_value(handlers::initialize_result()));
                if reply.response_result.is_ok() {
                    self.state = State::Running;
                }
                reply
            }
            (State::Uninitialised, _) => refuse(
                ErrorCode::ServerNotInitialized,
                "the server is not initialised: send `initialize` first",
            ),
            (State::ShutDown, _) => refuse(
                ErrorCode::InvalidRequest,
                "the server is shut down: only `exit` is left",
            ),
            (State::Running, "initialize") => refuse(
                ErrorCode::InvalidRequest,
                "the server is initialised already",
            ),
            (State::Running, "shutdown") => {
                self.state = State::ShutDown;
                Response::new_ok(r.id, serde_json::Value::Null)
            }
            (State::Running, _) => {
                // Answers are about the latest text.
                self.check_changed()?;
                self.follow_cursor(&r.method, &r.params);
                let docs = &self.docs;
                respond(r.id, || handlers::handle(docs, &r.method, r.params))
            }
        };
        self.out.send(response)?;
        Ok(None)
    }

    fn notification(&mut self, n: Notification) -> Flow {
        use lsp::notification as note;
        if n.method == note::Exit::METHOD {
            return Ok(Some(if self.state == State::ShutDown { 0 } else { 1 }));
        }
        if self.state != State::Running {
            return Ok(None);
        }
        let method = n.method.clone();
        let applied = catch_unwind(AssertUnwindSafe(|| self.sync(n)));
        match applied {
            Ok(Ok(Some(closed))) => {
                // A closed document keeps no diagnostics.
                self.publish(closed, Vec::new(), None)?;
            }
            Ok(Ok(None)) => {}
            Ok(Err(e)) => errln!("clayc lsp: ignored `{method}`: {}", e.message),
            Err(_) => errln!("clayc lsp: `{method}` panicked; ignored"),
        }
        Ok(None)
    }

    /// Applies a document notification; returns the uri of a closed document.
    fn sync(&mut self, n: Notification) -> Result<Option<lsp::Uri>, ResponseError> {
        use lsp::notification as note;
        match n.method.as_str() {
            note::DidOpenTextDocument::METHOD => {
                let p: lsp::DidOpenTextDocumentParams = handlers::params(n.params)?;
                let d = p.text_document;
                let key = d.uri.as_str().to_string();
                self.docs
                    .insert(key.clone(), Document::new(d.uri, d.text, d.version));
                self.changed_document(&key);
            }
            note::DidChangeTextDocument::METHOD => {
                let p: lsp::DidChangeTextDocumentParams = handlers::params(n.params)?;
                let doc = self
                    .docs
                    .get_mut(p.text_document.uri.as_str())
                    .ok_or_else(|| handlers::not_open(&p.text_document.uri))?;
                for change in p.content_changes {
                    apply(&mut doc.text, change);
                }
                doc.version = p.text_document.version;
                doc.dirty = true;
                self.changed_document(p.text_document.uri.as_str());
            }
            note::DidCloseTextDocument::METHOD => {
                let p: lsp::DidCloseTextDocumentParams = handlers::params(n.params)?;
                if self.docs.remove(p.text_document.uri.as_str()).is_some() {
                    // Its importers read it from the disk again.
                    self.changed_document(p.text_document.uri.as_str());
                    return Ok(Some(p.text_document.uri));
                }
            }
            // `initialized`, `didSave`, `$/cancelRequest` (answers are in order and quick),
            // `$/setTrace` and the rest need nothing.
            _ => {}
        }
        Ok(None)
    }

    /// The document `uri` changed (or opened, or closed): check it after the debounce, with the
    /// documents that import it.
    fn changed_document(&mut self, uri: &str) {
        let path = normalised_path(uri);
        for d in self.docs.values_mut() {
            if d.analysis
                .as_ref()
                .is_some_and(|a| a.imported_paths().any(|p| p == path))
            {
                d.dirty = true;
            }
        }
        self.changed();
    }

    /// A document changed: check it after the debounce.
    fn changed(&mut self) {
        let now = Instant::now();
        let first = *self.first_change.get_or_insert(now);
        self.deadline = Some((now + DEBOUNCE).min(first + MAX_DELAY));
    }

    /// Analyses every changed document once, waiting for each until the timeout, and publishes
    /// its diagnostics (or that it timed out). A document whose late analysis still runs waits
    /// for it to end.
    fn check_changed(&mut self) -> std::io::Result<()> {
        self.poll_late()?;
        self.deadline = None;
        self.first_change = None;
        let started = self.start_analyses();
        let until = Instant::now() + self.timeout;
        let mut ready = Vec::new();
        for (uri, job) in started {
            let Some(doc) = self.docs.get_mut(&uri) else {
                continue;
            };
            match job.wait(until) {
                worker::State::Done(a) => ready.push(doc.finished(a)),
                worker::State::Failed => errln!("clayc lsp: the analysis of `{uri}` failed"),
                worker::State::Running => {
                    errln!("clayc lsp: the analysis of `{uri}` timed out; it goes on");
                    ready.push(doc.timed_out(self.timeout));
                    doc.late = Some(job);
                }
            }
        }
        self.publish_all(ready)
    }

    /// Starts the analysis of every changed document that has none running.
    fn start_analyses(&mut self) -> Vec<(String, worker::Job)> {
        if !self.docs.values().any(|d| d.dirty && d.late.is_none()) {
            return Vec::new();
        }
        // An import of an open document reads its text in the editor, saved or not.
        let buffers: Arc<dyn Loader + Send + Sync> = Arc::new(Buffers(
            self.docs
                .iter()
                .map(|(uri, d)| (normalised_path(uri), d.text.clone()))
                .collect(),
        ));
        self.docs
            .iter_mut()
            .filter(|(_, d)| d.dirty && d.late.is_none())
            .map(|(uri, d)| (uri.clone(), d.start(buffers.clone())))
            .collect()
    }

    /// Takes the late analyses that have ended: the diagnostics of one whose document has not
    /// changed since are published; a changed document is checked again.
    fn poll_late(&mut self) -> std::io::Result<()> {
        let mut ready = Vec::new();
        let mut again = false;
        for (uri, doc) in &mut self.docs {
            let Some(job) = &doc.late else { continue };
            match job.poll() {
                worker::State::Running => continue,
                worker::State::Done(a) if !doc.dirty => ready.push(doc.finished(a)),
                worker::State::Done(_) => {}
                worker::State::Failed => errln!("clayc lsp: the analysis of `{uri}` failed"),
            }
            doc.late = None;
            again |= doc.dirty;
        }
        if again {
            self.changed();
        }
        self.publish_all(ready)
    }

    fn publish_all(&mut self, ready: Vec<Published>) -> std::io::Result<()> {
        for (uri, diagnostics, version) in ready {
            self.publish(uri, diagnostics, Some(version))?;
        }
        Ok(())
    }

    fn publish(
        &mut self,
        uri: lsp::Uri,
        diagnostics: Vec<lsp::Diagnostic>,
        version: Option<i32>,
    ) -> std::io::Result<()> {
        let params = lsp::PublishDiagnosticsParams {
            uri,
            diagnostics,
            version,
        };
        self.out.send(Notification::new(
            lsp::notification::PublishDiagnostics::METHOD.to_string(),
            params,
        ))
    }
}

/// A document's path as the compiler names an imported file.
fn normalised_path(uri: &str) -> String {
    clay_dsl::resolve_import("", &convert::file_path(uri))
}

/// Imported files for the compiler: the open documents' texts, else the files on disk.
struct Buffers(HashMap<String, String>);

impl Loader for Buffers {
    fn load(&self, path: &str) -> std::io::Result<Vec<u8>> {
        match self.0.get(path) {
            Some(text) => Ok(text.clone().into_bytes()),
            None => FsLoader.load(path),
        }
    }
}

/// Applies one change: the whole text, or (from a client that ignores the full-sync
/// capability) a range of it.
fn apply(text: &mut String, change: lsp::TextDocumentContentChangeEvent) {
    match change.range {
        None => *text = change.text,
        Some(range) => {
            let s = convert::span(&LineIndex::new(text), range);
            text.replace_range(s.start..s.end, &change.text);
        }
    }
}

/// Runs a handler; its error, or a panic, becomes an error response.
fn respond(
    id: RequestId,
    f: impl FnOnce() -> Result<serde_json::Value, ResponseError>,
) -> Response {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(value)) => Response::new_ok(id, value),
        Ok(Err(error)) => Response {
            id,
            response_result: Err(error),
        },
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "a panic".into());
            Response::new_err(
                id,
                ErrorCode::InternalError as i32,
                format!("internal error: {what}"),
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panicking_handler_gives_an_internal_error_response() {
        let r = respond(RequestId::from(3), || panic!("boom"));
        let e = r.response_result.expect_err("an error");
        assert_eq!(e.code, ErrorCode::InternalError as i32);
        assert!(e.message.contains("boom"), "{}", e.message);
        let r = respond(RequestId::from(4), || Ok(serde_json::json!(1)));
        assert_eq!(r.response_result.unwrap(), serde_json::json!(1));
    }

    #[test]
    fn a_ranged_change_is_applied_at_utf16_positions() {
        let mut text = "// é😀 x\nab".to_string();
        apply(
            &mut text,
            lsp::TextDocumentContentChangeEvent {
                range: Some(lsp::Range::new(
                    lsp::Position::new(0, 7),
                    lsp::Position::new(0, 8),
                )),
                range_length: None,
                text: "y".into(),
            },
        );
        assert_eq!(text, "// é😀 y\nab");
    }
}
