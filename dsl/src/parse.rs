//! Text -> syntax tree: runs the pest grammar and lowers its pairs by hand into the typed tree
//! of `syntax.rs`. Parsing knows nothing of compilation; it only reports text that is not a
//! `.clay` file (syntax errors, number literals that overflow, nesting too deep to parse).

use pest::Parser;
use pest::error::{ErrorVariant, InputLocation};
use pest::iterators::Pair;

use crate::diagnostic::{Diagnostic, Diagnostics};
use crate::syntax::*;

#[derive(pest_derive::Parser)]
#[grammar = "grammar.pest"]
struct ClayParser;

/// Deepest nesting of brackets and block comments accepted. Deeper input is rejected before
/// pest sees it, because pest recurses once per nested block comment.
pub const MAX_NESTING: usize = 256;

/// Deepest expression tree accepted (operators, signs and parentheses on one path), so that
/// every pass over an expression can recurse safely. Real expressions are a few levels deep.
pub const MAX_EXPR_DEPTH: usize = 128;

/// Pops the top operator and its two operands and pushes their binary node (with its depth).
fn reduce(operands: &mut Vec<(Expr, usize)>, operators: &mut Vec<BinaryOp>) {
    let (Some(op), Some((rhs, dr)), Some((lhs, dl))) =
        (operators.pop(), operands.pop(), operands.pop())
    else {
        return;
    };
    let span = lhs.span.to(rhs.span);
    let depth = dl.max(dr) + 1;
    if depth > MAX_EXPR_DEPTH {
        // Too deep (reported by the caller): a leaf keeps the tree shallow.
        operands.push((Expr::number(0.0, span), depth));
        return;
    }
    operands.push((
        Expr {
            kind: ExprKind::Binary(op, Box::new(lhs), Box::new(rhs)),
            span,
        },
        dl.max(dr) + 1,
    ));
}

/// Stable diagnostic codes emitted by the parser.
pub mod codes {
    /// The text does not follow the grammar.
    pub const SYNTAX: &str = "E001";
    /// Brackets or block comments nested deeper than 256 (the parser's `MAX_NESTING`).
    pub const TOO_DEEP: &str = "E002";
    /// A number literal too large for a 64-bit float.
    pub const NON_FINITE: &str = "E012";
}

/// Human words for a grammar rule, used in "expected ..." messages. The match is exhaustive
/// on purpose: adding a rule to the grammar forces choosing its words here.
pub fn describe(rule: Rule) -> &'static str {
    match rule {
        Rule::EOI => "end of file",
        Rule::WHITESPACE | Rule::COMMENT | Rule::line_comment | Rule::block_comment => "whitespace",
        Rule::ident_char => "a letter, digit or `_`",
        Rule::item => {
            "`import`, `let`, `solver`, `site type`, `piece`, `stretch`, `merge`, `cut` or `model`"
        }
        Rule::piece_stmt => "a piece statement",
        Rule::state_stmt => "a state statement",
        Rule::stretch_stmt => "`min`, `max` or `variants`",
        Rule::model_stmt => "an instance or a `dock`",
        Rule::name => "a name",
        Rule::number | Rule::plain => "a number",
        Rule::blank => "a space",
        Rule::expr | Rule::operand | Rule::primary => "a number",
        Rule::prefix | Rule::neg | Rule::pos => "a sign",
        Rule::infix | Rule::add | Rule::sub | Rule::mul | Rule::div => "an operator",
        Rule::call => "a function call like `sin(30)`",
        Rule::paren_expr => "`(`",
        Rule::let_decl => "a `let` constant",
        Rule::kw_let => "`let`",
        Rule::kw_extrude => "`extrude`",
        Rule::kw_above => "`above`",
        Rule::extrude => "`extrude HEIGHT [above BASE]`",
        Rule::integer => "a whole number",
        Rule::colour => "a colour like `#b5651d`",
        Rule::point | Rule::plain_point => "a point `(x, y)`",
        Rule::kw_solver => "`solver`",
        Rule::kw_site => "`site`",
        Rule::kw_type => "`type`",
        Rule::kw_docks => "`docks`",
        Rule::kw_piece => "`piece`",
        Rule::kw_vertex => "`vertex`",
        Rule::kw_edges => "`edges`",
        Rule::kw_out => "`out`",
        Rule::kw_axis => "`axis`",
        Rule::kw_polygon => "`polygon`",
        Rule::kw_polyline => "`polyline`",
        Rule::kw_rigid => "`rigid`",
        Rule::kw_skinned => "`skinned`",
        Rule::kw_fill => "`fill`",
        Rule::kw_width => "`width`",
        Rule::kw_hole => "`hole`",
        Rule::kw_state => "`state`",
        Rule::kw_stretch => "`stretch`",
        Rule::kw_from => "`from`",
        Rule::kw_to => "`to`",
        Rule::kw_min => "`min`",
        Rule::kw_max => "`max`",
        Rule::kw_variants => "`variants`",
        Rule::kw_merge => "`merge`",
        Rule::kw_onto => "`onto`",
        Rule::kw_into => "`into`",
        Rule::kw_within => "`within`",
        Rule::kw_cut => "`cut`",
        Rule::kw_model => "`model`",
        Rule::kw_chain => "`chain`",
        Rule::kw_x => "`x`",
        Rule::kw_along => "`along`",
        Rule::kw_at => "`at`",
        Rule::kw_rotate => "`rotate`",
        Rule::kw_dock => "`dock`",
        Rule::kw_last => "`last`",
        Rule::kw_bend => "`bend`",
        Rule::kw_mirror => "`mirror`",
        Rule::kw_import => "`import`",
        Rule::kw_extends => "`extends`",
        Rule::kw_mesh => "`mesh`",
        Rule::string => "a file path in double quotes, like `\"lib.clay\"`",
        Rule::import_decl => "an `import`",
        Rule::extends => "`extends`",
        Rule::lbrace => "`{`",
        Rule::rbrace => "`}`",
        Rule::lparen => "`(`",
        Rule::rparen => "`)`",
        Rule::lbracket => "`[`",
        Rule::rbracket => "`]`",
        Rule::comma => "`,`",
        Rule::colon => "`:`",
        Rule::equals => "`=`",
        Rule::arrow => "`->`",
        Rule::dash => "`-`",
        Rule::dot => "`.`",
        Rule::file => {
            "`import`, `let`, `solver`, `site type`, `piece`, `stretch`, `merge`, `cut`, `model` or end of file"
        }
        Rule::solver_block => "a `solver` block",
        Rule::solver_entry => "a solver parameter `NAME = NUMBER`",
        Rule::site_type_decl => "a `site type` declaration",
        Rule::piece_decl => "a `piece`",
        Rule::vertex_decl => "a `vertex`",
        Rule::edges_decl => "`edges`",
        Rule::edge_path => "an edge path `a-b-c`",
        Rule::site_decl => "a `site`",
        Rule::vertex_list => "a vertex list `[a, b]`",
        Rule::axis_decl => "an `axis`",
        Rule::binding => "`rigid` or `skinned`",
        Rule::polygon_decl => "a `polygon`",
        Rule::hole => "a `hole`",
        Rule::polyline_decl => "a `polyline`",
        Rule::mesh_decl => "a `mesh`",
        Rule::point_list => "points",
        Rule::state_decl => "a `state`",
        Rule::state_position => "a vertex position `NAME (x, y)`",
        Rule::state_derive => "`bend` or `mirror`",
        Rule::state_bend => "`bend ANGLE`",
        Rule::state_mirror => "`mirror STATE`",
        Rule::derived_body => "`{`",
        Rule::derived_stmt => "a `polygon` or `polyline`",
        Rule::stretch_decl => "a `stretch` rule",
        Rule::min_decl => "`min`",
        Rule::max_decl => "`max`",
        Rule::variants_decl => "`variants`",
        Rule::variant => "a variant `PIECE FREQUENCY`",
        Rule::merge_decl => "a `merge` rule",
        Rule::site_path => "a site `PIECE.SITE`",
        Rule::cut_decl => "a `cut` rule",
        Rule::model_block => "a `model` block",
        Rule::dock_decl => "a `dock`",
        Rule::instance_site => "an instance site `INSTANCE.SITE`",
        Rule::element_index => "an element index `[N]`",
        Rule::chain_decl => "a `chain`",
        Rule::along => "`along`",
        Rule::instance_decl => "an instance `NAME = PIECE`",
        Rule::at => "`at`",
        Rule::rotate => "`rotate`",
    }
}

/// Parses a whole file. Errors are returned as diagnostics; the tree is only returned for text
/// that follows the grammar and whose numbers are all finite.
pub fn parse(source: &str) -> Result<File, Diagnostics> {
    let base = span_base();
    let scan = scan(source);
    if let Some(d) = scan.too_deep {
        return Err(d.shifted(base).into());
    }
    let mut pairs = match ClayParser::parse(Rule::file, source) {
        Ok(p) => p,
        Err(e) => {
            // A comment left open swallows the rest of the file: that is the mistake, unless
            // the text has one before it.
            let d = match scan.unclosed_comment {
                Some(open) if open.start <= error_position(&e) => unclosed_comment(open),
                _ => syntax_error(source, e),
            };
            return Err(d.shifted(base).into());
        }
    };
    let Some(file) = pairs.next() else {
        return Err(
            Diagnostic::error(codes::SYNTAX, "empty parse", Span::new(base, base), "here").into(),
        );
    };
    let mut lower = Lower {
        diags: Diagnostics::new(),
    };
    let tree = lower.file(file);
    if lower.diags.has_errors() {
        Err(lower.diags)
    } else {
        Ok(tree)
    }
}

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
struct Scan {
    /// E002 at the first place nested deeper than [`MAX_NESTING`] (brackets of any kind, or
    /// block comments): rejected before the recursive parser runs.
    too_deep: Option<Diagnostic>,
    /// The `/*` of the outermost block comment still open at the end of the text.
    unclosed_comment: Option<Span>,
}

/// One linear scan of the source for the nesting guard and the unclosed-comment check.
fn scan(source: &str) -> Scan {
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
fn unclosed_comment(open: Span) -> Diagnostic {
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

/// Where pest stopped.
fn error_position(e: &pest::error::Error<Rule>) -> usize {
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

fn syntax_error(source: &str, e: pest::error::Error<Rule>) -> Diagnostic {
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

/// The innermost bracket left open at the end of the source (comments skipped).
fn unclosed(source: &str) -> Option<Span> {
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
        return Some("a statement ends with its line: remove the `;`".into());
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
        return Some("a file is a list of `import`, `solver`, `site type`, `piece`, `stretch`, `merge`, `cut` and `model` items".into());
    }
    None
}

/// The lowering pass: pest pairs -> syntax tree.
struct Lower {
    diags: Diagnostics,
}

/// The span of a pair without the trailing whitespace and comments pest includes when an
/// optional tail was tried and not found: it ends where its last token ends.
fn span_of(p: &Pair<Rule>) -> Span {
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

fn span_base() -> usize {
    SPAN_BASE.with(std::cell::Cell::get)
}

/// Parses a file whose text starts at global position `base` (an imported file): every span
/// of the tree and of the diagnostics is offset by `base`.
pub(crate) fn parse_at(source: &str, base: usize) -> Result<File, Diagnostics> {
    struct Reset;
    impl Drop for Reset {
        fn drop(&mut self) {
            SPAN_BASE.with(|b| b.set(0));
        }
    }
    let _reset = Reset;
    SPAN_BASE.with(|b| b.set(base));
    parse(source)
}

/// Children that carry meaning: punctuation is dropped.
fn kids(p: Pair<Rule>) -> Vec<Pair<Rule>> {
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
                    | Rule::EOI
            )
        })
        .collect()
}

/// Children of one rule, in order.
fn of<'i>(children: &[Pair<'i, Rule>], rule: Rule) -> Vec<Pair<'i, Rule>> {
    children
        .iter()
        .filter(|c| c.as_rule() == rule)
        .cloned()
        .collect()
}

fn first<'i>(children: &[Pair<'i, Rule>], rule: Rule) -> Option<Pair<'i, Rule>> {
    children.iter().find(|c| c.as_rule() == rule).cloned()
}

impl Lower {
    fn ident(&self, p: Pair<Rule>) -> Ident {
        Ident {
            name: p.as_str().to_string(),
            span: span_of(&p),
        }
    }

    /// The first name among `children`, or an empty one at `span` (the grammar guarantees one;
    /// this keeps lowering total).
    fn name_or(&self, children: &[Pair<Rule>], span: Span) -> Ident {
        first(children, Rule::name).map_or(
            Ident {
                name: String::new(),
                span,
            },
            |n| self.ident(n),
        )
    }

    fn idents(&self, children: &[Pair<Rule>]) -> Vec<Ident> {
        of(children, Rule::name)
            .into_iter()
            .map(|p| self.ident(p))
            .collect()
    }

    fn number(&mut self, p: Pair<Rule>) -> Expr {
        self.literal(p.as_str(), span_of(&p))
    }

    /// A decimal literal's value, or E012 at `span` when it does not fit in an f64.
    fn literal(&mut self, text: &str, span: Span) -> Expr {
        // The grammar only admits decimal literals, which Rust's float parser accepts; a
        // literal beyond f64's range parses to infinity and is reported here.
        let value = text.parse::<f64>().unwrap_or(f64::NAN);
        if !value.is_finite() {
            self.diags.push(
                Diagnostic::error(
                    codes::NON_FINITE,
                    "number is too large",
                    span,
                    "does not fit in a 64-bit float",
                )
                .with_hint("numbers must be finite; the largest is about 1.8e308"),
            );
            return Expr::number(0.0, span);
        }
        Expr::number(value, span)
    }

    /// An `expr` pair (or a missing one, as zero at `fallback`) as a tree.
    fn expr_or(&mut self, p: Option<Pair<Rule>>, fallback: Span) -> Expr {
        match p {
            Some(p) => self.expr(p).0,
            None => Expr::number(0.0, fallback),
        }
    }

    /// Lowers an `expr` pair, a flat list `operand (infix operand)*`, into a tree by
    /// precedence (shunting-yard, so no recursion per operator), and returns it with its depth.
    /// A tree deeper than [`MAX_EXPR_DEPTH`] is reported: every later pass walks it recursively.
    fn expr(&mut self, p: Pair<Rule>) -> (Expr, usize) {
        let span = span_of(&p);
        let mut operands: Vec<(Expr, usize)> = Vec::new();
        let mut operators: Vec<BinaryOp> = Vec::new();
        let mut prefixes: Vec<(UnaryOp, usize)> = Vec::new();
        for c in kids(p) {
            let start = c.as_span().start();
            let op = match c.as_rule() {
                Rule::neg => {
                    prefixes.push((UnaryOp::Neg, start));
                    continue;
                }
                Rule::pos => {
                    prefixes.push((UnaryOp::Plus, start));
                    continue;
                }
                Rule::add => BinaryOp::Add,
                Rule::sub => BinaryOp::Sub,
                Rule::mul => BinaryOp::Mul,
                Rule::div => BinaryOp::Div,
                _ => {
                    let mut operand = self.primary(c);
                    // Never build a tree deeper than the limit (dropping one would recurse).
                    if operand.1 + prefixes.len() > MAX_EXPR_DEPTH {
                        prefixes.clear();
                        operand = (Expr::number(0.0, operand.0.span), MAX_EXPR_DEPTH + 1);
                    }
                    while let Some((op, start)) = prefixes.pop() {
                        let span = Span::new(start, operand.0.span.end);
                        operand = (
                            Expr {
                                kind: ExprKind::Unary(op, Box::new(operand.0)),
                                span,
                            },
                            operand.1 + 1,
                        );
                    }
                    operands.push(operand);
                    continue;
                }
            };
            while operators
                .last()
                .is_some_and(|top| top.precedence() >= op.precedence())
            {
                reduce(&mut operands, &mut operators);
            }
            operators.push(op);
        }
        while !operators.is_empty() {
            reduce(&mut operands, &mut operators);
        }
        let (tree, depth) = operands.pop().unwrap_or((Expr::number(0.0, span), 1));
        if depth > MAX_EXPR_DEPTH {
            self.diags.push(
                Diagnostic::error(
                    codes::TOO_DEEP,
                    "expression is nested too deeply",
                    span,
                    format!("more than {MAX_EXPR_DEPTH} levels of operators and parentheses"),
                )
                .with_hint("split it into several `let` constants"),
            );
            return (Expr::number(0.0, span), 1);
        }
        (tree, depth)
    }

    fn primary(&mut self, c: Pair<Rule>) -> (Expr, usize) {
        let span = span_of(&c);
        match c.as_rule() {
            Rule::number => (self.number(c), 1),
            Rule::name => (
                Expr {
                    kind: ExprKind::Name(Box::new(self.ident(c))),
                    span,
                },
                1,
            ),
            Rule::paren_expr => {
                let inner = first(&kids(c), Rule::expr).map(|e| self.expr(e));
                let (inner, depth) = inner.unwrap_or((Expr::number(0.0, span), 1));
                (
                    Expr {
                        kind: ExprKind::Paren(Box::new(inner)),
                        span,
                    },
                    depth + 1,
                )
            }
            Rule::call => {
                let ch = kids(c);
                let func = self.name_or(&ch, span);
                let mut depth = 1;
                let mut args = Vec::new();
                for a in of(&ch, Rule::expr) {
                    let (arg, d) = self.expr(a);
                    depth = depth.max(d + 1);
                    args.push(arg);
                }
                (
                    Expr {
                        kind: ExprKind::Call(Box::new(Call { func, args })),
                        span,
                    },
                    depth,
                )
            }
            _ => (Expr::number(0.0, span), 1),
        }
    }

    fn point(&mut self, p: Pair<Rule>) -> Point {
        let span = span_of(&p);
        let mut inner = p.clone().into_inner();
        if let Some(q) = inner.next().filter(|q| q.as_rule() == Rule::plain_point) {
            return self.plain_point(q.as_str(), span);
        }
        let mut coords = kids(p)
            .into_iter()
            .filter(|c| matches!(c.as_rule(), Rule::expr | Rule::plain));
        let mut coord = |s: &mut Self| match coords.next() {
            // A plain literal (with its sign) is a number: its text parses as one.
            Some(c) if c.as_rule() == Rule::plain => s.number(c),
            c => s.expr_or(c, span),
        };
        let x = coord(self);
        let y = coord(self);
        Point { x, y, span }
    }

    /// A `plain_point` token, `(x, y)` with two literals and only blanks between: its
    /// coordinates are found in its text, each with the span of its digits.
    fn plain_point(&mut self, text: &str, span: Span) -> Point {
        let inside = &text[1..text.len() - 1];
        let comma = inside.find(',').unwrap_or(inside.len());
        let coord = |s: &mut Self, from: usize, to: usize| {
            let part = &inside[from..to];
            let lead = part.len() - part.trim_start().len();
            let digits = part.trim();
            let start = span.start + 1 + from + lead;
            s.literal(digits, Span::new(start, start + digits.len()))
        };
        let x = coord(self, 0, comma);
        let y = coord(self, (comma + 1).min(inside.len()), inside.len());
        Point { x, y, span }
    }

    fn points(&mut self, p: Pair<Rule>) -> Vec<Point> {
        of(&kids(p), Rule::point)
            .into_iter()
            .map(|q| self.point(q))
            .collect()
    }

    fn colour(&self, p: Pair<Rule>) -> Colour {
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

    fn file(&mut self, p: Pair<Rule>) -> File {
        let span = span_of(&p);
        let mut items = Vec::new();
        for c in kids(p) {
            let item = match c.as_rule() {
                Rule::let_decl => Item::Let(self.let_decl(c)),
                Rule::import_decl => Item::Import(self.import(c)),
                Rule::solver_block => Item::Solver(self.solver(c)),
                Rule::site_type_decl => Item::SiteType(self.site_type(c)),
                Rule::piece_decl => Item::Piece(self.piece(c)),
                Rule::stretch_decl => Item::Stretch(self.stretch(c)),
                Rule::merge_decl => Item::Merge(self.merge(c)),
                Rule::cut_decl => Item::Cut(self.cut(c)),
                Rule::model_block => Item::Model(self.model(c)),
                _ => continue,
            };
            items.push(item);
        }
        File { items, span }
    }

    fn let_decl(&mut self, p: Pair<Rule>) -> LetDecl {
        let span = span_of(&p);
        let ch = kids(p);
        let name = self.name_or(&ch, span);
        let value = self.expr_or(first(&ch, Rule::expr), span);
        LetDecl { name, value, span }
    }

    fn import(&mut self, p: Pair<Rule>) -> ImportDecl {
        let span = span_of(&p);
        let path = self.string_or(first(&kids(p), Rule::string), span);
        ImportDecl { path, span }
    }

    /// A quoted path without its quotes (empty at `span` when the parser recovered without one).
    fn string_or(&mut self, s: Option<Pair<Rule>>, span: Span) -> StringLit {
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

    fn solver(&mut self, p: Pair<Rule>) -> SolverBlock {
        let span = span_of(&p);
        let ch = kids(p);
        let keyword = first(&ch, Rule::kw_solver).map_or(span, |k| span_of(&k));
        let mut entries = Vec::new();
        for e in of(&ch, Rule::solver_entry) {
            let espan = span_of(&e);
            let ec = kids(e);
            let (Some(n), Some(v)) = (first(&ec, Rule::name), first(&ec, Rule::expr)) else {
                continue;
            };
            let name = self.ident(n);
            let value = self.expr(v).0;
            entries.push(SolverEntry {
                name,
                value,
                span: espan,
            });
        }
        SolverBlock {
            entries,
            keyword,
            span,
        }
    }

    fn site_type(&mut self, p: Pair<Rule>) -> SiteTypeDecl {
        let span = span_of(&p);
        let mut names = self.idents(&kids(p)).into_iter();
        let name = names.next().unwrap_or(Ident {
            name: String::new(),
            span,
        });
        SiteTypeDecl {
            name,
            docks: names.collect(),
            span,
        }
    }

    fn piece(&mut self, p: Pair<Rule>) -> PieceDecl {
        let span = span_of(&p);
        let ch = kids(p);
        let name = self.name_or(&ch, span);
        let extends = first(&ch, Rule::extends)
            .and_then(|e| first(&kids(e), Rule::name))
            .map(|n| self.ident(n));
        let mut stmts = Vec::new();
        for c in ch {
            let stmt = match c.as_rule() {
                Rule::vertex_decl => PieceStmt::Vertex(self.vertex(c)),
                Rule::edges_decl => PieceStmt::Edges(self.edges(c)),
                Rule::site_decl => PieceStmt::Site(self.site(c)),
                Rule::axis_decl => {
                    let aspan = span_of(&c);
                    let names = self.idents(&kids(c));
                    let (Some(from), Some(to)) = (names.first(), names.get(1)) else {
                        continue;
                    };
                    PieceStmt::Axis(AxisDecl {
                        from: from.clone(),
                        to: to.clone(),
                        span: aspan,
                    })
                }
                Rule::polygon_decl | Rule::polyline_decl | Rule::mesh_decl => {
                    PieceStmt::Geometry(self.geometry(c))
                }
                Rule::state_decl => PieceStmt::State(self.state(c)),
                _ => continue,
            };
            stmts.push(stmt);
        }
        PieceDecl {
            name,
            extends,
            stmts,
            span,
        }
    }

    fn vertex(&mut self, p: Pair<Rule>) -> VertexDecl {
        let span = span_of(&p);
        let ch = kids(p);
        let name = self.name_or(&ch, span);
        let pos = first(&ch, Rule::point).map(|q| self.point(q));
        let zero = Expr::number(0.0, span);
        VertexDecl {
            name,
            pos: pos.unwrap_or(Point {
                x: zero.clone(),
                y: zero,
                span,
            }),
            span,
        }
    }

    fn edges(&mut self, p: Pair<Rule>) -> EdgesDecl {
        let span = span_of(&p);
        let paths = of(&kids(p), Rule::edge_path)
            .into_iter()
            .map(|path| self.idents(&kids(path)))
            .collect();
        EdgesDecl { paths, span }
    }

    fn site(&mut self, p: Pair<Rule>) -> SiteDecl {
        let span = span_of(&p);
        let ch = kids(p);
        let names = self.idents(&ch);
        let empty = Ident {
            name: String::new(),
            span,
        };
        let list = first(&ch, Rule::vertex_list);
        let vertices_span = list.as_ref().map_or(span, span_of);
        let vertices = list.map(|l| self.idents(&kids(l))).unwrap_or_default();
        let out = first(&ch, Rule::point).map(|q| self.point(q));
        let zero = Expr::number(0.0, span);
        SiteDecl {
            name: names.first().cloned().unwrap_or(empty.clone()),
            site_type: names.get(1).cloned().unwrap_or(empty),
            vertices,
            vertices_span,
            out: out.unwrap_or(Point {
                x: zero.clone(),
                y: zero,
                span,
            }),
            span,
        }
    }

    fn geometry(&mut self, p: Pair<Rule>) -> GeometryDecl {
        let span = span_of(&p);
        let rule = p.as_rule();
        let ch = kids(p);
        let keyword = ch.first().map_or(span, span_of);
        let binding = first(&ch, Rule::binding).map(|b| {
            let bspan = span_of(&b);
            let kind = if b.as_str().starts_with("skinned") {
                BindingKw::Skinned
            } else {
                BindingKw::Rigid
            };
            (kind, bspan)
        });
        let fill = first(&ch, Rule::colour).map_or(
            Colour {
                rgba: [255; 4],
                span,
            },
            |c| self.colour(c),
        );
        let points = first(&ch, Rule::point_list)
            .map(|l| self.points(l))
            .unwrap_or_default();
        let shape = if rule == Rule::mesh_decl {
            ShapeDecl::Mesh {
                path: self.string_or(first(&ch, Rule::string), span),
                fill: first(&ch, Rule::colour).map(|c| self.colour(c)),
            }
        } else if rule == Rule::polygon_decl {
            let holes = of(&ch, Rule::hole)
                .into_iter()
                .map(|h| {
                    let hspan = span_of(&h);
                    let points = first(&kids(h), Rule::point_list)
                        .map(|l| self.points(l))
                        .unwrap_or_default();
                    HoleDecl {
                        points,
                        span: hspan,
                    }
                })
                .collect();
            ShapeDecl::Polygon {
                outer: points,
                holes,
            }
        } else {
            let width = self.expr_or(first(&ch, Rule::expr), span);
            ShapeDecl::Polyline { width, points }
        };
        let extrude = first(&ch, Rule::extrude).map(|e| {
            let espan = span_of(&e);
            let mut exprs = of(&kids(e), Rule::expr).into_iter();
            let height = self.expr_or(exprs.next(), espan);
            let above = exprs.next().map(|b| self.expr(b).0);
            ExtrudeDecl {
                height,
                above,
                span: espan,
            }
        });
        GeometryDecl {
            shape,
            binding,
            fill,
            extrude,
            keyword,
            span,
        }
    }

    fn state(&mut self, p: Pair<Rule>) -> StateDecl {
        let span = span_of(&p);
        let ch = kids(p);
        let name = self.name_or(&ch, span);
        let mut positions = Vec::new();
        let mut edges = Vec::new();
        let mut geometry = Vec::new();
        let mut derive = None;
        for c in ch {
            match c.as_rule() {
                Rule::state_position => positions.push(self.vertex(c)),
                Rule::edges_decl => edges.push(self.edges(c)),
                Rule::polygon_decl | Rule::polyline_decl => geometry.push(self.geometry(c)),
                Rule::state_bend | Rule::state_mirror => derive = self.state_derive(c),
                Rule::derived_body => {
                    for g in kids(c) {
                        geometry.push(self.geometry(g));
                    }
                }
                _ => {}
            }
        }
        StateDecl {
            name,
            positions,
            edges,
            geometry,
            derive,
            span,
        }
    }

    /// `bend ANGLE` or `mirror OTHER`.
    fn state_derive(&mut self, p: Pair<Rule>) -> Option<StateDerive> {
        let span = span_of(&p);
        let is_bend = p.as_rule() == Rule::state_bend;
        let ch = kids(p);
        let keyword = span_of(ch.first()?);
        let kind = if is_bend {
            DeriveKind::Bend(self.expr(first(&ch, Rule::expr)?).0)
        } else {
            DeriveKind::Mirror(self.ident(first(&ch, Rule::name)?))
        };
        Some(StateDerive {
            kind,
            keyword,
            span,
        })
    }

    fn stretch(&mut self, p: Pair<Rule>) -> StretchDecl {
        let span = span_of(&p);
        let ch = kids(p);
        let names = self.idents(&ch);
        let empty = Ident {
            name: String::new(),
            span,
        };
        let min = of(&ch, Rule::min_decl)
            .into_iter()
            .filter_map(|m| first(&kids(m), Rule::expr))
            .map(|n| self.expr(n).0)
            .collect();
        let max = of(&ch, Rule::max_decl)
            .into_iter()
            .filter_map(|m| first(&kids(m), Rule::expr))
            .map(|n| self.expr(n).0)
            .collect();
        let variants = of(&ch, Rule::variants_decl)
            .into_iter()
            .map(|v| {
                let vspan = span_of(&v);
                let entries = of(&kids(v), Rule::variant)
                    .into_iter()
                    .map(|e| {
                        let espan = span_of(&e);
                        let ec = kids(e);
                        let piece = self.name_or(&ec, espan);
                        let frequency = self.expr_or(first(&ec, Rule::expr), espan);
                        VariantEntry {
                            piece,
                            frequency,
                            span: espan,
                        }
                    })
                    .collect();
                VariantsDecl {
                    entries,
                    span: vspan,
                }
            })
            .collect();
        StretchDecl {
            piece: names.first().cloned().unwrap_or(empty.clone()),
            from: names.get(1).cloned().unwrap_or(empty.clone()),
            to: names.get(2).cloned().unwrap_or(empty),
            min,
            max,
            variants,
            span,
        }
    }

    fn site_path(&self, p: Pair<Rule>) -> SitePath {
        let span = span_of(&p);
        let names = self.idents(&kids(p));
        let empty = Ident {
            name: String::new(),
            span,
        };
        SitePath {
            piece: names.first().cloned().unwrap_or(empty.clone()),
            site: names.get(1).cloned().unwrap_or(empty),
            span,
        }
    }

    fn merge(&mut self, p: Pair<Rule>) -> MergeDecl {
        let span = span_of(&p);
        let ch = kids(p);
        let mut paths = of(&ch, Rule::site_path)
            .into_iter()
            .map(|s| self.site_path(s));
        let empty = SitePath {
            piece: Ident {
                name: String::new(),
                span,
            },
            site: Ident {
                name: String::new(),
                span,
            },
            span,
        };
        let mover = paths.next().unwrap_or(empty.clone());
        let target = paths.next().unwrap_or(empty);
        let junction = paths.next();
        let within = first(&ch, Rule::expr).map(|n| self.expr(n).0);
        MergeDecl {
            mover,
            target,
            junction,
            within,
            span,
        }
    }

    fn cut(&mut self, p: Pair<Rule>) -> CutDecl {
        let span = span_of(&p);
        let ch = kids(p);
        let empty = Ident {
            name: String::new(),
            span,
        };
        let junction = first(&ch, Rule::site_path)
            .map(|s| self.site_path(s))
            .unwrap_or(SitePath {
                piece: empty.clone(),
                site: empty.clone(),
                span,
            });
        let into = first(&ch, Rule::name).map_or(empty, |n| self.ident(n));
        CutDecl {
            junction,
            into,
            span,
        }
    }

    fn model(&mut self, p: Pair<Rule>) -> ModelBlock {
        let span = span_of(&p);
        let ch = kids(p);
        let keyword = first(&ch, Rule::kw_model).map_or(span, |k| span_of(&k));
        let mut stmts = Vec::new();
        for c in ch {
            let cspan = span_of(&c);
            match c.as_rule() {
                Rule::dock_decl => {
                    let mut sites = of(&kids(c), Rule::instance_site)
                        .into_iter()
                        .map(|s| self.instance_site(s));
                    let (Some(a), Some(b)) = (sites.next(), sites.next()) else {
                        continue;
                    };
                    stmts.push(ModelStmt::Dock(DockDecl { a, b, span: cspan }));
                }
                Rule::chain_decl => {
                    let cc = kids(c);
                    let names = self.idents(&cc);
                    let empty = Ident {
                        name: String::new(),
                        span: cspan,
                    };
                    let count = self.expr_or(first(&cc, Rule::expr), cspan);
                    let along = first(&cc, Rule::along).and_then(|a| {
                        let n = self.idents(&kids(a));
                        Some((n.first()?.clone(), n.get(1)?.clone()))
                    });
                    let (at, rotate) = self.placement(&cc);
                    stmts.push(ModelStmt::Chain(ChainDecl {
                        name: names.first().cloned().unwrap_or(empty.clone()),
                        piece: names.get(1).cloned().unwrap_or(empty),
                        count,
                        along,
                        at,
                        rotate,
                        span: cspan,
                    }));
                }
                Rule::instance_decl => {
                    let cc = kids(c);
                    let names = self.idents(&cc);
                    let empty = Ident {
                        name: String::new(),
                        span: cspan,
                    };
                    let (at, rotate) = self.placement(&cc);
                    stmts.push(ModelStmt::Instance(InstanceDecl {
                        name: names.first().cloned().unwrap_or(empty.clone()),
                        piece: names.get(1).cloned().unwrap_or(empty),
                        at,
                        rotate,
                        span: cspan,
                    }));
                }
                _ => {}
            }
        }
        ModelBlock {
            stmts,
            keyword,
            span,
        }
    }

    fn placement(&mut self, ch: &[Pair<Rule>]) -> (Option<Point>, Option<Expr>) {
        let at = first(ch, Rule::at)
            .and_then(|a| first(&kids(a), Rule::point))
            .map(|p| self.point(p));
        let rotate = first(ch, Rule::rotate)
            .and_then(|r| first(&kids(r), Rule::expr))
            .map(|n| self.expr(n).0);
        (at, rotate)
    }

    fn instance_site(&self, p: Pair<Rule>) -> InstanceSitePath {
        let span = span_of(&p);
        let ch = kids(p);
        let names = self.idents(&ch);
        let empty = Ident {
            name: String::new(),
            span,
        };
        let index = first(&ch, Rule::element_index).map(|e| {
            let espan = span_of(&e);
            let index = match first(&kids(e), Rule::integer) {
                // Absurdly long indices saturate; they are out of range either way.
                Some(i) => ElementIndexKind::At(i.as_str().parse().unwrap_or(u64::MAX)),
                None => ElementIndexKind::Last,
            };
            ElementIndex { index, span: espan }
        });
        InstanceSitePath {
            instance: names.first().cloned().unwrap_or(empty.clone()),
            index,
            site: names.get(1).cloned().unwrap_or(empty),
            span,
        }
    }
}
