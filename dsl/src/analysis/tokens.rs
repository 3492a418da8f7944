//! Semantic tokens (what each word, number and comment is, from the symbol table where it knows
//! and lexically otherwise) and folding ranges (multi-line blocks and block comments).

use std::collections::HashMap;

use super::analysed::{Analysis, KEYWORDS};
use super::symbols::SymbolKind;
use crate::syntax::Span;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TokenKind {
    Keyword,
    Comment,
    Number,
    /// A colour literal `#rrggbb`.
    Colour,
    Operator,
    Function,
    Parameter,
    Symbol(SymbolKind),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SemanticToken {
    pub span: Span,
    pub kind: TokenKind,
    /// The token is the name in a declaration.
    pub declaration: bool,
}

/// The tokens of the text in order; no two overlap and none spans a line break.
pub(super) fn semantic(a: &Analysis) -> Vec<SemanticToken> {
    let text = a.text();
    let syms = &a.symbols().symbols;
    let mut known: HashMap<usize, (TokenKind, bool)> = HashMap::new();
    for s in syms.iter().filter(|s| s.kind != SymbolKind::Rule) {
        known.insert(s.span.start, (TokenKind::Symbol(s.kind), true));
    }
    for r in &a.symbols().references {
        known.insert(
            r.span.start,
            (TokenKind::Symbol(syms[r.symbol].kind), false),
        );
    }
    for s in &a.symbols().parameters {
        known.insert(s.start, (TokenKind::Parameter, false));
    }
    for s in &a.symbols().builtins {
        known.insert(s.start, (TokenKind::Function, false));
    }
    let comments = crate::comment_spans(text);
    let mut out = Vec::new();
    let b = text.as_bytes();
    let mut i = 0;
    let mut next_comment = 0;
    while i < b.len() {
        if let Some(c) = comments.get(next_comment).filter(|c| c.start == i) {
            push_lines(text, *c, TokenKind::Comment, &mut out);
            i = c.end.max(i + 1);
            next_comment += 1;
            continue;
        }
        let c = b[i];
        let start = i;
        if c.is_ascii_alphabetic() || c == b'_' {
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            let word = &text[start..i];
            let kind = match known.get(&start) {
                Some(&(k, decl)) => Some((k, decl)),
                None if KEYWORDS.contains(&word) => Some((TokenKind::Keyword, false)),
                None => None,
            };
            if let Some((kind, declaration)) = kind {
                out.push(SemanticToken {
                    span: Span::new(start, i),
                    kind,
                    declaration,
                });
            }
        } else if c.is_ascii_digit() || (c == b'.' && b.get(i + 1).is_some_and(u8::is_ascii_digit))
        {
            i = number_end(b, i);
            out.push(token(start, i, TokenKind::Number));
        } else if c == b'#' {
            i += 1;
            while i < b.len() && b[i].is_ascii_hexdigit() {
                i += 1;
            }
            out.push(token(start, i, TokenKind::Colour));
        } else if b"+-*/=".contains(&c) {
            i += if c == b'-' && b.get(i + 1) == Some(&b'>') {
                2
            } else {
                1
            };
            out.push(token(start, i, TokenKind::Operator));
        } else {
            i += 1;
            while i < b.len() && !text.is_char_boundary(i) {
                i += 1;
            }
        }
    }
    out
}

fn token(start: usize, end: usize, kind: TokenKind) -> SemanticToken {
    SemanticToken {
        span: Span::new(start, end),
        kind,
        declaration: false,
    }
}

/// Where a number literal starting at `i` ends (digits, fraction, exponent).
fn number_end(b: &[u8], mut i: usize) -> usize {
    while i < b.len() && b[i].is_ascii_digit() {
        i += 1;
    }
    if b.get(i) == Some(&b'.') {
        i += 1;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
    }
    if matches!(b.get(i), Some(b'e' | b'E')) {
        let mut j = i + 1;
        if matches!(b.get(j), Some(b'+' | b'-')) {
            j += 1;
        }
        if b.get(j).is_some_and(u8::is_ascii_digit) {
            i = j;
            while i < b.len() && b[i].is_ascii_digit() {
                i += 1;
            }
        }
    }
    i
}

/// A multi-line token as one token per line (the protocol's tokens do not span lines).
fn push_lines(text: &str, span: Span, kind: TokenKind, out: &mut Vec<SemanticToken>) {
    let mut start = span.start;
    for line in text[span.start..span.end].split_inclusive('\n') {
        let end = start + line.trim_end_matches(['\n', '\r']).len();
        if end > start {
            out.push(token(start, end, kind));
        }
        start += line.len();
    }
}

/// Multi-line `{ ... }` blocks (outside comments) and multi-line block comments.
pub(super) fn folding(a: &Analysis) -> Vec<Span> {
    let text = a.text();
    let comments = crate::comment_spans(text);
    let mut open = Vec::new();
    let mut out = Vec::new();
    // Comments are in order: one cursor through them keeps this linear.
    let mut k = 0;
    for (i, c) in text.char_indices() {
        while comments.get(k).is_some_and(|c| c.end <= i) {
            k += 1;
        }
        let in_comment = comments.get(k).is_some_and(|c| c.start <= i);
        match c {
            '{' if !in_comment => open.push(i),
            '}' if !in_comment => {
                if let Some(start) = open.pop()
                    && text[start..i].contains('\n')
                {
                    out.push(Span::new(start, i + 1));
                }
            }
            _ => {}
        }
    }
    out.extend(
        comments
            .into_iter()
            .filter(|c| text[c.start..c.end].contains('\n')),
    );
    out.sort_by_key(|s| s.start);
    out
}
