//! JSON-RPC over a byte stream with `Content-Length` framing, tolerant of what a client gets
//! wrong: lsp-server's own stdio transport ends the connection at the first body that is not
//! a message, where the protocol wants an error response (`ParseError`, `InvalidRequest`) and
//! the server going on. Messages are lsp-server's; only the framing is ours.
//!
//! A frame that holds no JSON (a `Content-Length` off by a few bytes, a header without one)
//! gets one `ParseError`, and then the reader resynchronises: it looks for the next
//! `Content-Length:` from the first byte it has not accepted as a frame (inside the bad frame's
//! header and body too, either of which may have swallowed the start of the next frame), so
//! the frames after it are read as they were sent.

use std::io::{self, BufRead, Read, Write};
use std::sync::mpsc;

use lsp_server::{ErrorCode, Message, RequestId, Response};

/// A body larger than this is skipped (and answered with an error), never allocated.
const MAX_BODY: usize = 256 << 20;
/// A header line longer than this is not a header.
const MAX_HEADER_LINE: u64 = 64 << 10;
/// A frame's header longer than this (all its lines) is no header.
const MAX_HEADER: usize = 64 << 10;
/// Where a frame starts, in lower case (header names are case-insensitive).
const HEADER_START: &[u8] = b"content-length:";

/// What the reader hands the server.
#[derive(Debug)]
pub enum Input {
    Message(Message),
    /// A frame that holds no message: answer with this error (`id` null when unknown).
    Malformed {
        id: Option<RequestId>,
        code: ErrorCode,
        message: String,
    },
}

enum Frame {
    /// A body, and the header that framed it.
    Body {
        header: Vec<u8>,
        body: Vec<u8>,
    },
    /// No frame: what is wrong, and the bytes read that may hold the start of the next one.
    Bad {
        message: String,
        unframed: Vec<u8>,
    },
    End,
}

/// The client's bytes, with room to read some of them again.
struct Stream<R> {
    inner: R,
    again: Vec<u8>,
    at: usize,
    /// The last frame held no message: skip to the next header before reading on.
    lost: bool,
}

impl<R: BufRead> Stream<R> {
    fn new(inner: R) -> Self {
        Self {
            inner,
            again: Vec::new(),
            at: 0,
            lost: false,
        }
    }

    /// Puts `bytes` back in front of what is left to read.
    fn unread(&mut self, bytes: &[u8]) {
        let mut again = bytes.to_vec();
        again.extend_from_slice(&self.again[self.at..]);
        self.again = again;
        self.at = 0;
    }
}

impl<R: BufRead> Read for Stream<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let available = self.fill_buf()?;
        let n = available.len().min(buf.len());
        buf[..n].copy_from_slice(&available[..n]);
        self.consume(n);
        Ok(n)
    }
}

impl<R: BufRead> BufRead for Stream<R> {
    fn fill_buf(&mut self) -> io::Result<&[u8]> {
        if self.at < self.again.len() {
            return Ok(&self.again[self.at..]);
        }
        self.inner.fill_buf()
    }

    fn consume(&mut self, n: usize) {
        if self.at < self.again.len() {
            self.at += n;
            if self.at >= self.again.len() {
                self.again.clear();
                self.at = 0;
            }
        } else {
            self.inner.consume(n);
        }
    }
}

/// Reads frames on a thread of its own until the stream ends (or the `exit` notification),
/// so the server can wait for input with a timeout (the diagnostics' debounce).
pub fn spawn_reader<R: BufRead + Send + 'static>(input: R) -> mpsc::Receiver<Input> {
    let (tx, rx) = mpsc::channel();
    let mut input = Stream::new(input);
    std::thread::Builder::new()
        .name("lsp-reader".into())
        .spawn(move || {
            // The end of the stream, or an error reading it, ends reading.
            while let Ok(Some(item)) = next(&mut input) {
                let exit =
                    matches!(&item, Input::Message(Message::Notification(n)) if n.method == "exit");
                if tx.send(item).is_err() || exit {
                    break;
                }
            }
        })
        .expect("a thread for reading the client's messages");
    rx
}

/// The next message or error to answer with, `None` at the end of the stream. After a frame
/// that holds no JSON, skips to the next `Content-Length:` first; the skip waits for bytes, so
/// it comes after the error is handed on, not before (a client may wait for that answer).
fn next(input: &mut Stream<impl BufRead>) -> io::Result<Option<Input>> {
    if std::mem::take(&mut input.lost) {
        skip_to_header(input)?;
    }
    let (message, unframed) = match read_frame(input)? {
        Frame::End => return Ok(None),
        Frame::Body { header, body } => match parse(&body) {
            Input::Malformed {
                code: ErrorCode::ParseError,
                message,
                ..
            } => {
                // Nothing of it was a frame: its header too may have swallowed the start of
                // the next one (a header line without the blank line that ends it runs on
                // into the next frame's header).
                let mut bytes = unframed(header);
                bytes.extend_from_slice(&body);
                (message, bytes)
            }
            item => return Ok(Some(item)),
        },
        Frame::Bad { message, unframed } => (message, unframed),
    };
    input.unread(&unframed);
    input.lost = true;
    Ok(Some(Input::Malformed {
        id: None,
        code: ErrorCode::ParseError,
        message,
    }))
}

/// Consumes bytes up to the next `Content-Length:` (any case), which is left to read, or to
/// the end of the stream.
fn skip_to_header(input: &mut Stream<impl BufRead>) -> io::Result<()> {
    let mut matched = 0;
    loop {
        let buf = input.fill_buf()?;
        if buf.is_empty() {
            return Ok(());
        }
        let mut used = 0;
        for &b in buf {
            used += 1;
            let b = b.to_ascii_lowercase();
            // The pattern's first letter occurs only there, so a mismatch restarts it.
            matched = if b == HEADER_START[matched] {
                matched + 1
            } else {
                usize::from(b == HEADER_START[0])
            };
            if matched == HEADER_START.len() {
                break;
            }
        }
        input.consume(used);
        if matched == HEADER_START.len() {
            input.unread(b"Content-Length:");
            return Ok(());
        }
    }
}

fn read_frame(input: &mut impl BufRead) -> io::Result<Frame> {
    let mut length: Option<Result<usize, String>> = None;
    let mut bad_header: Option<String> = None;
    let mut seen_header = false;
    let mut header = Vec::new();
    let mut line = Vec::new();
    loop {
        line.clear();
        if input
            .by_ref()
            .take(MAX_HEADER_LINE)
            .read_until(b'\n', &mut line)?
            == 0
        {
            return Ok(Frame::End);
        }
        header.extend_from_slice(&line);
        if header.len() > MAX_HEADER {
            return Ok(bad(
                format!("a header of more than {MAX_HEADER} bytes"),
                header,
            ));
        }
        let text = String::from_utf8_lossy(&line);
        let text = text.trim_end_matches(['\r', '\n']);
        if text.is_empty() {
            if seen_header {
                break;
            }
            // Blank lines between frames are harmless.
            continue;
        }
        seen_header = true;
        match text.split_once(':') {
            Some((name, value)) if name.trim().eq_ignore_ascii_case("content-length") => {
                length = Some(
                    value
                        .trim()
                        .parse()
                        .map_err(|e| format!("bad Content-Length `{}`: {e}", value.trim())),
                );
            }
            Some(_) => {} // Content-Type and others
            None => bad_header = Some(format!("malformed header line `{text}`")),
        }
    }
    match length {
        None => Ok(bad(
            bad_header.unwrap_or_else(|| "a message without a Content-Length header".into()),
            header,
        )),
        Some(Err(message)) => Ok(bad(message, header)),
        Some(Ok(n)) if n > MAX_BODY => {
            io::copy(&mut input.by_ref().take(n as u64), &mut io::sink())?;
            Ok(bad(
                format!("a message of {n} bytes (at most {MAX_BODY})"),
                Vec::new(),
            ))
        }
        Some(Ok(n)) => {
            let mut body = Vec::with_capacity(n.min(1 << 20));
            input.by_ref().take(n as u64).read_to_end(&mut body)?;
            if body.len() < n {
                // The input ended inside the body: a length larger than what followed, which
                // may hold whole frames.
                let message = format!(
                    "the input ended {} bytes into a message of {n} bytes",
                    body.len()
                );
                header.extend_from_slice(&body);
                return Ok(bad(message, header));
            }
            Ok(Frame::Body { header, body })
        }
    }
}

/// A header that frames nothing.
fn bad(message: String, header: Vec<u8>) -> Frame {
    Frame::Bad {
        message,
        unframed: unframed(header),
    }
}

/// Where the next frame is looked for after a frame that held nothing: from its second byte on
/// (at least one byte is always skipped, so resynchronising ends).
fn unframed(mut bytes: Vec<u8>) -> Vec<u8> {
    if !bytes.is_empty() {
        bytes.remove(0);
    }
    bytes
}

/// A body as a message, or the error to answer it with.
fn parse(body: &[u8]) -> Input {
    let value: serde_json::Value = match serde_json::from_slice(body) {
        Ok(v) => v,
        Err(e) => {
            return Input::Malformed {
                id: None,
                code: ErrorCode::ParseError,
                message: format!("the message is not JSON: {e}"),
            };
        }
    };
    let id = value
        .get("id")
        .and_then(|id| serde_json::from_value::<RequestId>(id.clone()).ok());
    match serde_json::from_value::<Message>(value) {
        Ok(m) => Input::Message(m),
        Err(e) => Input::Malformed {
            id,
            code: ErrorCode::InvalidRequest,
            message: format!("not a JSON-RPC request, response or notification: {e}"),
        },
    }
}

/// Writes messages, each framed and flushed.
pub struct Writer<W: Write> {
    out: W,
}

impl<W: Write> Writer<W> {
    pub fn new(out: W) -> Self {
        Self { out }
    }

    pub fn send(&mut self, message: impl Into<Message>) -> io::Result<()> {
        message.into().write(&mut self.out)
    }

    /// An error response; with no id (the request's could not be read) its `id` is null.
    pub fn send_error(
        &mut self,
        id: Option<RequestId>,
        code: ErrorCode,
        message: String,
    ) -> io::Result<()> {
        match id {
            Some(id) => self.send(Response::new_err(id, code as i32, message)),
            None => {
                let body = serde_json::json!({
                    "jsonrpc": "2.0",
                    "id": null,
                    "error": { "code": code as i32, "message": message },
                })
                .to_string();
                write!(self.out, "Content-Length: {}\r\n\r\n{body}", body.len())?;
                self.out.flush()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frames(bytes: &[u8]) -> Vec<Input> {
        spawn_reader(io::Cursor::new(bytes.to_vec()))
            .iter()
            .collect()
    }

    fn framed(body: &str) -> String {
        format!("Content-Length: {}\r\n\r\n{body}", body.len())
    }

    #[test]
    fn bad_frames_become_errors_and_reading_goes_on() {
        let mut bytes = String::new();
        bytes += "X-Nonsense\r\n\r\n";
        bytes += &framed("{not json");
        bytes += &framed(r#"{"jsonrpc":"2.0","id":7}"#);
        bytes += "Content-Length: 99999999999\r\n\r\n";
        bytes += &framed(r#"{"jsonrpc":"2.0","id":1,"method":"shutdown"}"#);
        let got = frames(bytes.as_bytes());
        assert_eq!(got.len(), 4, "{got:?}");
        assert!(matches!(
            &got[0],
            Input::Malformed {
                id: None,
                code: ErrorCode::ParseError,
                ..
            }
        ));
        assert!(matches!(
            &got[1],
            Input::Malformed {
                code: ErrorCode::ParseError,
                ..
            }
        ));
        assert!(matches!(
            &got[2],
            Input::Malformed { id: Some(id), code: ErrorCode::InvalidRequest, .. } if *id == RequestId::from(7)
        ));
        // The absurd length swallows the rest of the stream, which then ends: no message is
        // invented from it.
        assert!(matches!(&got[3], Input::Malformed { .. }));
    }

    /// The methods of the messages read, `parse error` for each malformed frame.
    fn methods(bytes: &[u8]) -> Vec<String> {
        frames(bytes)
            .iter()
            .map(|input| match input {
                Input::Message(Message::Request(r)) => r.method.clone(),
                Input::Message(Message::Notification(n)) => n.method.clone(),
                Input::Message(Message::Response(_)) => "response".into(),
                Input::Malformed {
                    code: ErrorCode::ParseError,
                    ..
                } => "parse error".into(),
                Input::Malformed { .. } => "invalid request".into(),
            })
            .collect()
    }

    fn request(id: i32, method: &str) -> String {
        framed(&format!(
            r#"{{"jsonrpc":"2.0","id":{id},"method":"{method}","params":{{}}}}"#
        ))
    }

    #[test]
    fn after_a_wrong_content_length_the_next_frames_are_read() {
        let body = r#"{"jsonrpc":"2.0","method":"initialized","params":{}}"#;
        let next = request(1, "initialize") + &request(2, "shutdown");
        for delta in [-3i64, -1, 1, 2, 40] {
            let length = body.len() as i64 + delta;
            let bytes = format!("Content-Length: {length}\r\n\r\n{body}{next}");
            assert_eq!(
                methods(bytes.as_bytes()),
                ["parse error", "initialize", "shutdown"],
                "a length off by {delta}"
            );
        }
        // Junk between frames, a header glued to the junk, and lower-case header names.
        let bytes = format!(
            "Content-Length: 5\r\n\r\n{{\"a\":junk here}}content-length: 0\r\n\r\n{}",
            request(3, "initialize")
        );
        assert_eq!(
            methods(bytes.as_bytes()),
            ["parse error", "parse error", "initialize"]
        );
        // A header line without the blank line that ends the header runs on into the next
        // frame's header, and the body is read from the next frame's body: that frame is found
        // again in the bad one's header (found by tests/fuzz_lsp.rs).
        let body = r#"{"jsonrpc":"2.0","method":"x"}"#;
        let bytes = format!(
            "Content-Length: {}\r\n{body}{}",
            body.len(),
            request(5, "initialize")
        );
        assert_eq!(methods(bytes.as_bytes()), ["parse error", "initialize"]);
        // The input ends inside a body whose length runs past the frames after it: they are
        // read (found by tests/fuzz_lsp.rs).
        let bytes = format!(
            "Content-Length: 1000000\r\n\r\n{{{}",
            request(6, "initialize")
        );
        assert_eq!(methods(bytes.as_bytes()), ["parse error", "initialize"]);
        // A header that never ends is skipped to the next frame too.
        let bytes = format!(
            "{}\r\n{}",
            "x".repeat(MAX_HEADER + 10),
            request(4, "initialize")
        );
        assert_eq!(methods(bytes.as_bytes()), ["parse error", "initialize"]);
    }

    #[test]
    fn an_error_without_id_has_a_null_id() {
        let mut w = Writer::new(Vec::new());
        w.send_error(None, ErrorCode::ParseError, "bad".into())
            .unwrap();
        let text = String::from_utf8(w.out).unwrap();
        let body = text.split("\r\n\r\n").nth(1).unwrap();
        let v: serde_json::Value = serde_json::from_str(body).unwrap();
        assert_eq!(v["id"], serde_json::Value::Null);
        assert_eq!(v["error"]["code"], -32700);
    }
}
