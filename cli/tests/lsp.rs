//! `clayc lsp` (issue 19) driven as an editor drives it: the real binary, JSON-RPC with
//! `Content-Length` framing over its stdin and stdout. Every wait for the server has a generous
//! bound, so a hang fails the test instead of blocking it; nothing here measures time.

use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Child, ChildStdin, Command, ExitStatus, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use serde_json::{Value, json};

/// The longest wait for one message (a debug build on a busy shared machine).
const PATIENCE: Duration = Duration::from_secs(60);
const URI: &str = "file:///grammars/wall.clay";

fn wall() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../grammars/wall.clay"
    ))
    .unwrap()
}

/// The byte offset of the `nth` occurrence of `needle`, plus `into` bytes.
fn at(text: &str, needle: &str, nth: usize, into: usize) -> usize {
    text.match_indices(needle)
        .nth(nth)
        .unwrap_or_else(|| panic!("no {nth}th `{needle}`"))
        .0
        + into
}

/// The protocol position of a byte offset, counted here independently of the server: the
/// line, and the UTF-16 code units before the offset on it.
fn pos(text: &str, offset: usize) -> Value {
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    json!({
        "line": text[..offset].matches('\n').count(),
        "character": text[line_start..offset].encode_utf16().count(),
    })
}

fn range(text: &str, start: usize, end: usize) -> Value {
    json!({ "start": pos(text, start), "end": pos(text, end) })
}

/// The byte offset of a protocol position.
fn offset(text: &str, p: &Value) -> usize {
    let line = p["line"].as_u64().unwrap() as usize;
    let col = p["character"].as_u64().unwrap() as usize;
    let start: usize = text.split_inclusive('\n').take(line).map(str::len).sum();
    let mut units = 0;
    for (i, c) in text[start..].char_indices() {
        if units >= col || c == '\n' {
            return start + i;
        }
        units += c.len_utf16();
    }
    text.len()
}

/// Applies text edits (`[{range, newText}]`) to `text`.
fn apply(text: &str, edits: &[Value]) -> String {
    let mut spans: Vec<(usize, usize, &str)> = edits
        .iter()
        .map(|e| {
            (
                offset(text, &e["range"]["start"]),
                offset(text, &e["range"]["end"]),
                e["newText"].as_str().unwrap(),
            )
        })
        .collect();
    spans.sort_by_key(|s| std::cmp::Reverse(s.0));
    let mut out = text.to_string();
    for (a, b, with) in spans {
        out.replace_range(a..b, with);
    }
    out
}

fn doc() -> Value {
    json!({ "uri": URI })
}

fn at_pos(text: &str, offset: usize) -> Value {
    json!({ "textDocument": doc(), "position": pos(text, offset) })
}

/// A hover on wall.clay's `chain brick` (`text`) is answered with the piece.
fn hover_shows_the_brick(c: &mut Client, text: &str) {
    let brick = at(text, "chain brick", 0, 7);
    let hover = c.result("textDocument/hover", at_pos(text, brick));
    assert!(
        hover["contents"]["value"]
            .as_str()
            .unwrap()
            .contains("piece brick"),
        "{hover}"
    );
}

struct Client {
    child: Child,
    stdin: Option<ChildStdin>,
    messages: mpsc::Receiver<Value>,
    /// Notifications read while waiting for something else.
    stash: Vec<Value>,
    next_id: i64,
}

impl Client {
    fn spawn() -> Self {
        // No following Clay editor: a folder that does not exist.
        Self::spawn_following(&std::env::temp_dir().join("clay-lsp-tests-follow-nobody"))
    }

    /// A server whose channel to a following Clay editor is the folder `follow`.
    fn spawn_following(follow: &std::path::Path) -> Self {
        Self::spawn_in(follow, &[])
    }

    /// A server started with `clayc lsp ARGS...`.
    fn spawn_with(args: &[&str]) -> Self {
        Self::spawn_in(
            &std::env::temp_dir().join("clay-lsp-tests-follow-nobody"),
            args,
        )
    }

    fn spawn_in(follow: &std::path::Path, args: &[&str]) -> Self {
        let mut child = Command::new(env!("CARGO_BIN_EXE_clayc"))
            .arg("lsp")
            .args(args)
            .env("CLAY_FOLLOW_DIR", follow)
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
        Self {
            child,
            stdin,
            messages,
            stash: Vec::new(),
            next_id: 1,
        }
    }

    /// A server past `initialize` and `initialized`.
    fn start() -> Self {
        Self::initialised(Self::spawn())
    }

    fn initialised(mut c: Self) -> Self {
        let init = c.request("initialize", json!({ "capabilities": {} }));
        assert!(init["result"]["capabilities"].is_object(), "{init}");
        c.notify("initialized", json!({}));
        c
    }

    fn send_raw(&mut self, bytes: &[u8]) {
        let stdin = self.stdin.as_mut().expect("stdin is open");
        stdin.write_all(bytes).unwrap();
        stdin.flush().unwrap();
    }

    fn send(&mut self, message: &Value) {
        let body = message.to_string();
        self.send_raw(format!("Content-Length: {}\r\n\r\n{body}", body.len()).as_bytes());
    }

    fn notify(&mut self, method: &str, params: Value) {
        self.send(&json!({ "jsonrpc": "2.0", "method": method, "params": params }));
    }

    fn recv(&mut self) -> Value {
        self.messages
            .recv_timeout(PATIENCE)
            .expect("the server answers in time")
    }

    /// The response to a request with `id` (notifications meanwhile are kept).
    fn response(&mut self, id: &Value) -> Value {
        loop {
            let m = self.recv();
            if m.get("method").is_none() && &m["id"] == id {
                return m;
            }
            self.stash.push(m);
        }
    }

    /// Sends a request and returns the whole response (`result` or `error`).
    fn request(&mut self, method: &str, params: Value) -> Value {
        let id = json!(self.next_id);
        self.next_id += 1;
        self.send(&json!({ "jsonrpc": "2.0", "id": id, "method": method, "params": params }));
        self.response(&id)
    }

    fn result(&mut self, method: &str, params: Value) -> Value {
        let r = self.request(method, params);
        assert!(r.get("error").is_none(), "{method}: {r}");
        r["result"].clone()
    }

    /// The next diagnostics published for the document.
    fn diagnostics(&mut self) -> Value {
        let is_ours = |m: &Value| {
            m["method"] == "textDocument/publishDiagnostics" && m["params"]["uri"] == URI
        };
        if let Some(i) = self.stash.iter().position(is_ours) {
            return self.stash.remove(i)["params"].clone();
        }
        loop {
            let m = self.recv();
            if is_ours(&m) {
                return m["params"].clone();
            }
            self.stash.push(m);
        }
    }

    fn open(&mut self, text: &str) -> Value {
        self.notify(
            "textDocument/didOpen",
            json!({ "textDocument": { "uri": URI, "languageId": "clay", "version": 1, "text": text } }),
        );
        self.diagnostics()
    }

    fn change(&mut self, version: i32, text: &str) {
        self.change_uri(URI, version, text);
    }

    fn change_uri(&mut self, uri: &str, version: i32, text: &str) {
        self.notify(
            "textDocument/didChange",
            json!({
                "textDocument": { "uri": uri, "version": version },
                "contentChanges": [{ "text": text }],
            }),
        );
    }

    /// Closes stdin and waits for the process to end (looking at most `PATIENCE` / 50 ms
    /// times: a guard against a hang, not a measure).
    fn wait(mut self) -> ExitStatus {
        drop(self.stdin.take());
        let step = Duration::from_millis(50);
        for _ in 0..PATIENCE.as_millis() / step.as_millis() {
            if let Some(status) = self.child.try_wait().unwrap() {
                return status;
            }
            std::thread::sleep(step);
        }
        panic!("the server did not exit");
    }

    fn shutdown_and_exit(mut self) -> ExitStatus {
        let r = self.request("shutdown", Value::Null);
        assert_eq!(r["result"], Value::Null, "{r}");
        assert!(r.get("error").is_none(), "{r}");
        self.notify("exit", Value::Null);
        self.wait()
    }
}

impl Drop for Client {
    fn drop(&mut self) {
        // A failed test leaves no server behind.
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[test]
fn a_typo_is_e011_at_its_range_its_fix_is_a_code_action_and_fixing_clears_it() {
    let good = wall();
    let typo = good.replace("site west: joint", "site west: jiont");
    let mut c = Client::start();
    let published = c.open(&typo);
    assert_eq!(published["version"], 1);
    let diags = published["diagnostics"].as_array().unwrap();
    assert_eq!(diags.len(), 1, "{diags:?}");
    let d = &diags[0];
    let start = at(&typo, "jiont", 0, 0);
    assert_eq!(d["range"], range(&typo, start, start + 5));
    assert_eq!(d["code"], "E011");
    assert_eq!(d["severity"], 1);
    assert_eq!(d["source"], "clay");
    // No documentation link: there is no public address to link (docs/editors.md).
    assert!(d.get("codeDescription").is_none(), "{d}");
    let message = d["message"].as_str().unwrap();
    assert!(
        message.starts_with("unknown site type `jiont`"),
        "{message}"
    );
    assert!(
        message.contains("\nhelp: did you mean `joint`?"),
        "{message}"
    );

    // The quick fix for it.
    let actions = c.result(
        "textDocument/codeAction",
        json!({
            "textDocument": doc(),
            "range": d["range"],
            "context": { "diagnostics": [d] },
        }),
    );
    let actions = actions.as_array().unwrap();
    assert_eq!(actions.len(), 1, "{actions:?}");
    assert_eq!(actions[0]["kind"], "quickfix");
    assert_eq!(actions[0]["title"], "replace with `joint`");
    let edits = actions[0]["edit"]["changes"][URI].as_array().unwrap();
    assert_eq!(apply(&typo, edits), good);

    // Fixed: the diagnostics are cleared.
    c.change(2, &good);
    let published = c.diagnostics();
    assert_eq!(published["version"], 2);
    assert_eq!(published["diagnostics"], json!([]));

    // Closed with an error in it: its diagnostics are cleared, and it is no longer served.
    c.change(3, &typo);
    assert_eq!(c.diagnostics()["diagnostics"].as_array().unwrap().len(), 1);
    c.notify("textDocument/didClose", json!({ "textDocument": doc() }));
    assert_eq!(c.diagnostics()["diagnostics"], json!([]));
    let gone = c.request("textDocument/hover", at_pos(&typo, 0));
    assert_eq!(gone["error"]["code"], -32602, "{gone}");
    assert!(c.shutdown_and_exit().success());
}

#[test]
fn columns_are_utf16_code_units_after_non_ascii_text_on_the_line() {
    let typo = wall().replace("    site west: joint", "    /* é😀 */ site west: jiont");
    let mut c = Client::start();
    let published = c.open(&typo);
    let d = &published["diagnostics"][0];
    let start = at(&typo, "jiont", 0, 0);
    let line_start = typo[..start].rfind('\n').unwrap() + 1;
    let before = &typo[line_start..start];
    // UTF-16 units, not bytes or characters: é is 1 unit (2 bytes), the emoji 2 (4 bytes).
    assert_eq!(before.encode_utf16().count(), before.len() - 3);
    assert_eq!(before.encode_utf16().count(), before.chars().count() + 1);
    assert_eq!(
        d["range"]["start"]["character"],
        before.encode_utf16().count()
    );
    assert_eq!(d["range"], range(&typo, start, start + 5));
    // A hover just after the emoji, on the same line, lands on the site's name.
    let west = at(&typo, "site west", 0, "site w".len());
    let hover = c.result("textDocument/hover", at_pos(&typo, west));
    assert_eq!(hover["range"], range(&typo, west - 1, west + 3), "{hover}");
}

#[test]
fn hover_definition_references_and_highlights_of_a_piece() {
    let text = wall();
    let mut c = Client::start();
    assert_eq!(c.open(&text)["diagnostics"], json!([]));
    let brick_use = at(&text, "chain brick", 0, "chain b".len());
    let hover = c.result("textDocument/hover", at_pos(&text, brick_use));
    assert_eq!(hover["contents"]["kind"], "markdown");
    let md = hover["contents"]["value"].as_str().unwrap();
    assert!(md.contains("piece brick"), "{md}");
    assert!(md.contains("**4 vertices**"), "{md}");
    assert!(md.contains("`west: joint [nw, sw] out (-1, 0)`"), "{md}");
    assert!(md.contains("stretch brick from west to east"), "{md}");
    let chain_brick = at(&text, "chain brick", 0, "chain ".len());
    assert_eq!(hover["range"], range(&text, chain_brick, chain_brick + 5));

    let decl = at(&text, "piece brick", 0, "piece ".len());
    let def = c.result("textDocument/definition", at_pos(&text, brick_use));
    assert_eq!(def["uri"], URI);
    assert_eq!(def["range"], range(&text, decl, decl + 5));

    let mut params = at_pos(&text, decl + 1);
    params["context"] = json!({ "includeDeclaration": true });
    let refs = c.result("textDocument/references", params.clone());
    let ranges: Vec<&Value> = refs
        .as_array()
        .unwrap()
        .iter()
        .map(|l| &l["range"])
        .collect();
    let stretch_brick = at(&text, "stretch brick", 0, "stretch ".len());
    assert_eq!(
        ranges,
        vec![
            &range(&text, decl, decl + 5),
            &range(&text, stretch_brick, stretch_brick + 5),
            &range(&text, chain_brick, chain_brick + 5),
        ]
    );
    params["context"] = json!({ "includeDeclaration": false });
    let refs = c.result("textDocument/references", params);
    assert_eq!(refs.as_array().unwrap().len(), 2);

    let lights = c.result("textDocument/documentHighlight", at_pos(&text, brick_use));
    let kinds: Vec<&Value> = lights
        .as_array()
        .unwrap()
        .iter()
        .map(|h| &h["kind"])
        .collect();
    // The declaration is written (3), the uses read (2).
    assert_eq!(kinds, vec![&json!(3), &json!(2), &json!(2)]);

    // Nothing to say about a keyword.
    let hover = c.result(
        "textDocument/hover",
        at_pos(&text, at(&text, "model", 0, 1)),
    );
    assert_eq!(hover, Value::Null);
}

#[test]
fn completion_after_a_site_colon_offers_the_site_types() {
    let text = wall();
    let mut c = Client::start();
    c.open(&text);
    let after = at(&text, "site west: ", 0, "site west: ".len());
    let list = c.result("textDocument/completion", at_pos(&text, after));
    let items = list.as_array().unwrap();
    let labels: Vec<&str> = items.iter().map(|i| i["label"].as_str().unwrap()).collect();
    assert_eq!(labels, vec!["joint"]);
    assert_eq!(items[0]["kind"], 8, "a site type is an interface");
    assert_eq!(items[0]["textEdit"]["newText"], "joint");
    assert_eq!(items[0]["textEdit"]["range"], range(&text, after, after));

    // A partly typed word is replaced.
    let partial = text.replace("chain brick x 8", "chain br");
    c.change(2, &partial);
    let end = at(&partial, "chain br", 0, "chain br".len());
    let list = c.result("textDocument/completion", at_pos(&partial, end));
    let item = &list.as_array().unwrap()[0];
    assert_eq!(item["label"], "brick");
    assert_eq!(item["kind"], 7, "a piece is a class");
    assert_eq!(item["textEdit"]["range"], range(&partial, end - 2, end));
}

#[test]
fn formatting_gives_what_clayc_fmt_prints() {
    let messy = wall()
        .replace("    vertex se (1, 0)", "vertex   se (1,0)")
        .replace(
            "stretch brick from west to east { min 2 }",
            "stretch brick from west to east {min 2}",
        );
    let mut fmt = Command::new(env!("CARGO_BIN_EXE_clayc"))
        .args(["fmt", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    fmt.stdin
        .take()
        .unwrap()
        .write_all(messy.as_bytes())
        .unwrap();
    let out = fmt.wait_with_output().unwrap();
    assert!(out.status.success());
    let expected = String::from_utf8(out.stdout).unwrap();
    assert_ne!(expected, messy);

    let mut c = Client::start();
    c.open(&messy);
    let params =
        json!({ "textDocument": doc(), "options": { "tabSize": 4, "insertSpaces": true } });
    let edits = c.result("textDocument/formatting", params.clone());
    assert_eq!(apply(&messy, edits.as_array().unwrap()), expected);
    // Formatted already: no edits. Not parsing: nothing (no edit, no error).
    c.change(2, &expected);
    assert_eq!(
        c.result("textDocument/formatting", params.clone()),
        json!([])
    );
    c.change(3, &expected.replace("model {", "model {{"));
    assert_eq!(c.result("textDocument/formatting", params), Value::Null);
}

#[test]
fn rename_of_brick_compiles_clean_and_a_bad_name_is_refused() {
    let text = wall();
    let mut c = Client::start();
    c.open(&text);
    let decl = at(&text, "piece brick", 0, "piece ".len());
    let prepared = c.result("textDocument/prepareRename", at_pos(&text, decl + 2));
    assert_eq!(prepared, range(&text, decl, decl + 5));
    let mut params = at_pos(&text, decl + 2);
    params["newName"] = json!("block");
    let edit = c.result("textDocument/rename", params.clone());
    let edits = edit["changes"][URI].as_array().unwrap();
    assert_eq!(edits.len(), 3);
    let renamed = apply(&text, edits);
    let compiled = clay_dsl::compile(&renamed, "wall.clay", &clay_dsl::CompileOptions::default())
        .expect("the renamed grammar compiles");
    assert!(compiled.warnings.is_empty(), "{:?}", compiled.warnings);
    assert_eq!(compiled.grammar.pieces[0].name, "block");
    for use_ in ["piece block {", "stretch block from", "chain block x"] {
        assert!(renamed.contains(use_), "{use_}");
    }

    params["newName"] = json!("piece");
    let refused = c.request("textDocument/rename", params);
    assert_eq!(refused["error"]["code"], -32803, "{refused}");
    assert!(
        refused["error"]["message"]
            .as_str()
            .unwrap()
            .contains("keyword"),
        "{refused}"
    );
    // Nothing to rename on a keyword.
    let prepared = c.result(
        "textDocument/prepareRename",
        at_pos(&text, at(&text, "model", 0, 1)),
    );
    assert_eq!(prepared, Value::Null);
}

#[test]
fn document_symbols_nest_semantic_tokens_decode_and_blocks_fold() {
    let text = wall();
    let mut c = Client::start();
    c.open(&text);
    let symbols = c.result(
        "textDocument/documentSymbol",
        json!({ "textDocument": doc() }),
    );
    let top: Vec<&str> = symbols
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(top, vec!["joint", "brick", "stretch brick", "model"]);
    let brick = &symbols[1];
    assert_eq!(brick["kind"], 5, "a piece is a class");
    let members: Vec<&str> = brick["children"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(members, vec!["sw", "se", "ne", "nw", "west", "east"]);
    let decl = at(&text, "piece brick", 0, "piece ".len());
    assert_eq!(brick["selectionRange"], range(&text, decl, decl + 5));
    assert_eq!(symbols[3]["children"][0]["name"], "wall");

    // The legend from initialize, then the tokens decoded against it.
    let mut fresh = Client::spawn();
    let init = fresh.request("initialize", json!({ "capabilities": {} }));
    let legend = &init["result"]["capabilities"]["semanticTokensProvider"]["legend"];
    let types: Vec<&str> = legend["tokenTypes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_str().unwrap())
        .collect();
    let tokens = c.result(
        "textDocument/semanticTokens/full",
        json!({ "textDocument": doc() }),
    );
    let data: Vec<u64> = tokens["data"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_u64().unwrap())
        .collect();
    assert!(!data.is_empty() && data.len().is_multiple_of(5));
    let lines: Vec<&str> = text.lines().collect();
    let (mut line, mut col) = (0usize, 0usize);
    let mut decoded = Vec::new();
    for t in data.chunks(5) {
        if t[0] > 0 {
            line += t[0] as usize;
            col = 0;
        }
        col += t[1] as usize;
        let units: Vec<u16> = lines[line].encode_utf16().collect();
        let word = String::from_utf16(&units[col..col + t[2] as usize]).unwrap();
        decoded.push((word, types[t[3] as usize], t[4]));
    }
    let has = |word: &str, ty: &str, modifiers: u64| {
        decoded
            .iter()
            .any(|(w, t, m)| w == word && *t == ty && *m == modifiers)
    };
    assert!(has("piece", "keyword", 0), "{decoded:?}");
    assert!(has("brick", "class", 1), "the declaration: {decoded:?}");
    assert!(has("brick", "class", 0), "a use: {decoded:?}");
    assert!(has("joint", "type", 0), "{decoded:?}");
    assert!(has("#b5651d", "string", 0), "{decoded:?}");
    assert!(has("0.97", "number", 0), "{decoded:?}");
    assert!(has("hysteresis", "parameter", 0), "{decoded:?}");
    assert!(
        decoded
            .iter()
            .any(|(w, t, _)| w.starts_with("// a darker") && *t == "comment")
    );

    let folds = c.result(
        "textDocument/foldingRange",
        json!({ "textDocument": doc() }),
    );
    let piece_line = text[..decl].matches('\n').count();
    let close_line = text[..at(&text, "\n}\n", 1, 1)].matches('\n').count();
    assert!(
        folds
            .as_array()
            .unwrap()
            .iter()
            .any(|f| f["startLine"] == piece_line
                && f["endLine"] == close_line - 1
                && f["kind"] == "region"),
        "the piece folds up to its closing brace: {folds}"
    );
    drop(fresh);
}

#[test]
fn a_syntax_error_mid_file_is_e001_and_queries_still_answer() {
    let good = wall();
    let broken = good.replace(
        "stretch brick from west to east { min 2 }",
        "stretch brick from west to { min 2 }",
    );
    let mut c = Client::start();
    assert_eq!(c.open(&good)["diagnostics"], json!([]));
    c.change(2, &broken);
    let published = c.diagnostics();
    assert_eq!(published["version"], 2);
    let diags = published["diagnostics"].as_array().unwrap();
    assert_eq!(diags.len(), 1, "{diags:?}");
    assert_eq!(diags[0]["code"], "E001");
    let error_line = broken[..at(&broken, "to { min", 0, 0)]
        .matches('\n')
        .count();
    assert_eq!(diags[0]["range"]["start"]["line"], error_line);

    // Before the error: the piece answers from the parsed prefix.
    let hover = c.result(
        "textDocument/hover",
        at_pos(&broken, at(&broken, "piece brick", 0, 7)),
    );
    let md = hover["contents"]["value"].as_str().unwrap();
    assert!(md.contains("4 vertices"), "{md}");
    // After it: the model answers from the last text that parsed, where it now lies.
    let wall_at = at(&broken, "wall = chain", 0, 0);
    let def = c.result("textDocument/definition", at_pos(&broken, wall_at + 1));
    assert_eq!(def["range"], range(&broken, wall_at, wall_at + 4));

    // A burst of changes, then a request: the request sees the last text, whose diagnostics
    // are published before its answer.
    for v in 3..8 {
        let text = if v == 7 {
            good.clone()
        } else {
            broken.replace("min 2", &format!("min {v}"))
        };
        c.change(v, &text);
    }
    let _ = c.result("textDocument/hover", at_pos(&good, 0));
    let last = c
        .stash
        .iter()
        .rev()
        .find(|m| m["method"] == "textDocument/publishDiagnostics")
        .expect("diagnostics before the answer")
        .clone();
    assert_eq!(last["params"]["version"], 7);
    assert_eq!(last["params"]["diagnostics"], json!([]));
}

#[test]
fn malformed_messages_and_unknown_methods_get_errors_and_the_server_goes_on() {
    let text = wall();
    let mut c = Client::spawn();
    // Before initialize: refused, not fatal.
    let early = c.request("textDocument/hover", at_pos(&text, 0));
    assert_eq!(early["error"]["code"], -32002, "{early}");
    let init = c.request("initialize", json!({ "capabilities": {} }));
    assert!(init["result"].is_object(), "{init}");
    c.notify("initialized", json!({}));
    c.open(&text);

    // A body that is not JSON: a parse error with a null id.
    c.send_raw(b"Content-Length: 9\r\n\r\n{\"id\": 1,");
    let m = c.recv();
    assert_eq!(m["error"]["code"], -32700, "{m}");
    assert_eq!(m["id"], Value::Null);
    // JSON that is no message: an invalid request, with its id.
    c.send(&json!({ "jsonrpc": "2.0", "id": 77 }));
    let m = c.response(&json!(77));
    assert_eq!(m["error"]["code"], -32600, "{m}");
    // Bad params.
    let bad = c.request("textDocument/hover", json!({ "textDocument": 5 }));
    assert_eq!(bad["error"]["code"], -32602, "{bad}");
    let bad = c.request("textDocument/completion", json!("nonsense"));
    assert_eq!(bad["error"]["code"], -32602, "{bad}");
    // A position far outside the text is clamped, not a crash.
    let far = c.request(
        "textDocument/hover",
        json!({ "textDocument": doc(), "position": { "line": 99999, "character": 99999 } }),
    );
    assert!(far.get("error").is_none(), "{far}");
    // A document that is not open.
    let closed = c.request(
        "textDocument/hover",
        json!({ "textDocument": { "uri": "file:///nowhere.clay" }, "position": { "line": 0, "character": 0 } }),
    );
    assert_eq!(closed["error"]["code"], -32602, "{closed}");
    // An unknown method.
    let unknown = c.request("clay/nonsense", json!({}));
    assert_eq!(unknown["error"]["code"], -32601, "{unknown}");
    // A notification with bad params and an unknown one: ignored.
    c.notify("textDocument/didChange", json!({ "contentChanges": 3 }));
    c.notify("clay/whatever", json!([1, 2]));

    // Still serving.
    hover_shows_the_brick(&mut c, &text);
    assert!(c.shutdown_and_exit().success());
}

#[test]
fn shutdown_then_exit_is_exit_code_0_and_exit_alone_is_1() {
    let c = Client::start();
    let status = c.shutdown_and_exit();
    assert_eq!(status.code(), Some(0));

    let mut c = Client::start();
    c.notify("exit", Value::Null);
    assert_eq!(c.wait().code(), Some(1));

    // After shutdown only exit is left: requests are refused.
    let mut c = Client::start();
    let _ = c.request("shutdown", Value::Null);
    let late = c.request("textDocument/hover", at_pos("", 0));
    assert_eq!(late["error"]["code"], -32600, "{late}");
    c.notify("exit", Value::Null);
    assert_eq!(c.wait().code(), Some(0));
}

#[test]
fn after_a_frame_with_a_wrong_content_length_the_next_request_is_answered() {
    let body = json!({ "jsonrpc": "2.0", "method": "initialized", "params": {} }).to_string();
    let parse_errors = |c: &Client| {
        c.stash
            .iter()
            .filter(|m| m["error"]["code"] == -32700 && m["id"] == Value::Null)
            .count()
    };
    // One byte too many: the body swallows the first byte of the `initialize` frame.
    let mut c = Client::spawn();
    c.send_raw(format!("Content-Length: {}\r\n\r\n{body}", body.len() + 1).as_bytes());
    let init = c.request("initialize", json!({ "capabilities": {} }));
    assert!(init["result"]["capabilities"].is_object(), "{init}");
    assert_eq!(parse_errors(&c), 1, "{:?}", c.stash);
    c.notify("initialized", json!({}));
    // One byte too few, the body's last byte left before the next frame.
    let text = wall();
    c.open(&text);
    c.send_raw(format!("Content-Length: {}\r\n\r\n{body}", body.len() - 1).as_bytes());
    hover_shows_the_brick(&mut c, &text);
    assert_eq!(parse_errors(&c), 2, "{:?}", c.stash);
    assert!(c.shutdown_and_exit().success());
}

/// Found by tests/fuzz_lsp.rs: a header line without the blank line that ends the header ran on
/// into the next frame's header, and the body was read from that frame's body; the reader
/// looked for the next frame only inside the body it had read, so the request was never
/// answered. It looks inside the bad frame's header too.
#[test]
fn after_a_header_without_its_blank_line_the_next_request_is_answered() {
    let body = json!({ "jsonrpc": "2.0", "method": "initialized", "params": {} }).to_string();
    let mut c = Client::spawn();
    // Shorter than the next frame's body, which it runs into.
    c.send_raw(format!("Content-Length: {}\r\n{body}", body.len()).as_bytes());
    let init = c.request("initialize", json!({ "capabilities": {} }));
    assert!(init["result"]["capabilities"].is_object(), "{init}");
    let parse_errors = c
        .stash
        .iter()
        .filter(|m| m["error"]["code"] == -32700 && m["id"] == Value::Null)
        .count();
    assert_eq!(parse_errors, 1, "{:?}", c.stash);
    assert!(c.shutdown_and_exit().success());
}

#[test]
fn closing_the_input_stops_the_server_with_exit_code_0() {
    // Nothing sent at all.
    assert_eq!(Client::spawn().wait().code(), Some(0));
    // Running with a document open, without `shutdown` or `exit`.
    let mut c = Client::start();
    c.open(&wall());
    assert_eq!(c.wait().code(), Some(0));
}

#[test]
fn an_analysis_past_its_timeout_is_reported_and_the_server_answers_on() {
    // A wall of 90,000 bricks takes far longer to analyse than the 50 ms this server allows
    // (about 0.3 s to check in a debug build), a plain wall far less (about 1 ms): with a
    // deadline of 1 ms, the plain wall's analysis was itself late on a loaded machine, and the
    // hover below failed (the compiler refuses a FIFO import, which would block for good,
    // before reading).
    let big = wall().replace("chain brick x 8", "chain brick x 90000");
    assert_ne!(big, wall());
    let uri = "file:///clay-lsp-late/main.clay";
    let mut c = Client::initialised(Client::spawn_with(&["--analysis-timeout-ms", "50"]));
    let published = c.open_as(uri, &big);
    assert_eq!(published["version"], 1, "{published}");
    let diags = published["diagnostics"].as_array().unwrap();
    assert_eq!(diags.len(), 1, "{published}");
    assert_eq!(diags[0]["severity"], 2, "a warning: {published}");
    let message = diags[0]["message"].as_str().unwrap();
    assert!(message.contains("analysis timed out"), "{message}");

    // The server answers on while that analysis runs: a request on another document.
    let text = wall();
    c.notify(
        "textDocument/didOpen",
        json!({ "textDocument": { "uri": URI, "languageId": "clay", "version": 1, "text": text } }),
    );
    let brick = at(&text, "chain brick", 0, 7);
    let answer = c.request("textDocument/hover", at_pos(&text, brick));
    assert!(answer.get("error").is_none(), "{answer}");

    // Once the late analysis ends, its diagnostics replace the warning.
    let late = c.published(uri, Some(1));
    assert_eq!(late["diagnostics"], json!([]), "{late}");
    assert!(c.shutdown_and_exit().success());
}

#[test]
fn every_advertised_capability_has_its_row_in_docs_editors_md() {
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/editors.md"))
        .unwrap();
    let mut c = Client::spawn();
    let init = c.request("initialize", json!({ "capabilities": {} }));
    let caps = init["result"]["capabilities"].as_object().unwrap();
    let method = |cap: &str| match cap {
        "positionEncoding" => "`initialize`",
        "textDocumentSync" => "`textDocument/didOpen`",
        "hoverProvider" => "`textDocument/hover`",
        "definitionProvider" => "`textDocument/definition`",
        "referencesProvider" => "`textDocument/references`",
        "documentHighlightProvider" => "`textDocument/documentHighlight`",
        "completionProvider" => "`textDocument/completion`",
        "documentFormattingProvider" => "`textDocument/formatting`",
        "documentRangeFormattingProvider" => "`textDocument/rangeFormatting`",
        "renameProvider" => "`textDocument/rename`",
        "documentSymbolProvider" => "`textDocument/documentSymbol`",
        "semanticTokensProvider" => "`textDocument/semanticTokens/full`",
        "foldingRangeProvider" => "`textDocument/foldingRange`",
        "codeActionProvider" => "`textDocument/codeAction`",
        other => panic!("a capability this test does not know: {other}"),
    };
    for cap in caps.keys() {
        let m = method(cap);
        assert!(
            doc.lines().any(|l| l.starts_with("| ") && l.contains(m)),
            "docs/editors.md has no row for {m} ({cap})"
        );
    }
}

#[test]
fn imports_are_read_from_the_documents_folder_on_disk() {
    // A folder with a space (escaped in the URI) holding a library and the grammar that
    // imports it: the server compiles the document as the file its URI names.
    let dir = std::env::temp_dir().join(format!("clay lsp {}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let lib = "site type joint\npiece brick {\n    vertex a (0, 0)\n    vertex b (1, 0)\n    \
               vertex c (1, 1)\n    edges a-b-c-a\n}\n";
    std::fs::write(dir.join("lib.clay"), lib).unwrap();
    let main = "import \"lib.clay\"\n\nmodel {\n    b = brick\n}\n";
    let uri = format!("file://{}/main.clay", dir.display()).replace(' ', "%20");
    let mut c = Client::start();
    c.notify(
        "textDocument/didOpen",
        json!({ "textDocument": { "uri": uri, "languageId": "clay", "version": 1, "text": main } }),
    );
    let published = loop {
        let m = c.recv();
        if m["method"] == "textDocument/publishDiagnostics" && m["params"]["uri"] == uri.as_str() {
            break m["params"].clone();
        }
    };
    assert_eq!(published["diagnostics"], json!([]), "{published}");

    // A mistake inside the library: shown on the document's import line, naming the place in
    // the library, which is the related information (with the library's own URI).
    std::fs::write(
        dir.join("lib.clay"),
        lib.replace("edges a-b-c-a", "edges a-b-c-d"),
    )
    .unwrap();
    c.notify(
        "textDocument/didChange",
        json!({
            "textDocument": { "uri": uri, "version": 2 },
            "contentChanges": [{ "text": format!("{main}\n") }],
        }),
    );
    let published = loop {
        let m = c.recv();
        if m["method"] == "textDocument/publishDiagnostics"
            && m["params"]["uri"] == uri.as_str()
            && m["params"]["version"] == 2
        {
            break m["params"].clone();
        }
    };
    let diags = published["diagnostics"].as_array().unwrap();
    assert_eq!(diags.len(), 1, "{diags:?}");
    let d = &diags[0];
    assert_eq!(d["code"], "E011");
    assert_eq!(d["range"]["start"], json!({ "line": 0, "character": 0 }));
    assert_eq!(d["range"]["end"], json!({ "line": 0, "character": 17 }));
    let message = d["message"].as_str().unwrap();
    assert!(
        message.contains("lib.clay:6:17: unknown vertex `d`"),
        "{message}"
    );
    let place = &d["relatedInformation"][0]["location"];
    assert!(
        place["uri"].as_str().unwrap().ends_with("/lib.clay"),
        "{place}"
    );
    assert!(
        place["uri"].as_str().unwrap().contains("clay%20lsp"),
        "{place}"
    );
    assert_eq!(
        place["range"]["start"],
        json!({ "line": 5, "character": 16 })
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A library declaring `brick` (with its site type and sites) and a grammar using it, in a
/// folder of their own; the URIs of both.
struct Library {
    dir: std::path::PathBuf,
    lib: String,
    main: String,
    lib_uri: String,
    main_uri: String,
}

const LIB: &str = "site type joint\n\npiece brick {\n    vertex sw (0, 0)\n    vertex se (1, 0)\n    \
                   vertex ne (1, 0.5)\n    vertex nw (0, 0.5)\n    edges sw-se-ne-nw-sw, sw-ne\n    \
                   site west: joint [nw, sw] out (-1, 0)\n    site east: joint [se, ne] out (1, 0)\n}\n";
const MAIN: &str = "import \"lib.clay\"\n\nstretch brick from west to east\n\nmodel {\n    wall = chain brick x 3\n}\n";

impl Library {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("clay-lsp-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("lib.clay"), LIB).unwrap();
        std::fs::write(dir.join("main.clay"), MAIN).unwrap();
        let uri = |f: &str| format!("file://{}/{f}", dir.display());
        Self {
            lib_uri: uri("lib.clay"),
            main_uri: uri("main.clay"),
            dir,
            lib: LIB.into(),
            main: MAIN.into(),
        }
    }
}

impl Drop for Library {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

impl Client {
    /// Opens `text` as `uri` and returns its first published diagnostics.
    fn open_as(&mut self, uri: &str, text: &str) -> Value {
        self.notify(
            "textDocument/didOpen",
            json!({ "textDocument": { "uri": uri, "languageId": "clay", "version": 1, "text": text } }),
        );
        self.published(uri, None)
    }

    /// The next diagnostics published for `uri` (of `version`, when given).
    fn published(&mut self, uri: &str, version: Option<i32>) -> Value {
        let is_it = |m: &Value| {
            m["method"] == "textDocument/publishDiagnostics"
                && m["params"]["uri"] == uri
                && version.is_none_or(|v| m["params"]["version"] == v)
        };
        if let Some(i) = self.stash.iter().position(is_it) {
            return self.stash.remove(i)["params"].clone();
        }
        loop {
            let m = self.recv();
            if is_it(&m) {
                return m["params"].clone();
            }
            self.stash.push(m);
        }
    }
}

fn at_in(uri: &str, text: &str, offset: usize) -> Value {
    json!({ "textDocument": { "uri": uri }, "position": pos(text, offset) })
}

#[test]
fn definition_hover_and_completion_reach_into_an_imported_file() {
    let l = Library::new("queries");
    let mut c = Client::start();
    assert_eq!(c.open_as(&l.main_uri, &l.main)["diagnostics"], json!([]));
    let brick_use = at(&l.main, "chain brick", 0, 6);

    // Definition: the library's URI, the range of the name in the library.
    let def = c.result(
        "textDocument/definition",
        at_in(&l.main_uri, &l.main, brick_use),
    );
    assert_eq!(def["uri"], l.lib_uri.as_str(), "{def}");
    let decl = at(&l.lib, "piece brick", 0, 6);
    assert_eq!(def["range"], range(&l.lib, decl, decl + 5));
    // A site of the imported piece, from the rule in the document.
    let west = at(&l.main, "from west", 0, 5);
    let def = c.result("textDocument/definition", at_in(&l.main_uri, &l.main, west));
    assert_eq!(def["uri"], l.lib_uri.as_str());
    let site = at(&l.lib, "site west", 0, 5);
    assert_eq!(def["range"], range(&l.lib, site, site + 4));

    // Hover: the imported declaration, its members, and which file it is in.
    let hover = c.result("textDocument/hover", at_in(&l.main_uri, &l.main, brick_use));
    let text = hover["contents"]["value"].as_str().unwrap();
    assert!(text.contains("piece brick"), "{text}");
    assert!(
        text.contains("`west: joint [nw, sw] out (-1, 0)`"),
        "{text}"
    );
    assert!(text.contains("/lib.clay`"), "{text}");
    assert_eq!(
        hover["range"],
        range(&l.main, brick_use, brick_use + 5),
        "{hover}"
    );

    // Completion: the imported piece after `chain`, its sites after `brick.`.
    let edited = l.main.replace("chain brick x 3", "chain b");
    c.change_uri(&l.main_uri, 2, &edited);
    let items = c.result(
        "textDocument/completion",
        at_in(&l.main_uri, &edited, at(&edited, "chain b", 0, 7)),
    );
    let labels = |items: &Value| -> Vec<String> {
        items
            .as_array()
            .unwrap()
            .iter()
            .map(|i| i["label"].as_str().unwrap().to_string())
            .collect()
    };
    assert!(labels(&items).contains(&"brick".to_string()), "{items}");
    let edited = format!("{}\nmerge brick.", l.main);
    c.change_uri(&l.main_uri, 3, &edited);
    let items = c.result(
        "textDocument/completion",
        at_in(&l.main_uri, &edited, edited.len()),
    );
    assert_eq!(labels(&items), ["west", "east"], "{items}");
    let edited = format!("{}\nsite type cap docks ", l.main);
    c.change_uri(&l.main_uri, 4, &edited);
    let items = c.result(
        "textDocument/completion",
        at_in(&l.main_uri, &edited, edited.len()),
    );
    assert!(labels(&items).contains(&"joint".to_string()), "{items}");
    assert!(c.shutdown_and_exit().success());
}

#[test]
fn references_and_rename_of_an_imported_piece_span_the_open_files() {
    let l = Library::new("rename");
    let mut c = Client::start();
    c.open_as(&l.main_uri, &l.main);
    c.open_as(&l.lib_uri, &l.lib);

    // Asked in the library: its own declaration and the two uses in the open grammar.
    let decl = at(&l.lib, "piece brick", 0, 6);
    let refs = c.result(
        "textDocument/references",
        json!({
            "textDocument": { "uri": l.lib_uri },
            "position": pos(&l.lib, decl),
            "context": { "includeDeclaration": true },
        }),
    );
    let mut found: Vec<(String, Value)> = refs
        .as_array()
        .unwrap()
        .iter()
        .map(|r| (r["uri"].as_str().unwrap().to_string(), r["range"].clone()))
        .collect();
    found.sort_by_key(|f| (f.0.clone(), f.1.to_string()));
    let in_main = |needle: &str| {
        let s = at(&l.main, needle, 0, needle.len() - 5);
        (l.main_uri.clone(), range(&l.main, s, s + 5))
    };
    let mut want = vec![
        (l.lib_uri.clone(), range(&l.lib, decl, decl + 5)),
        in_main("stretch brick"),
        in_main("chain brick"),
    ];
    want.sort_by_key(|f| (f.0.clone(), f.1.to_string()));
    assert_eq!(found, want);

    // Rename from a use in the grammar: one edit list per file, and both check clean after.
    let edit = c.result(
        "textDocument/rename",
        json!({
            "textDocument": { "uri": l.main_uri },
            "position": pos(&l.main, at(&l.main, "chain brick", 0, 7)),
            "newName": "block",
        }),
    );
    let changes = edit["changes"].as_object().unwrap();
    assert_eq!(changes.len(), 2, "{edit}");
    let lib = apply(&l.lib, changes[&l.lib_uri].as_array().unwrap());
    let main = apply(&l.main, changes[&l.main_uri].as_array().unwrap());
    assert_eq!(lib, l.lib.replace("piece brick", "piece block"));
    assert_eq!(main, l.main.replace("brick", "block"));
    c.change_uri(&l.lib_uri, 2, &lib);
    c.change_uri(&l.main_uri, 2, &main);
    // (The library alone has no model: a warning, no error.)
    let lib_diags = c.published(&l.lib_uri, Some(2));
    assert!(
        lib_diags["diagnostics"]
            .as_array()
            .unwrap()
            .iter()
            .all(|d| d["severity"] != 1),
        "{lib_diags}"
    );
    assert_eq!(c.published(&l.main_uri, Some(2))["diagnostics"], json!([]));

    // A clash in the library refuses the rename, naming the file.
    let refused = c.request(
        "textDocument/rename",
        json!({
            "textDocument": { "uri": l.main_uri },
            "position": pos(&main, at(&main, "from west", 0, 5)),
            "newName": "east",
        }),
    );
    let message = refused["error"]["message"].as_str().unwrap();
    assert!(
        message.contains("site `east` already exists (`") && message.contains("lib.clay` line 10)"),
        "{refused}"
    );
    assert!(c.shutdown_and_exit().success());
}

#[test]
fn range_formatting_prints_the_declarations_the_range_touches() {
    let good = wall();
    let model = "    wall = chain brick x 8 at (0, 0)";
    let messy = good
        .replace("    vertex sw (0, 0)", "  vertex   sw ( 0,0 )")
        .replace(model, "  wall = chain brick x 8 at (0,0)");
    let mut c = Client::start();
    c.open(&messy);
    // A range inside the piece: the piece is printed, the model stays as it was.
    let inside = at(&messy, "vertex   sw", 0, 3);
    let edits = c.result(
        "textDocument/rangeFormatting",
        json!({
            "textDocument": doc(),
            "range": range(&messy, inside, inside + 2),
            "options": { "tabSize": 4, "insertSpaces": true },
        }),
    );
    let edits = edits.as_array().unwrap();
    assert_eq!(edits.len(), 1, "{edits:?}");
    assert_eq!(
        apply(&messy, edits),
        good.replace(model, "  wall = chain brick x 8 at (0,0)")
    );
    // A range over both: all of it, as `textDocument/formatting` would.
    let edits = c.result(
        "textDocument/rangeFormatting",
        json!({
            "textDocument": doc(),
            "range": range(&messy, 0, messy.len()),
            "options": { "tabSize": 4, "insertSpaces": true },
        }),
    );
    assert_eq!(apply(&messy, edits.as_array().unwrap()), good);
    // While the text does not parse: nothing.
    c.change(2, &format!("{messy}\npiece {{"));
    let none = c.result(
        "textDocument/rangeFormatting",
        json!({
            "textDocument": doc(),
            "range": range(&messy, inside, inside + 2),
            "options": { "tabSize": 4, "insertSpaces": true },
        }),
    );
    assert_eq!(none, Value::Null);
    assert!(c.shutdown_and_exit().success());
}

#[test]
fn the_cursor_is_published_for_the_clay_editor_and_its_reveal_shows_the_declaration() {
    let l = Library::new("follow");
    let channel = l.dir.join("follow");
    std::fs::create_dir_all(&channel).unwrap();
    let mut c = Client::initialised(Client::spawn_following(&channel));
    c.open_as(&l.main_uri, &l.main);
    let main_path = l.dir.join("main.clay").display().to_string();
    let cursor = || -> Value {
        serde_json::from_slice(&std::fs::read(channel.join("cursor.json")).unwrap()).unwrap()
    };

    // The cursor on the chain (a documentHighlight), then on a site of the imported piece (a
    // hover): each is written for the Clay editor.
    c.result(
        "textDocument/documentHighlight",
        at_in(&l.main_uri, &l.main, at(&l.main, "wall", 0, 1)),
    );
    assert_eq!(
        cursor(),
        json!({ "file": main_path, "kind": "chain", "name": "wall", "piece": "brick" })
    );
    c.result(
        "textDocument/hover",
        at_in(&l.main_uri, &l.main, at(&l.main, "from west", 0, 5)),
    );
    assert_eq!(
        cursor(),
        json!({ "file": main_path, "kind": "site", "name": "west", "piece": "brick" })
    );

    // The Clay editor asks for a site's declaration: the server asks the client to show it,
    // in the library.
    let reveal = json!({ "file": main_path, "kind": "site", "name": "east", "piece": "brick" });
    let tmp = channel.join(".reveal.tmp");
    std::fs::write(&tmp, reveal.to_string()).unwrap();
    std::fs::rename(&tmp, channel.join("reveal.json")).unwrap();
    let shown = loop {
        let m = c.recv();
        if m["method"] == "window/showDocument" {
            break m;
        }
        c.stash.push(m);
    };
    assert!(
        shown["id"].is_string() || shown["id"].is_number(),
        "{shown}"
    );
    assert_eq!(shown["params"]["uri"], l.lib_uri.as_str());
    assert_eq!(shown["params"]["takeFocus"], true);
    let east = at(&l.lib, "site east", 0, 5);
    assert_eq!(shown["params"]["selection"], range(&l.lib, east, east + 4));
    // The client's answer is taken, and the server goes on.
    c.send(&json!({ "jsonrpc": "2.0", "id": shown["id"], "result": { "success": true } }));
    assert!(c.shutdown_and_exit().success());
}

/// What the Neovim check does once the grammar is open: wait for the diagnostics, hover at
/// `CLAY_NVIM_HOVER_LINE`/`_COL`, write both to `CLAY_NVIM_OUT`, quit.
const NVIM_CHECK: &str = r#"
local lines = {}
vim.wait(30000, function() return #vim.diagnostic.get(0) > 0 end, 50)
for _, d in ipairs(vim.diagnostic.get(0)) do
  local lsp = d.user_data and d.user_data.lsp or {}
  table.insert(lines, string.format('diagnostic %s %d:%d %s', d.code or lsp.code or '?',
    d.lnum + 1, d.col + 1, (d.message:gsub('\n.*', ''))))
end
local row = tonumber(os.getenv('CLAY_NVIM_HOVER_LINE'))
local col = tonumber(os.getenv('CLAY_NVIM_HOVER_COL'))
vim.api.nvim_win_set_cursor(0, { row, col })
local params = vim.lsp.util.make_position_params()
local replies = vim.lsp.buf_request_sync(0, 'textDocument/hover', params, 20000)
for _, r in pairs(replies or {}) do
  if r.result then
    table.insert(lines, 'hover ' .. (r.result.contents.value:gsub('\n', ' | ')))
  end
end
-- K, as the documented setup maps it: a floating window with the hover.
vim.api.nvim_win_set_cursor(0, { row, col })
vim.api.nvim_feedkeys('K', 'x', false)
local float
vim.wait(20000, function()
  for _, w in ipairs(vim.api.nvim_list_wins()) do
    if vim.api.nvim_win_get_config(w).relative ~= '' then
      float = w
      return true
    end
  end
  return false
end, 50)
if float then
  local shown = vim.api.nvim_buf_get_lines(vim.api.nvim_win_get_buf(float), 0, -1, false)
  table.insert(lines, 'K ' .. table.concat(shown, ' | '))
  vim.api.nvim_win_close(float, true)
end
-- Ctrl-], as mapped: the cursor goes to the definition.
vim.api.nvim_win_set_cursor(0, { row, col })
vim.api.nvim_feedkeys(vim.api.nvim_replace_termcodes('<C-]>', true, false, true), 'x', false)
vim.wait(20000, function() return vim.api.nvim_win_get_cursor(0)[1] ~= row end, 50)
table.insert(lines, 'definition line ' .. vim.api.nvim_win_get_cursor(0)[1])
vim.fn.writefile(lines, os.getenv('CLAY_NVIM_OUT'))
vim.cmd('qa!')
"#;

/// The first ```` ```lua ```` block after `heading` in docs/editors.md.
fn lua_block_after(heading: &str) -> String {
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/editors.md"))
        .unwrap();
    let from = doc.find(heading).expect("the heading");
    let rest = &doc[from..];
    let start = rest.find("```lua\n").expect("a lua block") + "```lua\n".len();
    let len = rest[start..].find("```").unwrap();
    rest[start..start + len].to_string()
}

#[test]
fn neovim_with_the_documented_setup_shows_e011_and_hovers() {
    // Real Neovim (0.7 or later) when it is installed; `.ci/run` installs it and sets
    // CLAY_REQUIRE_NVIM so that a missing one fails there.
    let found = Command::new("nvim")
        .arg("--version")
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !found {
        assert!(
            std::env::var_os("CLAY_REQUIRE_NVIM").is_none(),
            "nvim is required"
        );
        eprintln!("nvim not installed: the Neovim check is skipped");
        return;
    }
    let dir = std::env::temp_dir().join(format!("clay-nvim-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("init.lua"), lua_block_after("### Neovim")).unwrap();
    std::fs::write(dir.join("check.lua"), NVIM_CHECK).unwrap();
    let typo = wall().replace("site west: joint", "site west: jiont");
    std::fs::write(dir.join("typo.clay"), &typo).unwrap();
    let clayc = std::path::Path::new(env!("CARGO_BIN_EXE_clayc"));
    let path = format!(
        "{}:{}",
        clayc.parent().unwrap().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let hover = at(&typo, "chain brick", 0, 7);
    let line_start = typo[..hover].rfind('\n').unwrap() + 1;
    let status = Command::new("timeout")
        .args([
            "120",
            "nvim",
            "--headless",
            "-n",
            "-i",
            "NONE",
            "-u",
            "init.lua",
        ])
        .args(["typo.clay", "-c", "luafile check.lua"])
        .current_dir(&dir)
        .env("PATH", path)
        .env("HOME", &dir)
        .env("XDG_CONFIG_HOME", dir.join("config"))
        .env("XDG_DATA_HOME", dir.join("data"))
        .env("XDG_STATE_HOME", dir.join("state"))
        .env("XDG_CACHE_HOME", dir.join("cache"))
        .env("CLAY_FOLLOW_DIR", dir.join("no-follow"))
        .env("CLAY_NVIM_OUT", dir.join("out.txt"))
        .env(
            "CLAY_NVIM_HOVER_LINE",
            (typo[..hover].matches('\n').count() + 1).to_string(),
        )
        .env("CLAY_NVIM_HOVER_COL", (hover - line_start).to_string())
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success(), "nvim: {status}");
    let out = std::fs::read_to_string(dir.join("out.txt")).unwrap();
    let jiont = at(&typo, "jiont", 0, 0);
    let line = typo[..jiont].matches('\n').count() + 1;
    let col = jiont - (typo[..jiont].rfind('\n').unwrap() + 1) + 1;
    assert!(
        out.contains(&format!(
            "diagnostic E011 {line}:{col} unknown site type `jiont`"
        )),
        "{out}"
    );
    assert!(out.contains("hover ```clay | piece brick |"), "{out}");
    // K and Ctrl-] as the block maps them (0.7 maps neither to the server).
    assert!(
        out.lines()
            .any(|l| l.starts_with("K ") && l.contains("piece brick")),
        "{out}"
    );
    let piece = typo[..typo.find("piece brick").unwrap()]
        .matches('\n')
        .count()
        + 1;
    assert!(out.contains(&format!("definition line {piece}")), "{out}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_open_library_is_read_from_its_buffer_and_its_change_rechecks_the_importer() {
    let l = Library::new("buffers");
    let mut c = Client::start();
    assert_eq!(c.open_as(&l.main_uri, &l.main)["diagnostics"], json!([]));
    c.open_as(&l.lib_uri, &l.lib);
    // Opening the library re-checks the grammar that imports it (against the same text).
    assert_eq!(c.published(&l.main_uri, None)["diagnostics"], json!([]));
    // The library's piece renamed in the editor, not saved: the grammar importing it is
    // checked again against the buffer, and its uses of `brick` are unknown now.
    c.change_uri(&l.lib_uri, 2, &l.lib.replace("piece brick", "piece block"));
    let published = c.published(&l.main_uri, None);
    let diags = published["diagnostics"].as_array().unwrap();
    assert!(!diags.is_empty(), "{published}");
    assert!(
        diags
            .iter()
            .all(|d| d["message"].as_str().unwrap().contains("`brick`")),
        "{published}"
    );
    // The disk still has `brick`: closing the buffer re-checks the grammar against the file.
    c.notify(
        "textDocument/didClose",
        json!({ "textDocument": { "uri": l.lib_uri } }),
    );
    assert_eq!(c.published(&l.main_uri, None)["diagnostics"], json!([]));
    assert!(c.shutdown_and_exit().success());
}

// Grammar parameters (`param NAME = DEFAULT in LO..HI`, issue 39): a hover on a parameter's
// name, at its declaration or a use, shows its value, default and range; where a number goes,
// completion offers the parameters as it offers `let` constants, with their value and range as
// detail, also while the text does not parse.

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

fn at_pos_in(uri: &str, text: &str, offset: usize) -> Value {
    json!({ "textDocument": { "uri": uri }, "position": pos(text, offset) })
}

/// The hover's markdown at `offset`.
fn hover(c: &mut Client, text: &str, offset: usize) -> String {
    let hover = c.result("textDocument/hover", at_pos(text, offset));
    hover["contents"]["value"]
        .as_str()
        .unwrap_or_else(|| panic!("a hover at {offset}: {hover}"))
        .to_string()
}

/// The completions at `offset`: label and item.
fn completions(c: &mut Client, text: &str, offset: usize) -> Vec<(String, Value)> {
    let list = c.result("textDocument/completion", at_pos(text, offset));
    let items = list
        .as_array()
        .or_else(|| list["items"].as_array())
        .unwrap();
    items
        .iter()
        .map(|i| (i["label"].as_str().unwrap().to_string(), i.clone()))
        .collect()
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
    let declaration = hover(&mut c, FENCE, at(FENCE, "param bays", 0, 7));
    assert!(
        declaration.contains("value `6`, default `6`, range `2..40`"),
        "{declaration}"
    );
    assert!(declaration.contains("--param bays=VALUE"), "{declaration}");
    let used = hover(&mut c, FENCE, at(FENCE, "x bays", 0, 3));
    assert!(
        used.contains("value `6`, default `6`, range `2..40`"),
        "{used}"
    );
    let width = hover(&mut c, FENCE, at(FENCE, "(bay_width, post)", 0, 2));
    assert!(
        width.contains("value `2`, default `2`, range `1..4`"),
        "{width}"
    );
    let lean = hover(&mut c, FENCE, at(FENCE, "lean * 0", 0, 1));
    assert!(
        lean.contains("value `0.5`, default `0.5`, range any finite number"),
        "{lean}"
    );
    // A `let` is no parameter: its hover has its value only.
    let post = hover(&mut c, FENCE, at(FENCE, "let post", 0, 5));
    assert!(post.contains("= `0.2`"), "{post}");
    assert!(!post.contains("parameter"), "{post}");
}

#[test]
fn completion_offers_the_parameters_where_a_number_goes_with_their_range() {
    let mut c = Client::start();
    c.open(FENCE);
    // A chain's count.
    let count = completions(&mut c, FENCE, at(FENCE, "x bays", 0, 2));
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
    let coordinate = completions(&mut c, FENCE, at(FENCE, "vertex ne (", 0, 11));
    assert!(detail(&coordinate, "bays").starts_with("parameter = 6"));
    // Not where a site type goes.
    let site = completions(&mut c, FENCE, at(FENCE, "west: rail", 0, 6));
    assert!(site.iter().all(|(l, _)| l != "bays"), "{site:?}");
}

#[test]
fn while_the_text_does_not_parse_the_last_parsed_parameters_are_offered() {
    let mut c = Client::start();
    c.open(FENCE);
    // The analysis of the good text first.
    let _ = hover(&mut c, FENCE, at(FENCE, "param bays", 0, 7));
    let marker = "    vertex nw (0, post)\n";
    let typing = FENCE.replace(marker, &format!("{marker}    vertex mid (\n"));
    c.change(2, &typing);
    let end = at(&typing, "vertex mid (", 0, 12);
    let offered = completions(&mut c, &typing, end);
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
    c.notify(
        "textDocument/didOpen",
        json!({ "textDocument": { "uri": uri, "languageId": "clay", "version": 1, "text": text } }),
    );
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
