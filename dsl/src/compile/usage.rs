//! Finds pieces nothing uses (W001) and rules that can never fire (W002).

use super::codes;
use super::state::Compiler;
use crate::compiled::ParamKind;
use crate::diagnostic::Diagnostic;
use crate::syntax::{self, Item, ModelStmt};

/// Which pieces the model names.
pub(super) struct Usage {
    /// False when a model statement names an unknown piece: the model is then incomplete and
    /// usage warnings would mislead.
    complete: bool,
    in_model: Vec<bool>,
    /// Named by a rule (stretch piece or variant, merge junction, cut junction or target).
    named: Vec<bool>,
}

impl Usage {
    pub fn find(c: &Compiler, file: &syntax::File, model: Option<&syntax::ModelBlock>) -> Self {
        let mut in_model = vec![false; c.pieces.len()];
        let mut complete = true;
        // Names written in rules count as uses even when the rule had errors (already
        // reported): warning that its pieces are unused would only add noise.
        let mut named = vec![false; c.pieces.len()];
        let mut name = |n: &str| {
            if let Some(&i) = c.piece_index.get(n) {
                named[i] = true;
            }
        };
        for item in &file.items {
            match item {
                // A base that other pieces extend is used by them.
                Item::Piece(p) => {
                    if let Some(b) = &p.extends {
                        name(&b.name);
                    }
                }
                Item::Stretch(s) => {
                    name(&s.piece.name);
                    s.variants
                        .iter()
                        .flat_map(|v| &v.entries)
                        .for_each(|e| name(&e.piece.name));
                }
                Item::Merge(m) => {
                    if let Some(j) = &m.junction {
                        name(&j.piece.name);
                    }
                }
                Item::Cut(cut) => {
                    name(&cut.junction.piece.name);
                    name(&cut.into.name);
                }
                _ => {}
            }
        }
        let mut stmts = Vec::new();
        ModelStmt::walk(model.map_or(&[][..], |m| &m.stmts), &mut stmts);
        for stmt in stmts {
            let name = match stmt {
                ModelStmt::Instance(d) => &d.piece.name,
                ModelStmt::Chain(d) => &d.piece.name,
                ModelStmt::Dock(_) | ModelStmt::If(_) => continue,
            };
            // A choice parameter puts each of its pieces in the model, for some value.
            let names: Vec<&str> = match c.param(name).map(|p| &p.kind) {
                Some(ParamKind::Choice { choices }) => choices.iter().map(String::as_str).collect(),
                _ => vec![name.as_str()],
            };
            for name in names {
                match c.piece_index.get(name) {
                    Some(&i) => in_model[i] = true,
                    None => complete = false,
                }
            }
        }
        Self {
            complete,
            in_model,
            named,
        }
    }

    // Long because: one warning kind per declaration kind, in order.
    pub fn report(&self, c: &mut Compiler, file: &syntax::File) {
        if !self.complete {
            return;
        }
        // Pieces a rule may bring into the assembly.
        let mut mentioned: Vec<bool> = self
            .in_model
            .iter()
            .zip(&self.named)
            .map(|(a, b)| *a || *b)
            .collect();
        for cut in &c.cut_rules {
            mentioned[cut.into] = true;
        }
        // Pieces that can actually appear: the model's, then whatever firing rules insert,
        // until nothing changes.
        let mut reach = self.in_model.clone();
        loop {
            let mut changed = false;
            let mut add = |reach: &mut Vec<bool>, p: usize| {
                if !reach[p] {
                    reach[p] = true;
                    changed = true;
                }
            };
            for r in &c.stretch_rules {
                if r.variants.iter().any(|v| reach[v.piece]) || reach[r.piece] {
                    for v in &r.variants {
                        add(&mut reach, v.piece);
                    }
                }
            }
            for m in &c.merge_rules {
                if let (Some(j), true) = (m.junction, reach[m.mover.piece] && reach[m.target.piece])
                {
                    add(&mut reach, j.piece);
                }
            }
            for cut in &c.cut_rules {
                if reach[cut.junction.piece] {
                    add(&mut reach, cut.into);
                }
            }
            if !changed {
                break;
            }
        }
        for (p, used) in mentioned.iter().enumerate() {
            if !used {
                let name = c.pieces[p].name.clone();
                c.diags.push(
                    Diagnostic::warning(codes::UNUSED_PIECE, format!("piece `{name}` is never used"), c.piece_spans[p].name, "declared here")
                        .with_hint("use it in the `model`, as a stretch variant, or as a merge junction or cut target; or remove it"),
                );
            }
        }
        let mut stretch = 0;
        let mut merge = 0;
        let mut cut = 0;
        for item in &file.items {
            match item {
                Item::Stretch(s)
                    if stretch < c.stretch_rules.len() && c.stretch_spans[stretch] == s.span =>
                {
                    let r = &c.stretch_rules[stretch];
                    stretch += 1;
                    if !reach[r.piece] && !r.variants.iter().any(|v| reach[v.piece]) {
                        let name = c.pieces[r.piece].name.clone();
                        c.diags.push(
                            Diagnostic::warning(
                                codes::DEAD_RULE,
                                "this stretch rule can never fire",
                                crate::syntax::Span::new(s.span.start, s.to.span.end),
                                format!("no instance of `{name}` can ever be in the assembly"),
                            )
                            .with_hint(format!(
                                "add `{name}` to the model, e.g. `{name}s = chain {name} x 2`"
                            )),
                        );
                    }
                }
                Item::Merge(s) if merge < c.merge_rules.len() && c.merge_spans[merge] == s.span => {
                    let r = c.merge_rules[merge].clone();
                    merge += 1;
                    let missing: Vec<String> = [r.mover.piece, r.target.piece]
                        .iter()
                        .filter(|&&p| !reach[p])
                        .map(|&p| format!("`{}`", c.pieces[p].name))
                        .collect();
                    if !missing.is_empty() {
                        c.diags.push(
                            Diagnostic::warning(
                                codes::DEAD_RULE,
                                "this merge rule can never fire",
                                s.span,
                                format!("{} never appears in the assembly", missing.join(" and ")),
                            )
                            .with_hint("a merge fires only when instances of both pieces exist"),
                        );
                    }
                }
                Item::Cut(s) => {
                    let Some(k) = (cut..c.cut_rules.len())
                        .find(|&k| !c.cut_rules[k].derived && c.cut_spans.get(k) == Some(&s.span))
                    else {
                        continue;
                    };
                    cut = k + 1;
                    let r = c.cut_rules[k].clone();
                    if !reach[r.junction.piece] {
                        let name = c.pieces[r.junction.piece].name.clone();
                        c.diags.push(
                            Diagnostic::warning(codes::DEAD_RULE, "this cut rule can never fire", s.span, format!("`{name}` never appears in the assembly"))
                                .with_hint(format!("a cut fires on an instance of `{name}`: add one to the model, or a `merge ... into {name}.SITE`")),
                        );
                    }
                }
                _ => {}
            }
        }
    }
}
