//! The fuzzer of the language server's message handling (issue 37): the server's own loop
//! (`src/lsp`, compiled in here as `benches/lsp.rs` compiles its `convert`) driven in
//! process through a reader and a writer. Each case is a session built from one mutated grammar
//! of the repository: `initialize`, documents opened and changed (whole texts mutated again,
//! ranges in UTF-16 that are wrong, past the end or reversed, versions out of order), requests
//! of every kind the server answers at positions in and far outside the text, `shutdown` and
//! `exit`, and, between them, corrupted frames: a `Content-Length` off by a few bytes, missing,
//! huge, negative or not a number; JSON cut short; bytes that are not UTF-8; JSON that is no
//! JSON-RPC message.
//!
//! Properties: no panic anywhere (the server's catching of a handler's panic is no excuse);
//! no case longer than `HANG`; every request the server could read gets exactly one response,
//! a corrupted frame's neighbours included, and nothing else gets one; the exit code is what
//! the protocol says; every diagnostic published for a text this side knows lies inside it.
//! `CLAY_FUZZ_CASES=N` runs N sessions (default [`CASES`]), `CLAY_FUZZ_SEED` another seed.

use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, Once};
use std::time::Duration;

use proptest::prelude::RngExt;
use proptest::test_runner::TestRng;
use serde_json::{Value, json};

/// The server's log lines (its `errln!`), kept for the properties instead of printed.
static LOG: Mutex<Vec<String>> = Mutex::new(Vec::new());
/// Panics on the server's threads (caught or not), with where they happened.
static PANICS: Mutex<Vec<String>> = Mutex::new(Vec::new());

macro_rules! errln {
    ($($arg:tt)*) => {
        $crate::LOG.lock().unwrap_or_else(|e| e.into_inner()).push(format!($($arg)*))
    };
}

#[allow(dead_code)] // the stdio entry point and the options are the binary's
#[path = "../src/lsp/mod.rs"]
mod lsp;

#[allow(dead_code)] // the engine's plain `fuzz` is the other targets'
#[path = "../../tests/fuzzing/mod.rs"]
mod fuzzing;

/// Sessions a plain `cargo test` runs: about 15 messages each, 2 ms a session in a debug
/// build (10,000 took 18 s on two shared cores).
const CASES: usize = 5_000;

// ---- the frames of a session ----------------------------------------------------------------

/// What a frame is to the server, as far as this side can tell.
#[derive(Clone, Debug)]
enum Kind {
    Request {
        id: Value,
        method: &'static str,
        /// The document the request is about, when its params are well formed.
        uri: Option<String>,
    },
    Notification {
        method: &'static str,
        effect: Effect,
    },
    /// A frame the server cannot read as a message (an answer with a null id at most).
    Lost,
    /// JSON that is no message, or a message of a shape the server refuses: answered at most
    /// once, under `id` if it has a usable one.
    Shape { id: Option<Value> },
    /// A length past the largest body: the rest of the stream is skipped unread.
    Swallow,
}

/// What a well-formed notification does to the documents.
#[derive(Clone, Debug)]
enum Effect {
    None,
    Open {
        uri: String,
        text: String,
        version: i32,
    },
    Change {
        uri: String,
        /// The new text when the change is whole, `None` when it is a range.
        text: Option<String>,
        version: i32,
    },
    Close {
        uri: String,
    },
}

struct Frame {
    bytes: Vec<u8>,
    kind: Kind,
}

fn framed(body: &[u8]) -> Vec<u8> {
    let mut out = format!("Content-Length: {}\r\n\r\n", body.len()).into_bytes();
    out.extend_from_slice(body);
    out
}

/// A well-formed frame of `message`, its header written as clients variously write it.
fn good(rng: &mut TestRng, message: &Value, kind: Kind) -> Frame {
    let body = message.to_string().into_bytes();
    let header = match rng.random_range(0..8) {
        0 => format!(
            "Content-Length: {}\r\nContent-Type: application/vscode-jsonrpc; charset=utf-8\r\n\r\n",
            body.len()
        ),
        1 => format!("content-length:{}\r\n\r\n", body.len()),
        // An earlier wrong length is overridden by the last.
        2 => format!(
            "Content-Length: 3\r\nContent-Length: {}\r\n\r\n",
            body.len()
        ),
        _ => format!("Content-Length: {}\r\n\r\n", body.len()),
    };
    let mut bytes = header.into_bytes();
    bytes.extend_from_slice(&body);
    Frame { bytes, kind }
}

/// A well-formed message broken on its way: the server cannot read it, and reads on.
fn corrupted(rng: &mut TestRng, message: &Value) -> Frame {
    let body = message.to_string().into_bytes();
    let n = body.len() as i64;
    let bytes = match rng.random_range(0..7) {
        0 => {
            let off = [-40i64, -3, -2, -1, 1, 2, 3, 40][rng.random_range(0..8)];
            let mut b = format!("Content-Length: {}\r\n\r\n", (n + off).max(0)).into_bytes();
            b.extend_from_slice(&body);
            b
        }
        1 => {
            let mut b = b"Content-Type: application/vscode-jsonrpc\r\n\r\n".to_vec();
            b.extend_from_slice(&body);
            b
        }
        2 => {
            let value = ["-5", "abc", "", "12abc", "0x10", "1e3", "-0"][rng.random_range(0..7)];
            let mut b = format!("Content-Length: {value}\r\n\r\n").into_bytes();
            b.extend_from_slice(&body);
            b
        }
        3 => framed(&body[..rng.random_range(0..body.len())]),
        4 => {
            let mut b = body.clone();
            let at = rng.random_range(0..=b.len());
            let bad: &[u8] =
                [&b"\xff"[..], b"\xc3\x28", b"\xed\xa0\x80", b"\xf0\x9f"][rng.random_range(0..4)];
            b.splice(at..at, bad.iter().copied());
            framed(&b)
        }
        5 => {
            // Header lines without the blank line that ends them, then the next frame.
            format!("Content-Length: {n}\r\n{}", String::from_utf8_lossy(&body)).into_bytes()
        }
        _ => {
            let mut b = body.clone();
            b.truncate(b.len().saturating_sub(1));
            b.extend_from_slice(b",}");
            framed(&b)
        }
    };
    Frame {
        bytes,
        kind: Kind::Lost,
    }
}

/// Whether the last frame is a header without the blank line that ends it. The next frame's
/// header then runs on in it, and the length it declares frames what comes next: whatever
/// follows is read as a body (or, if that fails, looked for again). So what follows is a whole
/// message, never one whose reading or loss this side could not tell: a body that is whole
/// JSON behind a bad header would be read when the lengths happen to agree, and a length past
/// everything would be taken for a header line.
fn open_header(frames: &[Frame]) -> bool {
    frames.last().is_some_and(|f| {
        matches!(f.kind, Kind::Lost)
            && f.bytes.starts_with(b"Content-Length: ")
            && !f.bytes.windows(4).any(|w| w == b"\r\n\r\n")
    })
}

/// JSON that no handler reads as the message it claims to be, with `id` (unique) where it has
/// one.
fn shape(rng: &mut TestRng, id: i64) -> Frame {
    let body = match rng.random_range(0..12) {
        0 => json!([]),
        1 => json!(null),
        2 => json!(1),
        3 => json!({}),
        4 => json!({"jsonrpc": "2.0"}),
        5 => json!({"jsonrpc": "2.0", "id": id}),
        6 => json!({"jsonrpc": "2.0", "id": id, "method": 5}),
        7 => json!({"jsonrpc": "2.0", "id": {"a": 1}, "method": "textDocument/hover"}),
        8 => json!({"jsonrpc": "2.0", "id": 1.5, "method": "shutdown"}),
        9 => json!({"jsonrpc": "2.0", "method": "textDocument/didOpen", "params": "x"}),
        10 => json!({"jsonrpc": "2.0", "id": id, "result": null}),
        _ => json!({"jsonrpc": "2.0", "id": id, "error": {"code": 1}}),
    };
    let id = body.get("id").filter(|i| i.is_i64()).cloned();
    Frame {
        bytes: framed(body.to_string().as_bytes()),
        kind: Kind::Shape { id },
    }
}

// ---- sessions -------------------------------------------------------------------------------

const URIS: &[&str] = &[
    "file:///tmp/clay-fuzz-lsp/a.clay",
    "file:///tmp/clay-fuzz-lsp/lib/b.clay",
    "untitled:Untitled-1",
    "file:///tmp/clay-fuzz-lsp/%E2%82%AC%20x.clay",
];

/// Requests the server answers, with how their params are made.
const REQUESTS: &[&str] = &[
    "textDocument/hover",
    "textDocument/definition",
    "textDocument/references",
    "textDocument/documentHighlight",
    "textDocument/completion",
    "textDocument/formatting",
    "textDocument/rangeFormatting",
    "textDocument/prepareRename",
    "textDocument/rename",
    "textDocument/documentSymbol",
    "textDocument/semanticTokens/full",
    "textDocument/foldingRange",
    "textDocument/codeAction",
    "workspace/symbol",
    "clay/unknown",
];

/// A position in `text`, or near it, or far outside it.
fn position(rng: &mut TestRng, text: &str) -> Value {
    let lines: Vec<&str> = text.split('\n').collect();
    let line = match rng.random_range(0..12) {
        0 => u32::MAX as usize,
        1 => lines.len() + rng.random_range(0..3),
        _ => rng.random_range(0..lines.len()),
    };
    let width = lines.get(line).map_or(0, |l| l.encode_utf16().count());
    let character = match rng.random_range(0..12) {
        0 => u32::MAX as usize,
        1 => width + rng.random_range(1..4),
        _ => rng.random_range(0..=width),
    };
    json!({"line": line, "character": character})
}

fn range(rng: &mut TestRng, text: &str) -> Value {
    json!({"start": position(rng, text), "end": position(rng, text)})
}

/// The params of a request `method` about `uri` (whose text this side believes is `text`).
fn request_params(rng: &mut TestRng, method: &str, uri: &str, text: &str) -> Value {
    let doc = json!({"uri": uri});
    let at = position(rng, text);
    match method {
        "textDocument/references" => json!({
            "textDocument": doc, "position": at, "context": {"includeDeclaration": rng.random_bool(0.5)}
        }),
        "textDocument/formatting" => json!({
            "textDocument": doc, "options": {"tabSize": 4, "insertSpaces": true}
        }),
        "textDocument/rangeFormatting" => json!({
            "textDocument": doc, "range": range(rng, text),
            "options": {"tabSize": 2, "insertSpaces": rng.random_bool(0.5)}
        }),
        "textDocument/rename" => {
            let names = ["b2", "x", "", "1abc", "piece", "é", "a b", "🧱"];
            json!({"textDocument": doc, "position": at, "newName": names[rng.random_range(0..names.len())]})
        }
        "textDocument/documentSymbol"
        | "textDocument/semanticTokens/full"
        | "textDocument/foldingRange" => json!({"textDocument": doc}),
        "textDocument/codeAction" => json!({
            "textDocument": doc, "range": range(rng, text), "context": {"diagnostics": []}
        }),
        "workspace/symbol" => json!({"query": "a"}),
        _ => json!({"textDocument": doc, "position": at}),
    }
}

/// Params that fit no request.
fn wrong_params(rng: &mut TestRng, uri: &str) -> Value {
    match rng.random_range(0..6) {
        0 => json!(null),
        1 => json!([1, 2]),
        2 => json!({"textDocument": {"uri": 5}}),
        3 => json!({"textDocument": {"uri": uri}, "position": {"line": -1, "character": 0}}),
        4 => json!({"textDocument": {"uri": "not a uri"}, "position": {"line": 0, "character": 0}}),
        _ => json!({"textDocument": {"uri": uri}, "position": "here"}),
    }
}

/// A text `text` changed as a user might change it.
fn edited(rng: &mut TestRng, text: &str) -> String {
    let corpus = [text.as_bytes().to_vec()];
    fuzzing::lossy(&fuzzing::mutate(rng, text.as_bytes(), &corpus))
}

fn version(rng: &mut TestRng, last: &mut i32) -> i32 {
    match rng.random_range(0..10) {
        0 => [i32::MIN, -1, 0, i32::MAX][rng.random_range(0..4)],
        1 => *last - 1,
        2 => *last,
        _ => {
            *last = last.saturating_add(1);
            *last
        }
    }
}

/// The frames of one session about `text`.
fn session(rng: &mut TestRng, text: &str) -> Vec<Frame> {
    let mut frames = Vec::new();
    let mut next_id = 1i64;
    // Numbers and strings, as clients send them.
    let id = |rng: &mut TestRng, next_id: &mut i64| {
        *next_id += 1;
        if rng.random_bool(0.2) {
            json!(format!("s{next_id}"))
        } else {
            json!(*next_id)
        }
    };
    let mut last_version = 0i32;
    // This side's idea of each document's text, for the params of the next message.
    let mut texts: HashMap<&str, String> = HashMap::new();
    let push = |frames: &mut Vec<Frame>, rng: &mut TestRng, message: Value, kind: Kind| {
        if rng.random_bool(0.1) && !open_header(frames) {
            // The message never arrives whole; its neighbours must.
            frames.push(corrupted(rng, &message));
        } else {
            frames.push(good(rng, &message, kind));
        }
    };
    if rng.random_bool(0.95) {
        let i = id(rng, &mut next_id);
        let m = json!({"jsonrpc": "2.0", "id": i, "method": "initialize",
            "params": {"processId": null, "rootUri": null, "capabilities": {"future": [1, {"x": null}]}}});
        let kind = Kind::Request {
            id: i,
            method: "initialize",
            uri: None,
        };
        push(&mut frames, rng, m, kind);
        let m = json!({"jsonrpc": "2.0", "method": "initialized", "params": {}});
        push(
            &mut frames,
            rng,
            m,
            Kind::Notification {
                method: "initialized",
                effect: Effect::None,
            },
        );
    }
    let steps = rng.random_range(3..24);
    for step in 0..steps {
        let uri = URIS[if rng.random_bool(0.7) {
            0
        } else {
            rng.random_range(0..URIS.len())
        }];
        let known = texts.get(uri).cloned().unwrap_or_else(|| text.to_string());
        let pick = if step == 0 {
            0
        } else {
            rng.random_range(0..20)
        };
        match pick {
            0 | 1 => {
                let body = if texts.is_empty() || rng.random_bool(0.7) {
                    text.to_string()
                } else if uri == URIS[1] {
                    // A library that the first document may import.
                    "piece lib_piece {\n    vertex a (0, 0)\n    vertex b (1, 0)\n    edges a-b\n}\n".into()
                } else {
                    format!("import \"lib/b.clay\"\n{}", edited(rng, text))
                };
                let v = version(rng, &mut last_version);
                let m = json!({"jsonrpc": "2.0", "method": "textDocument/didOpen", "params": {
                    "textDocument": {"uri": uri, "languageId": "clay", "version": v, "text": body}}});
                texts.insert(uri, body.clone());
                let effect = Effect::Open {
                    uri: uri.into(),
                    text: body,
                    version: v,
                };
                push(
                    &mut frames,
                    rng,
                    m,
                    Kind::Notification {
                        method: "textDocument/didOpen",
                        effect,
                    },
                );
            }
            2..=5 => {
                let v = version(rng, &mut last_version);
                let (changes, new_text) = if rng.random_bool(0.6) {
                    let t = edited(rng, &known);
                    (json!([{"text": t}]), Some(t))
                } else {
                    let n = rng.random_range(1..4);
                    let changes: Vec<Value> = (0..n)
                        .map(|_| {
                            let insert =
                                fuzzing::TOKENS[rng.random_range(0..fuzzing::TOKENS.len())];
                            json!({"range": range(rng, &known), "text": insert})
                        })
                        .collect();
                    (Value::Array(changes), None)
                };
                if let Some(t) = &new_text {
                    texts.insert(uri, t.clone());
                } else {
                    texts.remove(uri);
                }
                let m = json!({"jsonrpc": "2.0", "method": "textDocument/didChange", "params": {
                    "textDocument": {"uri": uri, "version": v}, "contentChanges": changes}});
                let effect = Effect::Change {
                    uri: uri.into(),
                    text: new_text,
                    version: v,
                };
                push(
                    &mut frames,
                    rng,
                    m,
                    Kind::Notification {
                        method: "textDocument/didChange",
                        effect,
                    },
                );
            }
            6..=13 => {
                let method = REQUESTS[rng.random_range(0..REQUESTS.len())];
                let i = id(rng, &mut next_id);
                let (params, well_formed) = if rng.random_bool(0.1) {
                    (wrong_params(rng, uri), false)
                } else {
                    (request_params(rng, method, uri, &known), true)
                };
                let m = json!({"jsonrpc": "2.0", "id": i, "method": method, "params": params});
                let kind = Kind::Request {
                    id: i,
                    method,
                    uri: well_formed.then(|| uri.to_string()),
                };
                push(&mut frames, rng, m, kind);
            }
            14 => {
                let m = json!({"jsonrpc": "2.0", "method": "textDocument/didClose",
                    "params": {"textDocument": {"uri": uri}}});
                texts.remove(uri);
                let effect = Effect::Close { uri: uri.into() };
                push(
                    &mut frames,
                    rng,
                    m,
                    Kind::Notification {
                        method: "textDocument/didClose",
                        effect,
                    },
                );
            }
            15 => {
                let methods = [
                    "textDocument/didSave",
                    "$/cancelRequest",
                    "$/setTrace",
                    "workspace/didChangeConfiguration",
                    "clay/unknown",
                ];
                let method = methods[rng.random_range(0..methods.len())];
                let m = json!({"jsonrpc": "2.0", "method": method, "params": {"textDocument": {"uri": uri}, "id": 1}});
                push(
                    &mut frames,
                    rng,
                    m,
                    Kind::Notification {
                        method,
                        effect: Effect::None,
                    },
                );
            }
            16 if rng.random_bool(0.3) => {
                let i = id(rng, &mut next_id);
                let method = if rng.random_bool(0.5) {
                    "shutdown"
                } else {
                    "initialize"
                };
                let m = json!({"jsonrpc": "2.0", "id": i, "method": method, "params": {"capabilities": {}}});
                push(
                    &mut frames,
                    rng,
                    m,
                    Kind::Request {
                        id: i,
                        method,
                        uri: None,
                    },
                );
            }
            17 => {
                next_id += 1;
                frames.push(shape(rng, 1_000_000 + next_id));
            }
            18 if !open_header(&frames) => {
                // Junk between frames; blank lines only after a frame that is read (a body
                // too long by a byte or two would be read with them as whole JSON).
                let after_lost = frames.last().is_some_and(|f| matches!(f.kind, Kind::Lost));
                let junk: &[u8] = [
                    &b"garbage\r\n\r\n"[..],
                    b"\x00\xff\xfe",
                    b"{\"jsonrpc\":\"2.0\"}",
                    b"Content-Length",
                    b"\r\n\r\n",
                ][rng.random_range(0..if after_lost { 4 } else { 5 })];
                frames.push(Frame {
                    bytes: junk.to_vec(),
                    kind: Kind::Lost,
                });
            }
            _ => {
                if rng.random_bool(0.1) && !open_header(&frames) {
                    // A length beyond everything left: past the largest body the server
                    // reads, the rest is skipped unread; within it, the input ends inside the
                    // body, and the frames that body took are read.
                    let (n, kind) = if rng.random_bool(0.5) {
                        ("99999999999", Kind::Swallow)
                    } else {
                        ("1000000", Kind::Lost)
                    };
                    frames.push(Frame {
                        bytes: format!("Content-Length: {n}\r\n\r\n{{").into_bytes(),
                        kind,
                    });
                }
            }
        }
    }
    if rng.random_bool(0.6) {
        let i = id(rng, &mut next_id);
        let m = json!({"jsonrpc": "2.0", "id": i, "method": "shutdown"});
        push(
            &mut frames,
            rng,
            m,
            Kind::Request {
                id: i,
                method: "shutdown",
                uri: None,
            },
        );
    }
    if rng.random_bool(0.6) {
        // An exit is never broken here: whether it arrives decides the exit code.
        let m = json!({"jsonrpc": "2.0", "method": "exit"});
        let kind = Kind::Notification {
            method: "exit",
            effect: Effect::None,
        };
        frames.push(good(rng, &m, kind));
        if rng.random_bool(0.3) {
            // Frames after `exit` are never read.
            let i = id(rng, &mut next_id);
            let m =
                json!({"jsonrpc": "2.0", "id": i, "method": "textDocument/hover", "params": {}});
            frames.push(good(
                rng,
                &m,
                Kind::Request {
                    id: i,
                    method: "textDocument/hover",
                    uri: None,
                },
            ));
        }
    }
    frames
}

// ---- what the server must do ----------------------------------------------------------------

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Want {
    Once,
    AtMostOnce,
    Never,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum State {
    Uninitialised,
    Running,
    ShutDown,
}

/// What the server must answer, as the protocol's state machine and the framing say.
struct Expected {
    answers: HashMap<String, Want>,
    /// The text of each (uri, version), when this side knows it and it is the only one.
    versions: HashMap<(String, i32), Option<String>>,
    /// The text of the document a request is about, when known at the time it is answered.
    request_text: HashMap<String, (String, &'static str)>,
    exit_code: u8,
}

fn key(id: &Value) -> String {
    id.to_string()
}

fn expected(frames: &[Frame]) -> Expected {
    let mut e = Expected {
        answers: HashMap::new(),
        versions: HashMap::new(),
        request_text: HashMap::new(),
        exit_code: 0,
    };
    let mut state = State::Uninitialised;
    let mut open: HashMap<String, Option<String>> = HashMap::new();
    let mut read = true;
    let note = |e: &mut Expected, uri: &str, version: i32, text: Option<&String>| {
        let k = (uri.to_string(), version);
        match (e.versions.get(&k), text) {
            (None, Some(t)) => {
                e.versions.insert(k, Some(t.clone()));
            }
            (Some(Some(old)), Some(t)) if old == t => {}
            _ => {
                e.versions.insert(k, None);
            }
        }
    };
    for f in frames {
        match &f.kind {
            Kind::Request { id, method, uri } => {
                if !read {
                    e.answers.insert(key(id), Want::Never);
                    continue;
                }
                e.answers.insert(key(id), Want::Once);
                if let Some(u) = uri
                    && state == State::Running
                    && let Some(Some(t)) = open.get(u)
                {
                    e.request_text.insert(key(id), (t.clone(), method));
                }
                state = match (state, *method) {
                    (State::Uninitialised, "initialize") => State::Running,
                    (State::Running, "shutdown") => State::ShutDown,
                    (s, _) => s,
                };
            }
            Kind::Notification { method, effect } => {
                if !read {
                    continue;
                }
                if *method == "exit" {
                    e.exit_code = u8::from(state != State::ShutDown);
                    read = false;
                    continue;
                }
                if state != State::Running {
                    continue;
                }
                match effect {
                    Effect::None => {}
                    Effect::Open { uri, text, version } => {
                        open.insert(uri.clone(), Some(text.clone()));
                        note(&mut e, uri, *version, Some(text));
                    }
                    Effect::Change { uri, text, version } => {
                        if let Some(doc) = open.get_mut(uri) {
                            *doc = text.clone();
                            note(&mut e, uri, *version, text.as_ref());
                        }
                    }
                    Effect::Close { uri } => {
                        open.remove(uri);
                    }
                }
            }
            Kind::Lost => {}
            Kind::Shape { id } => {
                if let Some(id) = id {
                    e.answers
                        .insert(key(id), if read { Want::AtMostOnce } else { Want::Never });
                }
            }
            Kind::Swallow => read = false,
        }
    }
    e
}

/// The frames the server wrote.
fn written(bytes: &[u8]) -> Result<Vec<Value>, String> {
    let mut out = Vec::new();
    let mut rest = bytes;
    while !rest.is_empty() {
        let text = String::from_utf8_lossy(&rest[..rest.len().min(64)]).into_owned();
        let Some(end) = rest.windows(4).position(|w| w == b"\r\n\r\n") else {
            return Err(format!("output without a header end: {text:?}"));
        };
        let header = std::str::from_utf8(&rest[..end]).map_err(|e| e.to_string())?;
        let n: usize = header
            .strip_prefix("Content-Length: ")
            .and_then(|n| n.parse().ok())
            .ok_or_else(|| format!("a bad header written: {header:?}"))?;
        let body = rest
            .get(end + 4..end + 4 + n)
            .ok_or("a frame written short")?;
        out.push(serde_json::from_slice(body).map_err(|e| format!("written JSON: {e}"))?);
        rest = &rest[end + 4 + n..];
    }
    Ok(out)
}

/// Whether a range lies in `text`, its ends in order.
fn inside(range: &Value, text: &str) -> bool {
    let at = |p: &Value| -> Option<(u64, u64)> {
        Some((p.get("line")?.as_u64()?, p.get("character")?.as_u64()?))
    };
    let (Some(s), Some(e)) = (at(&range["start"]), at(&range["end"])) else {
        return false;
    };
    let lines: Vec<&str> = text.split('\n').collect();
    let fits = |(l, c): (u64, u64)| {
        lines
            .get(l as usize)
            .is_some_and(|line| c as usize <= line.encode_utf16().count())
    };
    s <= e && fits(s) && fits(e)
}

/// Every range in a value (objects with a `start` and an `end` position).
fn ranges(v: &Value, out: &mut Vec<Value>) {
    match v {
        Value::Object(m) => {
            if m.get("start").is_some_and(|s| s.get("line").is_some())
                && m.get("end").is_some_and(|s| s.get("line").is_some())
            {
                out.push(v.clone());
            }
            for (k, x) in m {
                // A location elsewhere (another file) is not about this text.
                if k != "relatedInformation" && k != "targetUri" {
                    ranges(x, out);
                }
            }
        }
        Value::Array(a) => a.iter().for_each(|x| ranges(x, out)),
        _ => {}
    }
}

fn check(frames: &[Frame], code: u8, out: &[u8], in_time: bool) -> Result<(), String> {
    let e = expected(frames);
    let messages = written(out)?;
    let mut got: HashMap<String, usize> = HashMap::new();
    for m in &messages {
        if m.get("method").is_some() {
            if m["method"] == "textDocument/publishDiagnostics" {
                let p = &m["params"];
                let uri = p["uri"].as_str().unwrap_or_default().to_string();
                let Some(v) = p["version"].as_i64() else {
                    continue;
                };
                if let Some(Some(text)) = e.versions.get(&(uri, v as i32)) {
                    for d in p["diagnostics"].as_array().into_iter().flatten() {
                        if !inside(&d["range"], text) {
                            return Err(format!("a diagnostic outside its text: {d}"));
                        }
                    }
                }
            } else if m.get("id").is_none() || m["method"] != "window/showDocument" {
                return Err(format!("the server sent {m}"));
            }
            continue;
        }
        let id = &m["id"];
        if id.is_null() {
            let code = m["error"]["code"].as_i64();
            if !matches!(code, Some(-32700 | -32600)) {
                return Err(format!("an answer to no request: {m}"));
            }
            continue;
        }
        if m["error"]["code"] == json!(-32603) {
            return Err(format!("an internal error (a panic?): {m}"));
        }
        *got.entry(key(id)).or_default() += 1;
        if let Some((text, method)) = e.request_text.get(&key(id))
            && in_time
            && matches!(
                *method,
                "textDocument/formatting"
                    | "textDocument/rangeFormatting"
                    | "textDocument/documentHighlight"
                    | "textDocument/documentSymbol"
                    | "textDocument/hover"
                    | "textDocument/prepareRename"
                    | "textDocument/codeAction"
            )
        {
            let mut found = Vec::new();
            ranges(&m["result"], &mut found);
            if let Some(r) = found.iter().find(|r| !inside(r, text)) {
                return Err(format!(
                    "{method} answers with a range outside the text: {r}"
                ));
            }
        }
    }
    for (id, want) in &e.answers {
        let n = got.get(id).copied().unwrap_or(0);
        let ok = match want {
            Want::Once => n == 1,
            Want::AtMostOnce => n <= 1,
            Want::Never => n == 0,
        };
        if !ok {
            return Err(format!("request {id}: {n} answers, wanted {want:?}"));
        }
    }
    if let Some(id) = got.keys().find(|id| !e.answers.contains_key(*id)) {
        return Err(format!("an answer to {id}, which was never asked"));
    }
    if code != e.exit_code {
        return Err(format!("exit code {code}, not {}", e.exit_code));
    }
    Ok(())
}

/// Output shared with the test after the server has ended.
#[derive(Clone, Default)]
struct Shared(Arc<Mutex<Vec<u8>>>);

impl Write for Shared {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.lock().unwrap().extend_from_slice(buf);
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Records panics on the server's threads (and still reports the others as usual).
fn watch_panics() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let usual = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            let name = std::thread::current().name().map(str::to_string);
            let ours = matches!(name.as_deref(), None | Some("lsp-analysis" | "lsp-reader"));
            if ours {
                PANICS
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .push(format!("{name:?}: {info}"));
            } else {
                usual(info);
            }
        }));
    });
}

fn describe(frames: &[Frame]) -> String {
    frames
        .iter()
        .map(|f| {
            let text = String::from_utf8_lossy(&f.bytes);
            let short: String = text.chars().take(160).collect();
            format!("  {:?}: {short:?}", kind_name(&f.kind))
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn kind_name(k: &Kind) -> String {
    match k {
        Kind::Request { id, method, .. } => format!("request {id} {method}"),
        Kind::Notification { method, .. } => format!("notification {method}"),
        Kind::Lost => "lost".into(),
        Kind::Shape { id } => format!("shape {id:?}"),
        Kind::Swallow => "swallow".into(),
    }
}

fn lsp_case(input: &[u8]) -> Result<(), String> {
    watch_panics();
    let mut h = std::collections::hash_map::DefaultHasher::new();
    input.hash(&mut h);
    let mut rng = fuzzing::rng(h.finish());
    let text = fuzzing::lossy(input);
    let frames = session(&mut rng, &text);
    let stream: Vec<u8> = frames
        .iter()
        .flat_map(|f| f.bytes.iter().copied())
        .collect();
    // Mostly time for every analysis; sometimes none, so that analyses run late.
    let in_time = rng.random_bool(0.7);
    let timeout = if in_time {
        Duration::from_secs(10)
    } else {
        Duration::from_millis(rng.random_range(0..3))
    };
    LOG.lock().unwrap_or_else(|e| e.into_inner()).clear();
    PANICS.lock().unwrap_or_else(|e| e.into_inner()).clear();
    let out = Shared::default();
    // Sometimes a Clay editor follows: the cursor is written where it would read it.
    let follow = if rng.random_bool(0.2) {
        following()
    } else {
        nowhere()
    };
    let code = lsp::serve(std::io::Cursor::new(stream), out.clone(), timeout, follow);
    let bytes = std::mem::take(&mut *out.0.lock().unwrap());
    let outcome = check(&frames, code, &bytes, in_time).and_then(|()| {
        let panics = PANICS.lock().unwrap_or_else(|e| e.into_inner()).clone();
        let log = LOG.lock().unwrap_or_else(|e| e.into_inner()).clone();
        match panics.first() {
            Some(p) => Err(format!("a panic: {p}")),
            None => match log
                .iter()
                .find(|l| l.contains("panicked") || l.contains("failed"))
            {
                Some(l) => Err(format!("the server logged: {l}")),
                None => Ok(()),
            },
        }
    });
    outcome.map_err(|why| format!("{why}\nsession:\n{}", describe(&frames)))
}

/// A folder that does not exist: no Clay editor follows.
fn nowhere() -> PathBuf {
    std::env::temp_dir().join("clay-fuzz-lsp-follow-nobody")
}

/// A folder of this process's own, as a following Clay editor makes it.
fn following() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("clay-fuzz-lsp-follow-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    dir
}

fn files_under(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            files_under(&p, out);
        } else if p.extension().is_some_and(|x| x == "clay") {
            out.push(p);
        }
    }
}

/// Every grammar of the repository, and the inputs issue 37 found.
fn corpus() -> Vec<Vec<u8>> {
    let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."));
    let mut files = Vec::new();
    for dir in ["grammars", "tests/fixtures", "dsl/tests", "docs"] {
        files_under(&root.join(dir), &mut files);
    }
    files.sort();
    let mut corpus: Vec<Vec<u8>> = files.iter().filter_map(|f| std::fs::read(f).ok()).collect();
    assert!(corpus.len() > 10, "the repository's grammars");
    for found in [
        "solver {\n    merge_distance = // in m²\n}\n",
        "piece\u{feff}x",
        &"/* ".repeat(30),
        "// é😀 x\nab",
        "",
    ] {
        corpus.push(found.as_bytes().to_vec());
    }
    corpus
}

#[test]
fn language_server_sessions_never_panic_hang_or_lose_an_answer() {
    fuzzing::fuzz_cases(
        "lsp",
        fuzzing::cases_or(CASES),
        corpus(),
        fuzzing::mutate,
        lsp_case,
    );
    let _ = std::fs::remove_dir_all(following());
}
