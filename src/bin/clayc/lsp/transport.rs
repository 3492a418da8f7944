//! JSON-RPC over a byte stream with `Content-Length` framing, tolerant of what a client gets
//! wrong: lsp-server's own stdio transport ends the connection at the first body that is not
//! a message, where the protocol wants an error response (`ParseError`, `InvalidRequest`) and
//! the server going on. Messages are lsp-server's; only the framing is ours.

use std::io::{self, BufRead, Read, Write};
use std::sync::mpsc;

use lsp_server::{ErrorCode, Message, RequestId, Response};

/// A body larger than this is skipped (and answered with an error), never allocated.
const MAX_BODY: usize = 256 << 20;
/// A header line longer than this is not a header.
const MAX_HEADER_LINE: u64 = 64 << 10;

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
    Body(Vec<u8>),
    Bad(String),
    End,
}

/// Reads frames on a thread of its own until the stream ends (or the `exit` notification),
/// so the server can wait for input with a timeout (the diagnostics' debounce).
pub fn spawn_reader<R: BufRead + Send + 'static>(mut input: R) -> mpsc::Receiver<Input> {
    let (tx, rx) = mpsc::channel();
    std::thread::Builder::new()
        .name("lsp-reader".into())
        .spawn(move || {
            loop {
                let item = match read_frame(&mut input) {
                    Ok(Frame::Body(body)) => parse(&body),
                    Ok(Frame::Bad(message)) => Input::Malformed {
                        id: None,
                        code: ErrorCode::ParseError,
                        message,
                    },
                    Ok(Frame::End) | Err(_) => break,
                };
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

fn read_frame(input: &mut impl BufRead) -> io::Result<Frame> {
    let mut length: Option<Result<usize, String>> = None;
    let mut bad_header: Option<String> = None;
    let mut seen_header = false;
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
        None => Ok(Frame::Bad(bad_header.unwrap_or_else(|| {
            "a message without a Content-Length header".into()
        }))),
        Some(Err(message)) => Ok(Frame::Bad(message)),
        Some(Ok(n)) if n > MAX_BODY => {
            io::copy(&mut input.by_ref().take(n as u64), &mut io::sink())?;
            Ok(Frame::Bad(format!(
                "a message of {n} bytes (at most {MAX_BODY})"
            )))
        }
        Some(Ok(n)) => {
            let mut body = vec![0; n];
            match input.read_exact(&mut body) {
                Ok(()) => Ok(Frame::Body(body)),
                Err(e) if e.kind() == io::ErrorKind::UnexpectedEof => Ok(Frame::End),
                Err(e) => Err(e),
            }
        }
    }
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
        bytes += &framed("{not json");
        bytes += "X-Nonsense\r\n\r\n";
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
