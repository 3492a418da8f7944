//! `clayc lsp` on grammar parameters (`param NAME = DEFAULT in LO..HI`, issue 39), driven as
//! an editor drives it: the real binary, JSON-RPC with `Content-Length` framing. A hover on a
//! parameter's name, at its declaration or a use, shows its value, default and range; where a
//! number goes, completion offers the parameters as it offers `let` constants, with their
//! value and range as detail, also while the text does not parse. Every wait has a generous
//! bound, so a hang fails the test; nothing here measures time.

use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use serde_json::{Value, json};

const PATIENCE: Duration = Duration::from_secs(60);
const URI: &str = "file:///grammars/fence.clay";

/// The fence of docs/language.md: two parameters, a `let` that uses one.
const FENCE: &str = "\
param bays = 6 in 2..40 // a chain count
param bay_width = 2 in 1..4 // metres
param lean = 0.5 // no range
let post = bay_width / 10

site type rail

piece bay {
    vertex sw (0, 0)
    vertex se (bay_width, lean * 0)
    vertex ne (bay_width, post)
    vertex nw (0, post)
    edges sw-se-ne-nw-sw, sw-ne
    site west: rail [nw, sw] out (-1, 0)
    site east: rail [se, ne] out (1, 0)
}

stretch bay from west to east

model {
    fence = chain bay x bays at (0, 0)
}
";

fn at(text: &str, needle: &str, nth: usize, into: usize) -> usize {
    text.match_indices(needle)
        .nth(nth)
        .unwrap_or_else(|| panic!("no {nth}th `{needle}`"))
        .0
        + into
}

fn pos(text: &str, offset: usize) -> Value {
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    json!({
        "line": text[..offset].matches('\n').count(),
        "character": text[line_start..offset].encode_utf16().count(),
    })
}

fn at_pos(text: &str, offset: usize) -> Value {
    at_pos_in(URI, text, offset)
}

fn at_pos_in(uri: &str, text: &str, offset: usize) -> Value {
    json!({ "textDocument": { "uri": uri }, "position": pos(text, offset) })
}

struct Client {
    child: Child,
    stdin: Option<ChildStdin>,
    messages: mpsc::Receiver<Value>,
    next_id: i64,
}

impl Client {
    fn start() -> Self {
        let mut child = Command::new(env!("CARGO_BIN_EXE_clayc"))
            .arg("lsp")
            .env(
                "CLAY_FOLLOW_DIR",
                std::env::temp_dir().join("clay-lsp-tests-follow-nobody"),
            )
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("clayc lsp starts");
        let stdin = child.stdin.take();
        let mut stdout = BufReader::new(child.stdout.take().unwrap());
        let (tx, messages) = mpsc::channel();
        std::thread::spawn(move || {
            loop {
                let mut length = None;
                loop {
                    let mut line = String::new();
                    if stdout.read_line(&mut line).unwrap_or(0) == 0 {
                        return;
                    }
                    let line = line.trim_end();
                    if line.is_empty() {
                        break;
                    }
                    if let Some(n) = line.strip_prefix("Content-Length: ") {
                        length = Some(n.parse::<usize>().unwrap());
                    }
                }
                let mut body = vec![0; length.expect("a Content-Length header")];
                stdout.read_exact(&mut body).unwrap();
                let value: Value = serde_json::from_slice(&body).expect("the server sends JSON");
                if tx.send(value).is_err() {
                    return;
                }
            }
        });
        let mut c = Self {
            child,
            stdin,
            messages,
            next_id: 1,
        };
        let init = c.request("initialize", json!({ "capabilities": {} }));
        assert!(init["result"]["capabilities"].is_object(), "{init}");
        c.notify("initialized", json!({}));
        c
    }

    fn send(&mut self, message: &Value) {
        let body = message.to_string();
        let stdin = self.stdin.as_mut().expect("stdin is open");
        write!(stdin, "Content-Length: {}\r\n\r\n{body}", body.len()).unwrap();
        stdin.flush().unwrap();
    }

    fn notify(&mut self, method: &str, params: Value) {
        self.send(&json!({ "jsonrpc": "2.0", "method": method, "params": params }));
    }

    fn request(&mut self, method: &str, params: Value) -> Value {
        let id = json!(self.next_id);
        self.next_id += 1;
        self.send(&json!({ "jsonrpc": "2.0", "id": id, "method": method, "params": params }));
        loop {
            let m = self
                .messages
                .recv_timeout(PATIENCE)
                .expect("the server answers in time");
            if m.get("method").is_none() && m["id"] == id {
                return m;
            }
        }
    }

    fn result(&mut self, method: &str, params: Value) -> Value {
        let r = self.request(method, params);
        assert!(r.get("error").is_none(), "{method}: {r}");
        r["result"].clone()
    }

    fn open(&mut self, text: &str) {
        self.open_at(URI, text);
    }

    fn open_at(&mut self, uri: &str, text: &str) {
        self.notify(
            "textDocument/didOpen",
            json!({ "textDocument": { "uri": uri, "languageId": "clay", "version": 1, "text": text } }),
        );
    }

    fn change(&mut self, version: i32, text: &str) {
        self.notify(
            "textDocument/didChange",
            json!({
                "textDocument": { "uri": URI, "version": version },
                "contentChanges": [{ "text": text }],
            }),
        );
    }

    fn hover(&mut self, text: &str, offset: usize) -> String {
        let hover = self.result("textDocument/hover", at_pos(text, offset));
        hover["contents"]["value"]
            .as_str()
            .unwrap_or_else(|| panic!("a hover at {offset}: {hover}"))
            .to_string()
    }

    /// The completions at `offset`: label to (kind, detail).
    fn completions(&mut self, text: &str, offset: usize) -> Vec<(String, Value)> {
        let list = self.result("textDocument/completion", at_pos(text, offset));
        let items = list
            .as_array()
            .or_else(|| list["items"].as_array())
            .unwrap();
        items
            .iter()
            .map(|i| (i["label"].as_str().unwrap().to_string(), i.clone()))
            .collect()
    }
}

impl Drop for Client {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn detail<'a>(items: &'a [(String, Value)], label: &str) -> &'a str {
    let (_, item) = items
        .iter()
        .find(|(l, _)| l == label)
        .unwrap_or_else(|| panic!("`{label}` is offered: {items:?}"));
    item["detail"].as_str().unwrap_or("")
}

#[test]
fn a_parameters_hover_shows_its_value_default_and_range_at_its_declaration_and_uses() {
    let mut c = Client::start();
    c.open(FENCE);
    let declaration = c.hover(FENCE, at(FENCE, "param bays", 0, 7));
    assert!(
        declaration.contains("value `6`, default `6`, range `2..40`"),
        "{declaration}"
    );
    assert!(declaration.contains("--param bays=VALUE"), "{declaration}");
    let used = c.hover(FENCE, at(FENCE, "x bays", 0, 3));
    assert!(
        used.contains("value `6`, default `6`, range `2..40`"),
        "{used}"
    );
    let width = c.hover(FENCE, at(FENCE, "(bay_width, post)", 0, 2));
    assert!(
        width.contains("value `2`, default `2`, range `1..4`"),
        "{width}"
    );
    let lean = c.hover(FENCE, at(FENCE, "lean * 0", 0, 1));
    assert!(
        lean.contains("value `0.5`, default `0.5`, range any finite number"),
        "{lean}"
    );
    // A `let` is no parameter: its hover has its value only.
    let post = c.hover(FENCE, at(FENCE, "let post", 0, 5));
    assert!(post.contains("= `0.2`"), "{post}");
    assert!(!post.contains("parameter"), "{post}");
}

#[test]
fn completion_offers_the_parameters_where_a_number_goes_with_their_range() {
    let mut c = Client::start();
    c.open(FENCE);
    // A chain's count.
    let count = c.completions(FENCE, at(FENCE, "x bays", 0, 2));
    assert_eq!(
        detail(&count, "bays"),
        "parameter = 6 (default 6, range 2..40)"
    );
    assert_eq!(
        detail(&count, "bay_width"),
        "parameter = 2 (default 2, range 1..4)"
    );
    assert_eq!(
        detail(&count, "lean"),
        "parameter = 0.5 (default 0.5, range any finite number)"
    );
    // The `let` is offered as before, with its value.
    assert_eq!(detail(&count, "post"), "= 0.2");
    // A coordinate, as the `let` constants are.
    let coordinate = c.completions(FENCE, at(FENCE, "vertex ne (", 0, 11));
    assert!(detail(&coordinate, "bays").starts_with("parameter = 6"));
    // Not where a site type goes.
    let site = c.completions(FENCE, at(FENCE, "west: rail", 0, 6));
    assert!(site.iter().all(|(l, _)| l != "bays"), "{site:?}");
}

#[test]
fn while_the_text_does_not_parse_the_last_parsed_parameters_are_offered() {
    let mut c = Client::start();
    c.open(FENCE);
    // The analysis of the good text first.
    let _ = c.hover(FENCE, at(FENCE, "param bays", 0, 7));
    let marker = "    vertex nw (0, post)\n";
    let typing = FENCE.replace(marker, &format!("{marker}    vertex mid (\n"));
    c.change(2, &typing);
    let end = at(&typing, "vertex mid (", 0, 12);
    let offered = c.completions(&typing, end);
    assert_eq!(
        detail(&offered, "bays"),
        "parameter = 6 (default 6, range 2..40)"
    );
}

#[test]
fn an_imported_parameter_is_hovered_and_offered_with_its_range() {
    let dir = std::env::temp_dir().join(format!("clay-lsp-params-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("lib.clay"),
        "let half = 0.5\nparam gap = 0.25 in 0..half\n",
    )
    .unwrap();
    let text = format!(
        "import \"lib.clay\"\n{}",
        FENCE.replace("(bay_width, post)", "(bay_width + gap, post)")
    );
    let uri = format!("file://{}", dir.join("main.clay").display());
    let mut c = Client::start();
    c.open_at(&uri, &text);
    let hover = c.result(
        "textDocument/hover",
        at_pos_in(&uri, &text, at(&text, "+ gap", 0, 3)),
    );
    let md = hover["contents"]["value"].as_str().unwrap_or_default();
    assert!(
        md.contains("value `0.25`, default `0.25`, range `0..0.5`"),
        "{hover}"
    );
    let list = c.result(
        "textDocument/completion",
        at_pos_in(&uri, &text, at(&text, "x bays", 0, 2)),
    );
    let gap = (list.as_array().unwrap().iter())
        .find(|i| i["label"] == "gap")
        .unwrap_or_else(|| panic!("gap is offered: {list}"));
    assert_eq!(
        gap["detail"],
        "parameter = 0.25 (default 0.25, range 0..0.5)"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
