//! Text -> syntax tree: runs the pest grammar and lowers its pairs by hand into the typed tree
//! of `syntax.rs`. Parsing knows nothing of compilation; it only reports text that is not a
//! `.clay` file (syntax errors, number literals that overflow, nesting too deep to parse).
//!
//! The files, in the order text meets them: `scan.rs` (nesting and unclosed comments, before
//! pest), `grammar.rs` (the pest parser and the words for its rules), `errors.rs` (syntax
//! errors as diagnostics), `codes.rs`; then the lowering: `lower.rs` (its state and shared
//! tools), `expr.rs` (expressions and points), `items.rs` (`let`, `param`, `import`, `solver`),
//! `pieces.rs`, `rules.rs` (stretch, merge, cut) and `model.rs`. This file is the entry and
//! the list of a file's items; the others import their siblings, never this file.

pub mod codes;
mod errors;
mod expr;
mod grammar;
mod items;
mod lower;
mod model;
mod pieces;
mod rules;
mod scan;

use pest::Parser;
use pest::iterators::Pair;

use crate::diagnostic::{Diagnostic, Diagnostics};
use crate::syntax::*;
use errors::{error_position, syntax_error};
use grammar::{ClayParser, Rule};
use lower::{Lower, kids, span_base, span_of};
use scan::{scan, unclosed_comment};

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

/// Parses a file whose text starts at global position `base` (an imported file): every span
/// of the tree and of the diagnostics is offset by `base`.
pub(crate) fn parse_at(source: &str, base: usize) -> Result<File, Diagnostics> {
    lower::with_span_base(base, || parse(source))
}

impl Lower {
    /// A whole file: each item lowered by the file that knows its construct.
    fn file(&mut self, p: Pair<Rule>) -> File {
        let span = span_of(&p);
        let mut items = Vec::new();
        for c in kids(p) {
            let item = match c.as_rule() {
                Rule::let_decl => Item::Let(self.let_decl(c)),
                Rule::param_decl => Item::Param(self.param_decl(c)),
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
}
