//! The rule declarations: `stretch` (with its `min`, `max` and `variants`), `merge` and `cut`.

use pest::iterators::Pair;

use super::grammar::Rule;
use super::lower::{Lower, first, kids, of, span_of};
use crate::syntax::*;

impl Lower {
    pub(super) fn stretch(&mut self, p: Pair<Rule>) -> StretchDecl {
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

    pub(super) fn merge(&mut self, p: Pair<Rule>) -> MergeDecl {
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

    pub(super) fn cut(&mut self, p: Pair<Rule>) -> CutDecl {
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
}
