//! Completion: what may be written at a position, judged from the text before it on its line
//! and the blocks it is inside (read from the text itself, so it works while the text does not
//! parse), and offered from the symbol table.

use super::analysed::Analysis;
use super::symbols::SymbolKind;
use crate::syntax::Span;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CompletionKind {
    Keyword,
    Piece,
    SiteType,
    Vertex,
    Site,
    State,
    Constant,
    Function,
    Instance,
    Parameter,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Completion {
    pub label: String,
    pub kind: CompletionKind,
    pub detail: Option<String>,
    /// The partly typed word the completion replaces.
    pub replace: Span,
}

const ITEM_KEYWORDS: &[&str] = &[
    "let",
    "solver",
    "site type",
    "piece",
    "stretch",
    "merge",
    "cut",
    "model",
];
const PIECE_KEYWORDS: &[&str] = &[
    "vertex", "edges", "site", "axis", "polygon", "polyline", "mesh", "state",
];
const STATE_KEYWORDS: &[&str] = &["edges", "polygon", "polyline"];

/// An open `{` and the words before it on its line (`piece brick`, `state left`, `model`).
struct Block<'a> {
    head: Vec<&'a str>,
}

/// The blocks open at `offset`, outermost first (comments skipped).
fn open_blocks(text: &str, offset: usize) -> Vec<Block<'_>> {
    let b = text.as_bytes();
    let mut stack = Vec::new();
    let mut i = 0;
    while i < offset.min(b.len()) {
        match b[i] {
            b'/' if b.get(i + 1) == Some(&b'/') => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                let mut depth = 0;
                while i < b.len() {
                    if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
                        depth += 1;
                        i += 1;
                    } else if b[i] == b'*' && b.get(i + 1) == Some(&b'/') {
                        depth -= 1;
                        i += 1;
                        if depth == 0 {
                            break;
                        }
                    }
                    i += 1;
                }
            }
            b'{' => {
                let line_start = text[..i].rfind('\n').map_or(0, |n| n + 1);
                stack.push(Block {
                    head: text[line_start..i].split_whitespace().collect(),
                });
            }
            b'}' => {
                stack.pop();
            }
            _ => {}
        }
        i += 1;
    }
    stack
}

fn is_word(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// Completions at `offset` of the analysed text.
pub(super) fn at(a: &Analysis, offset: usize) -> Vec<Completion> {
    let text = a.text();
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let line_start = text[..offset].rfind('\n').map_or(0, |n| n + 1);
    let prefix = &text[line_start..offset];
    let word_len = prefix.len() - prefix.trim_end_matches(is_word).len();
    let replace = Span::new(offset - word_len, offset);
    let before = prefix[..prefix.len() - word_len].trim_end();
    let blocks = open_blocks(text, offset);
    let mut out = Offer {
        a,
        replace,
        items: Vec::new(),
    };
    let piece = blocks
        .iter()
        .find(|b| b.head.first() == Some(&"piece"))
        .and_then(|b| b.head.get(1).copied());
    let inner = blocks.last().and_then(|b| b.head.first().copied());
    // `if NAME {` and `} else {` blocks hold model statements.
    let in_model = blocks.iter().any(|b| b.head.first() == Some(&"model"));
    let inner = match inner {
        Some("if" | "}" | "else") if in_model => Some("model"),
        other => other,
    };
    let words: Vec<&str> = before.split_whitespace().collect();
    let last = words.last().copied().unwrap_or("");
    let first = words.first().copied().unwrap_or("");

    if let Some(owner) = before.strip_suffix('.') {
        // `PIECE.` or `INSTANCE.` / `CHAIN[i].`
        let owner = owner.trim_end_matches(|c| c != '[' && !is_word(c) && c != ']');
        let owner = owner.split('[').next().unwrap_or(owner);
        let name = &owner[owner.trim_end_matches(is_word).len()..];
        out.sites_of_owner(name);
    } else if first == "param" && before.ends_with(':') {
        ["number", "int", "bool", "seed", "choice"]
            .iter()
            .for_each(|k| out.keyword(k));
    } else if inner == Some("model") && last == "if" {
        out.params_of("bool");
    } else if before.ends_with('[') && inner == Some("model") {
        out.keyword("last");
    } else if before.rfind('[') > before.rfind(']') && piece.is_some() {
        out.members(piece, SymbolKind::Vertex);
    } else if first == "site" && words.get(1) == Some(&"type") {
        if words.len() > 2 {
            out.of_kind(SymbolKind::SiteType);
        }
    } else if first == "site" && before.ends_with(':') {
        out.of_kind(SymbolKind::SiteType);
    } else if first == "edges" || (inner == Some("state") && last.ends_with('-')) {
        out.members(piece, SymbolKind::Vertex);
    } else if first == "axis" {
        out.members(piece, SymbolKind::Site);
    } else if last == "mirror" {
        out.keyword("base");
        out.members(piece, SymbolKind::State);
    } else if matches!(
        last,
        "extends" | "chain" | "stretch" | "merge" | "onto" | "cut" | "variants"
    ) || (first == "cut" && last == "into")
        || (first == "merge" && last == "into")
        || (inner == Some("model") && last == "=")
        || (inner == Some("variants")
            && (before.ends_with(',') || before.ends_with('{') || before.is_empty()))
    {
        out.of_kind(SymbolKind::Piece);
        if inner == Some("model") && last == "=" {
            out.keyword("chain");
            out.params_of("choice");
        }
    } else if first == "stretch" && matches!(last, "from" | "to") {
        out.members(words.get(1).copied(), SymbolKind::Site);
    } else if inner == Some("model") && matches!(last, "along" | "->") {
        let of = words
            .iter()
            .position(|w| *w == "chain")
            .and_then(|i| words.get(i + 1));
        out.members(of.copied(), SymbolKind::Site);
    } else if inner == Some("model") && (first == "dock") && matches!(last, "dock" | "to") {
        out.of_kind(SymbolKind::Instance);
        out.of_kind(SymbolKind::Chain);
    } else if expression_context(before, first, inner) {
        out.expressions(offset);
    } else if before.is_empty() {
        match inner {
            None => ITEM_KEYWORDS.iter().for_each(|k| out.keyword(k)),
            Some("piece") => PIECE_KEYWORDS.iter().for_each(|k| out.keyword(k)),
            Some("state") => {
                STATE_KEYWORDS.iter().for_each(|k| out.keyword(k));
                out.members(piece, SymbolKind::Vertex);
            }
            Some("model") => ["dock", "if"].iter().for_each(|k| out.keyword(k)),
            Some("solver") => crate::settings::grammar_names()
                .for_each(|p| out.push(p, CompletionKind::Parameter, None)),
            Some("stretch") => ["min", "max", "variants"]
                .iter()
                .for_each(|k| out.keyword(k)),
            Some("polygon") => out.keyword("hole"),
            _ => {}
        }
    }
    out.items
}

/// Whether a number (an expression) is expected after `before`.
fn expression_context(before: &str, first: &str, inner: Option<&str>) -> bool {
    let last_char = before.chars().last();
    matches!(last_char, Some('(' | '+' | '-' | '*' | '/'))
        || (last_char == Some(',') && before.rfind('(') > before.rfind(')'))
        || (last_char == Some('=') && (first == "let" || inner == Some("solver")))
        || before
            .split_whitespace()
            .last()
            .is_some_and(|w| matches!(w, "rotate" | "width" | "within" | "min" | "max" | "x"))
}

/// Collects completions without duplicates.
struct Offer<'a> {
    a: &'a Analysis,
    replace: Span,
    items: Vec<Completion>,
}

impl Offer<'_> {
    fn push(&mut self, label: &str, kind: CompletionKind, detail: Option<String>) {
        if !self.items.iter().any(|c| c.label == label) {
            self.items.push(Completion {
                label: label.to_string(),
                kind,
                detail,
                replace: self.replace,
            });
        }
    }

    fn keyword(&mut self, k: &str) {
        self.push(k, CompletionKind::Keyword, None);
    }

    fn of_kind(&mut self, kind: SymbolKind) {
        let a = self.a;
        for s in a.symbols().symbols.iter().filter(|s| s.kind == kind) {
            let detail = s
                .piece
                .as_ref()
                .map(|p| format!("{} of `{p}`", kind.word()));
            self.push(&s.name, completion_kind(kind), detail);
        }
    }

    /// The vertices, sites or states of the piece named `piece`.
    fn members(&mut self, piece: Option<&str>, kind: SymbolKind) {
        let a = self.a;
        let syms = &a.symbols().symbols;
        let Some(p) = piece.and_then(|name| {
            syms.iter()
                .position(|s| s.kind == SymbolKind::Piece && s.name == name)
        }) else {
            return;
        };
        for s in syms
            .iter()
            .filter(|s| s.container == Some(p) && s.kind == kind)
        {
            let detail = Some(format!("{} of `{}`", kind.word(), syms[p].name));
            self.push(&s.name, completion_kind(kind), detail);
        }
    }

    /// Sites after `NAME.`: of the piece, or of the instance's piece.
    fn sites_of_owner(&mut self, name: &str) {
        let a = self.a;
        let syms = &a.symbols().symbols;
        let piece = syms.iter().find_map(|s| match s.kind {
            SymbolKind::Piece if s.name == name => Some(s.name.clone()),
            SymbolKind::Instance | SymbolKind::Chain if s.name == name => s.piece.clone(),
            _ => None,
        });
        self.members(piece.as_deref(), SymbolKind::Site);
    }

    /// The parameters declared with type `ty` (`bool`, `choice`).
    fn params_of(&mut self, ty: &str) {
        let a = self.a;
        for s in (a.symbols().symbols.iter()).filter(|s| s.kind == SymbolKind::Constant) {
            let decl = a.source(s.full);
            let typed = decl.starts_with("param")
                && decl
                    .split_once(':')
                    .is_some_and(|(_, t)| t.trim_start().starts_with(ty));
            if typed {
                let detail = decl.split_once('=').map(|(_, v)| format!("= {}", v.trim()));
                self.push(&s.name, CompletionKind::Parameter, detail);
            }
        }
    }

    /// Constants visible at `offset`, `pi` and the functions.
    fn expressions(&mut self, offset: usize) {
        let a = self.a;
        for s in a
            .symbols()
            .symbols
            .iter()
            .filter(|s| s.kind == SymbolKind::Constant)
            // Declared before here, or in an imported file (past the end of the text).
            .filter(|s| s.full.end <= offset || s.span.start > a.text().len())
        {
            let value = a
                .values
                .get(&s.name)
                .map(|v| format!("= {}", crate::format_number(*v)));
            self.push(&s.name, CompletionKind::Constant, value);
        }
        self.push(
            "pi",
            CompletionKind::Constant,
            Some("= 3.141592653589793".into()),
        );
        for (name, usage) in crate::compile::functions() {
            self.push(name, CompletionKind::Function, Some(usage.to_string()));
        }
    }
}

fn completion_kind(kind: SymbolKind) -> CompletionKind {
    match kind {
        SymbolKind::Constant => CompletionKind::Constant,
        SymbolKind::SiteType => CompletionKind::SiteType,
        SymbolKind::Piece | SymbolKind::Rule => CompletionKind::Piece,
        SymbolKind::Vertex => CompletionKind::Vertex,
        SymbolKind::Site => CompletionKind::Site,
        SymbolKind::State => CompletionKind::State,
        SymbolKind::Instance | SymbolKind::Chain => CompletionKind::Instance,
    }
}
