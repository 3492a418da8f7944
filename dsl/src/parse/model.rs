//! The `model` block: instances, chains (with `along`), their placement, and docks between
//! instance sites (`wall[2].east`, `wall[-].east`).

use pest::iterators::Pair;

use super::grammar::Rule;
use super::lower::{Lower, first, kids, of, span_of};
use crate::syntax::*;

impl Lower {
    pub(super) fn model(&mut self, p: Pair<Rule>) -> ModelBlock {
        let span = span_of(&p);
        let ch = kids(p);
        let keyword = first(&ch, Rule::kw_model).map_or(span, |k| span_of(&k));
        let stmts = self.model_stmts(ch);
        ModelBlock {
            stmts,
            keyword,
            span,
        }
    }

    /// The model statements among `ch` (other children are skipped).
    fn model_stmts(&mut self, ch: Vec<Pair<Rule>>) -> Vec<ModelStmt> {
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
                Rule::model_if => {
                    let then_close = (c.clone().into_inner())
                        .find(|x| x.as_rule() == Rule::rbrace)
                        .map_or(cspan, |b| span_of(&b));
                    let cc = kids(c);
                    let else_keyword = first(&cc, Rule::model_else)
                        .and_then(|e| first(&kids(e), Rule::kw_else))
                        .map(|k| span_of(&k));
                    let keyword = first(&cc, Rule::kw_if).map_or(cspan, |k| span_of(&k));
                    let cond = self.name_or(&cc, cspan);
                    let otherwise = first(&cc, Rule::model_else).map(|e| self.model_stmts(kids(e)));
                    let then = self.model_stmts(cc);
                    stmts.push(ModelStmt::If(IfBlock {
                        cond,
                        then,
                        otherwise,
                        keyword,
                        then_close,
                        else_keyword,
                        span: cspan,
                    }));
                }
                _ => {}
            }
        }
        stmts
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
