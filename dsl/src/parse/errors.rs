//! Syntax errors: pest's error turned into one diagnostic in the grammar's words (E001), with
//! what was found, hints for common slips, the closest keyword, and the bracket or brace left
//! open that explains it.

use pest::error::{ErrorVariant, InputLocation};

use super::codes;
use super::grammar::{Rule, describe};
use super::scan::unclosed;
use crate::diagnostic::Diagnostic;
use crate::syntax::Span;

/// Where pest stopped.
pub(super) fn error_position(e: &pest::error::Error<Rule>) -> usize {
    match e.location {
        InputLocation::Pos(p) => p,
        InputLocation::Span((s, _)) => s,
    }
}

/// The span of the token starting at `pos` (after whitespace), and words for it.
fn found_token(source: &str, pos: usize) -> (Span, String) {
    let mut pos = pos.min(source.len());
    while !source.is_char_boundary(pos) {
        pos -= 1;
    }
    let rest = &source[pos..];
    // Only what the grammar skips: other white space (U+3000) is what it stopped at.
    let trimmed = rest.trim_start_matches([' ', '\t', '\n', '\r', '\u{FEFF}']);
    let start = pos + (rest.len() - trimmed.len());
    let Some(c) = trimmed.chars().next() else {
        return (
            Span::new(source.len(), source.len()),
            "end of file".to_string(),
        );
    };
    let len = if c.is_ascii_alphanumeric() || c == '_' {
        trimmed
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '.'))
            .unwrap_or(trimmed.len())
    } else {
        c.len_utf8()
    };
    let text = &trimmed[..len];
    let words = if c.is_control() || (!c.is_ascii() && (c.is_whitespace() || invisible(c))) {
        format!("character {c:?}")
    } else {
        format!("`{text}`")
    };
    (Span::new(start, start + len), words)
}

/// A character that shows as nothing: zero-width spaces and joiners, direction marks, the
/// word joiner and the byte-order mark.
fn invisible(c: char) -> bool {
    matches!(c, '\u{200B}'..='\u{200F}' | '\u{202A}'..='\u{202E}' | '\u{2060}'..='\u{2064}' | '\u{FEFF}')
}

/// Joins words as "a, b or c".
fn one_of(words: &[&str]) -> String {
    match words {
        [] => "something else".to_string(),
        [w] => (*w).to_string(),
        [init @ .., last] => format!("{} or {last}", init.join(", ")),
    }
}

pub(super) fn syntax_error(source: &str, e: pest::error::Error<Rule>) -> Diagnostic {
    let (span, found) = found_token(source, error_position(&e));
    match &e.variant {
        ErrorVariant::ParsingError { positives, .. } => {
            let mut words: Vec<&str> = Vec::new();
            for r in positives {
                let w = describe(*r);
                if !words.contains(&w) {
                    words.push(w);
                }
            }
            // "an operator" is rarely what was meant: name it last (`,` or an operator).
            words.sort_by_key(|w| *w == "an operator");
            let expected = one_of(&words);
            let mut d = Diagnostic::error(
                codes::SYNTAX,
                format!("expected {expected}, found {found}"),
                span,
                format!("expected {expected}"),
            );
            if let Some(hint) = syntax_hint(source, span, positives) {
                d = d.with_hint(hint);
            }
            // A misspelt keyword: suggest the closest one that would fit here.
            let text = source.get(span.start..span.end).unwrap_or("");
            // Backticked words in the expectation (`site type` offers `site`).
            let keywords = words
                .iter()
                .flat_map(|w| w.split('`').skip(1).step_by(2))
                .filter_map(|k| k.split_whitespace().next())
                .filter(|k| k.chars().all(|c| c.is_ascii_alphabetic()));
            if let Some(k) = crate::suggest::closest(text, keywords) {
                d = d.with_hint(format!("did you mean `{k}`?"));
            }
            if span.start >= source.len()
                && let Some(open) = unclosed(source)
            {
                d = d.with_secondary(open, "this bracket is never closed");
            } else if let Some((keyword, open)) = declaration_in_open_block(source, span) {
                // `state down {` inside an unclosed `state up {`: `state` was read as a vertex
                // name; the real mistake is the missing `}` before it.
                let (line, _) = crate::line_col(source, open.start);
                d = d
                    .with_secondary(open, "this `{` is never closed")
                    .with_hint(format!(
                        "`{keyword}` starts a new declaration, but the block opened on line \
                         {line} is still open: close it with `}}` first"
                    ));
            }
            d
        }
        ErrorVariant::CustomError { message } => {
            Diagnostic::error(codes::SYNTAX, message.clone(), span, "here")
        }
    }
}

/// A declaration keyword just before the error (`state` of `state down {`) while a `{` is still
/// open: the keyword and that brace.
fn declaration_in_open_block(source: &str, span: Span) -> Option<(&str, Span)> {
    const STARTS: [&str; 6] = ["state", "piece", "stretch", "merge", "cut", "model"];
    let before = source.get(..span.start)?.trim_end();
    // The word's start is found by trimming it off, which stays on a char boundary even after
    // a multi-byte character (`m²`).
    let word_start = before
        .trim_end_matches(|c: char| c.is_ascii_alphanumeric() || c == '_')
        .len();
    let keyword = &before[word_start..];
    let open = unclosed(&source[..word_start])?;
    if !(STARTS.contains(&keyword) && source.as_bytes().get(open.start) == Some(&b'{')) {
        return None;
    }
    // The block the brace opens, by the first word of its line: a `state` inside a `piece` is
    // where it belongs, so that open brace is no mistake.
    let line_start = source[..open.start].rfind('\n').map_or(0, |i| i + 1);
    let block = source[line_start..open.start].split_whitespace().next();
    (!(block == Some("piece") && keyword == "state")).then_some((keyword, open))
}

/// A hint for common slips, judged from what was expected and what is there.
fn syntax_hint(source: &str, span: Span, positives: &[Rule]) -> Option<String> {
    let text = source.get(span.start..span.end).unwrap_or("");
    if let Some(c) = text
        .chars()
        .next()
        .filter(|c| !c.is_ascii() && c.is_alphabetic())
    {
        return Some(format!(
            "names are ASCII: letters `a`-`z` and `A`-`Z`, digits and `_`; `{c}` is not one of them"
        ));
    }
    if text == ";" {
        return Some("statements need no separator: remove the `;`".into());
    }
    let digit_then_letter = text
        .char_indices()
        .any(|(i, c)| c.is_ascii_alphabetic() && text[..i].ends_with(|d: char| d.is_ascii_digit()));
    let wants_number = [Rule::number, Rule::expr, Rule::neg, Rule::paren_expr]
        .iter()
        .any(|r| positives.contains(r));
    if wants_number && digit_then_letter {
        return Some(format!(
            "`{text}` is not a number: a number is digits with an optional `.` and exponent \
             (`2`, `0.5`, `2e3`); a letter cannot follow its digits"
        ));
    }

    if positives.contains(&Rule::colour) && text.starts_with('#') {
        return Some(
            "colours are `#` followed by 6 or 8 hexadecimal digits, like `#b5651d` or `#b5651d80`"
                .into(),
        );
    }
    let after_x = positives.contains(&Rule::comma) && positives.contains(&Rule::add);
    if (positives.contains(&Rule::comma) && positives.contains(&Rule::rparen)) || after_x {
        return Some("points are written `(x, y)`".into());
    }
    if positives.contains(&Rule::kw_piece) && positives.contains(&Rule::kw_model) {
        return Some("a file is a list of `import`, `let`, `param`, `solver`, `site type`, `piece`, `stretch`, `merge`, `cut` and `model` items".into());
    }
    None
}
