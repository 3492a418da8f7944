//! The small file-level items: `let` constants, `param`eters, `import`s and the `solver` block.

use pest::iterators::Pair;

use super::grammar::Rule;
use super::lower::{Lower, first, kids, of, span_of};
use crate::syntax::*;

impl Lower {
    pub(super) fn let_decl(&mut self, p: Pair<Rule>) -> LetDecl {
        let span = span_of(&p);
        let ch = kids(p);
        let name = self.name_or(&ch, span);
        let value = self.expr_or(first(&ch, Rule::expr), span);
        LetDecl { name, value, span }
    }

    pub(super) fn param_decl(&mut self, p: Pair<Rule>) -> ParamDecl {
        let span = span_of(&p);
        let ch = kids(p);
        let name = self.name_or(&ch, span);
        let ty = first(&ch, Rule::param_type).map(|t| {
            let tspan = span_of(&t);
            let tc = kids(t);
            let kind = match first(&tc, Rule::param_choice) {
                Some(c) => {
                    let strings = of(&kids(c), Rule::string);
                    ParamTypeKind::Choice(
                        strings
                            .into_iter()
                            .map(|s| self.string_or(Some(s), tspan))
                            .collect(),
                    )
                }
                None => ParamTypeKind::Named(self.name_or(&tc, tspan)),
            };
            ParamTypeDecl {
                kind,
                span: tc.first().map_or(tspan, span_of),
            }
        });
        let value = match first(&ch, Rule::string) {
            Some(s) => ParamDefault::Text(self.string_or(Some(s), span)),
            None => ParamDefault::Expr(self.expr_or(first(&ch, Rule::expr), span)),
        };
        let range = first(&ch, Rule::param_range).map(|r| {
            let rspan = span_of(&r);
            let bounds = of(&kids(r), Rule::expr);
            let mut bounds = bounds.into_iter();
            let low = self.expr_or(bounds.next(), rspan);
            let high = self.expr_or(bounds.next(), rspan);
            ParamRange {
                low,
                high,
                span: rspan,
            }
        });
        ParamDecl {
            name,
            ty,
            value,
            range,
            span,
        }
    }

    pub(super) fn import(&mut self, p: Pair<Rule>) -> ImportDecl {
        let span = span_of(&p);
        let path = self.string_or(first(&kids(p), Rule::string), span);
        ImportDecl { path, span }
    }

    pub(super) fn solver(&mut self, p: Pair<Rule>) -> SolverBlock {
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
}
