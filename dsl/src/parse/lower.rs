//! The lowering pass's shared tools: the [`Lower`] state, spans of pest pairs (offset for
//! imported files), picking a pair's meaningful children, and names, strings and colours.

use pest::iterators::Pair;

use super::grammar::Rule;
use crate::diagnostic::Diagnostics;
use crate::syntax::*;

/// The lowering pass: pest pairs -> syntax tree.
pub(super) struct Lower {
    pub(super) diags: Diagnostics,
}

/// The span of a pair without the trailing whitespace and comments pest includes when an
/// optional tail was tried and not found: it ends where its last token ends.
pub(super) fn span_of(p: &Pair<Rule>) -> Span {
    let whole = p.as_span();
    let start = whole.start();
    let base = span_base();
    // Fast path: a token never ends in whitespace or `/`, and a comment's last byte is a
    // newline or `/` (`*/`) unless the file ends inside it; so a pair whose last byte is neither
    // and which does not reach the end of the input has no trivia to trim.
    let text = whole.as_str();
    let ends_in_trivia = text
        .as_bytes()
        .last()
        .is_some_and(|b| b.is_ascii_whitespace() || *b == b'/' || *b >= 0x80);
    if !ends_in_trivia && whole.end() < whole.get_input().len() {
        return Span::new(base + start, base + whole.end());
    }
    let mut last = p.clone();
    while let Some(child) = last.clone().into_inner().last() {
        last = child;
    }
    Span::new(base + start, base + last.as_span().end().max(start))
}

thread_local! {
    /// Where the text being parsed starts in the global positions of the source map
    /// (`source_map.rs`): 0 for the main file, so a single file's spans are its byte offsets.
    static SPAN_BASE: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

pub(super) fn span_base() -> usize {
    SPAN_BASE.with(std::cell::Cell::get)
}

/// Runs `f` with spans offset by `base` (an imported file's global start), and puts the offset
/// back to 0 afterwards, even when `f` panics.
pub(super) fn with_span_base<T>(base: usize, f: impl FnOnce() -> T) -> T {
    struct Reset;
    impl Drop for Reset {
        fn drop(&mut self) {
            SPAN_BASE.with(|b| b.set(0));
        }
    }
    let _reset = Reset;
    SPAN_BASE.with(|b| b.set(base));
    f()
}

/// Children that carry meaning: punctuation is dropped.
pub(super) fn kids(p: Pair<Rule>) -> Vec<Pair<Rule>> {
    p.into_inner()
        .filter(|c| {
            !matches!(
                c.as_rule(),
                Rule::lbrace
                    | Rule::rbrace
                    | Rule::lparen
                    | Rule::rparen
                    | Rule::lbracket
                    | Rule::rbracket
                    | Rule::comma
                    | Rule::colon
                    | Rule::equals
                    | Rule::arrow
                    | Rule::dash
                    | Rule::dot
                    | Rule::dotdot
                    | Rule::EOI
            )
        })
        .collect()
}

/// Children of one rule, in order.
pub(super) fn of<'i>(children: &[Pair<'i, Rule>], rule: Rule) -> Vec<Pair<'i, Rule>> {
    children
        .iter()
        .filter(|c| c.as_rule() == rule)
        .cloned()
        .collect()
}

pub(super) fn first<'i>(children: &[Pair<'i, Rule>], rule: Rule) -> Option<Pair<'i, Rule>> {
    children.iter().find(|c| c.as_rule() == rule).cloned()
}

impl Lower {
    pub(super) fn ident(&self, p: Pair<Rule>) -> Ident {
        Ident {
            name: p.as_str().to_string(),
            span: span_of(&p),
        }
    }

    /// The first name among `children`, or an empty one at `span` (the grammar guarantees one;
    /// this keeps lowering total).
    pub(super) fn name_or(&self, children: &[Pair<Rule>], span: Span) -> Ident {
        first(children, Rule::name).map_or(
            Ident {
                name: String::new(),
                span,
            },
            |n| self.ident(n),
        )
    }

    pub(super) fn idents(&self, children: &[Pair<Rule>]) -> Vec<Ident> {
        of(children, Rule::name)
            .into_iter()
            .map(|p| self.ident(p))
            .collect()
    }

    /// A quoted path without its quotes (empty at `span` when the parser recovered without one).
    pub(super) fn string_or(&mut self, s: Option<Pair<Rule>>, span: Span) -> StringLit {
        s.map_or(
            StringLit {
                value: String::new(),
                span,
            },
            |s| {
                let text = s.as_str();
                StringLit {
                    value: text[1..text.len() - 1].to_string(),
                    span: span_of(&s),
                }
            },
        )
    }

    pub(super) fn colour(&self, p: Pair<Rule>) -> Colour {
        let span = span_of(&p);
        let hex = p.as_str().trim_start_matches('#');
        let byte = |i: usize| {
            hex.get(i..i + 2)
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .unwrap_or(255)
        };
        let alpha = if hex.len() == 8 { byte(6) } else { 255 };
        Colour {
            rgba: [byte(0), byte(2), byte(4), alpha],
            span,
        }
    }
}
