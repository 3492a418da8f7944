//! The scan before pest: one linear pass over the text that knows comments and strings,
//! for the nesting guard (E002), the unclosed-comment check and the unclosed-bracket hint.

use super::codes;
use crate::diagnostic::Diagnostic;
use crate::syntax::Span;

/// Deepest nesting of brackets and block comments accepted. Deeper input is rejected before
/// pest sees it, because pest recurses once per nested block comment.
pub const MAX_NESTING: usize = 256;

/// One event of a scan of the source that knows comments (line comments skipped, block
/// comments nested) and strings (skipped): a bracket opened or closed outside comments and
/// strings, or a block comment opened or closed.
enum Nesting {
    Open(usize),
    Close,
    /// A block comment opened; `at` is its `*`, `depth` the comment nesting after it.
    Comment {
        at: usize,
        depth: usize,
    },
    /// A block comment closed; `depth` is the comment nesting after it.
    CommentEnd {
        depth: usize,
    },
}

/// The bracket and comment events of `bytes`, in order: the one lexer that the nesting guard,
/// the unclosed-comment check and the unclosed-bracket hint use, so they agree on what a
/// comment is. A string runs to its closing `"` or the end of its line, as in the grammar.
fn nesting_events(bytes: &[u8]) -> impl Iterator<Item = Nesting> + '_ {
    let mut i = 0;
    let mut comments = 0usize;
    std::iter::from_fn(move || {
        while i < bytes.len() {
            let (b, next) = (bytes[i], bytes.get(i + 1).copied());
            let at = i;
            i += 1;
            if comments > 0 {
                if b == b'/' && next == Some(b'*') {
                    comments += 1;
                    i += 1;
                    return Some(Nesting::Comment {
                        at: at + 1,
                        depth: comments,
                    });
                } else if b == b'*' && next == Some(b'/') {
                    comments -= 1;
                    i += 1;
                    return Some(Nesting::CommentEnd { depth: comments });
                }
            } else if b == b'/' && next == Some(b'/') {
                while i < bytes.len() && bytes[i] != b'\n' {
                    i += 1;
                }
            } else if b == b'"' {
                while i < bytes.len() && !matches!(bytes[i], b'"' | b'\n') {
                    i += 1;
                }
                i += 1;
            } else if b == b'/' && next == Some(b'*') {
                comments = 1;
                i += 1;
                return Some(Nesting::Comment {
                    at: at + 1,
                    depth: 1,
                });
            } else if matches!(b, b'(' | b'[' | b'{') {
                return Some(Nesting::Open(at));
            } else if matches!(b, b')' | b']' | b'}') {
                return Some(Nesting::Close);
            }
        }
        None
    })
}

/// What the scan before pest finds in the source.
pub(super) struct Scan {
    /// E002 at the first place nested deeper than [`MAX_NESTING`] (brackets of any kind, or
    /// block comments): rejected before the recursive parser runs.
    pub(super) too_deep: Option<Diagnostic>,
    /// The `/*` of the outermost block comment still open at the end of the text.
    pub(super) unclosed_comment: Option<Span>,
}

/// One linear scan of the source for the nesting guard and the unclosed-comment check.
pub(super) fn scan(source: &str) -> Scan {
    let mut brackets = 0usize;
    let mut comments = 0usize;
    // Where the outermost block comment (the one open at depth 1) starts.
    let mut outermost = 0usize;
    let mut too_deep = None;
    for event in nesting_events(source.as_bytes()) {
        let deeper = match event {
            Nesting::Open(at) => {
                brackets += 1;
                (brackets > MAX_NESTING).then_some((at, "brackets"))
            }
            Nesting::Close => {
                brackets = brackets.saturating_sub(1);
                None
            }
            Nesting::Comment { at, depth } => {
                comments = depth;
                if depth == 1 {
                    outermost = at - 1;
                }
                (depth > MAX_NESTING).then_some((at, "block comments"))
            }
            Nesting::CommentEnd { depth } => {
                comments = depth;
                None
            }
        };
        if too_deep.is_none() {
            too_deep = deeper;
        }
    }
    let unclosed_comment = (comments > 0).then(|| Span::new(outermost, outermost + 2));
    Scan {
        too_deep: too_deep.map(|(at, what)| nested_too_deep(at, what, unclosed_comment)),
        unclosed_comment,
    }
}

/// E002 at `at`, where `what` (brackets or block comments) pass [`MAX_NESTING`]; the open
/// comment, when it holds that place, is named too.
fn nested_too_deep(at: usize, what: &str, unclosed_comment: Option<Span>) -> Diagnostic {
    let d = Diagnostic::error(
        codes::TOO_DEEP,
        format!("{what} nested more than {MAX_NESTING} deep"),
        Span::new(at, at + 1),
        format!("nesting level {} starts here", MAX_NESTING + 1),
    )
    .with_hint("a clay file never needs more than three levels of brackets; look for an unclosed bracket or comment");
    match unclosed_comment.filter(|c| c.start <= at) {
        Some(open) => d.with_secondary(open, "this block comment is never closed"),
        None => d,
    }
}

/// E001 for a block comment that is never closed, at its `/*`.
pub(super) fn unclosed_comment(open: Span) -> Diagnostic {
    Diagnostic::error(
        codes::SYNTAX,
        "unclosed block comment",
        open,
        "this comment is never closed",
    )
    .with_hint(
        "close it with `*/`; block comments nest, so every `/*` inside it needs its own `*/`",
    )
}

/// The innermost bracket left open at the end of the source (comments skipped).
pub(super) fn unclosed(source: &str) -> Option<Span> {
    let mut open: Vec<usize> = Vec::new();
    for event in nesting_events(source.as_bytes()) {
        match event {
            Nesting::Open(at) => open.push(at),
            Nesting::Close => {
                open.pop();
            }
            Nesting::Comment { .. } | Nesting::CommentEnd { .. } => {}
        }
    }
    open.last().map(|&i| Span::new(i, i + 1))
}
