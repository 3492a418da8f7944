//! `piece NAME extends BASE { ... }`: a piece that starts as a copy of another.
//!
//! Inheritance is resolved on the syntax tree before the pieces are compiled: the child's
//! statements become BASE's (already expanded, so chains work) followed by its own, except that
//! BASE's piece-level `polygon`/`polyline`s are dropped when the child declares any (the child
//! *replaces* the proxy geometry; it never drops anything else). The child is then compiled as
//! if written out in full, so it is usable exactly like a hand-written piece.
//!
//! Diagnostics: redeclaring an inherited vertex, site, state or axis is E010, with the inherited
//! declaration as secondary span; an unknown BASE is E011; a cycle is E062; a chain deeper than
//! [`MAX_EXTENDS_DEPTH`] or copying more than [`MAX_INHERITED`] statements in all is E063. A
//! child that adds vertices cannot inherit alternative rest states that give no position for
//! them (E020, and the states are not inherited). A child whose BASE has errors, is unknown or
//! is in a cycle is *poisoned*: it still exists (no "unknown piece" for its uses), but nothing
//! is reported about it or about rules that name it, as rustc does with `{type error}`.

use std::collections::HashMap;

use super::codes;
use super::state::{Child, Compiler, Inheritance};
use crate::diagnostic::Diagnostic;
use crate::syntax::{self, Ident, Item, PieceDecl, PieceStmt, Span};

/// Deepest `extends` chain accepted (a piece extending a piece ... this many times).
pub const MAX_EXTENDS_DEPTH: usize = 64;
/// Most statements inheritance may copy in one file, all children together.
pub const MAX_INHERITED: usize = 1_000_000;

/// Most pieces of an `extends` cycle named in its message and labels.
const MAX_CYCLE_SHOWN: usize = 8;

impl Inheritance {
    /// The piece (the child itself or an ancestor) whose declaration holds `span`.
    fn owner<'a>(&'a self, child: &'a str, span: Span) -> &'a str {
        let Some(c) = self.children.get(child) else {
            return child;
        };
        if inside(c.own, span) {
            return child;
        }
        c.ancestors
            .iter()
            .find(|(_, d)| inside(*d, span))
            .map_or(c.base.as_str(), |(n, _)| n.as_str())
    }
}

fn inside(outer: Span, s: Span) -> bool {
    outer.start <= s.start && s.end <= outer.end
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Walk {
    Todo,
    Active,
    Done,
}

impl Compiler {
    /// Replaces every child's statements by its expanded list (see the module comment).
    // Long because: one walk over the extends graph (cycle search, then resolution along each chain).
    pub(super) fn expand_extends(&mut self, file: &mut syntax::File) {
        if !file
            .items
            .iter()
            .any(|i| matches!(i, Item::Piece(p) if p.extends.is_some()))
        {
            return;
        }
        let items = &file.items;
        let n = items.len();
        let piece = |i: usize| match &items[i] {
            Item::Piece(p) => Some(p),
            _ => None,
        };
        // The first declaration of each name: later ones are duplicates (reported later).
        let mut first: HashMap<&str, usize> = HashMap::new();
        for i in 0..n {
            if let Some(p) = piece(i) {
                first.entry(p.name.name.as_str()).or_insert(i);
            }
        }
        // In file order, so that suggestions and "known:" lists are deterministic.
        let names: Vec<&str> = (0..n)
            .filter_map(|i| piece(i).map(|p| (i, p.name.name.as_str())))
            .filter(|(i, name)| first[name] == *i)
            .map(|(_, name)| name)
            .collect();
        let mut walk = vec![Walk::Todo; n];
        let mut expanded: Vec<Option<Vec<PieceStmt>>> = vec![None; n];
        let mut budget = MAX_INHERITED;
        let mut budget_reported = false;
        for start in 0..n {
            match piece(start) {
                Some(p) if first[p.name.name.as_str()] == start && walk[start] == Walk::Todo => {}
                _ => continue,
            }
            // Follow the bases until a plain, unknown or finished piece, or a cycle.
            let mut path = Vec::new();
            let mut cur = start;
            loop {
                walk[cur] = Walk::Active;
                path.push(cur);
                let Some(base) = piece(cur).and_then(|p| p.extends.as_ref()) else {
                    break;
                };
                let Some(&j) = first.get(base.name.as_str()) else {
                    break;
                };
                match walk[j] {
                    Walk::Done => break,
                    Walk::Todo => cur = j,
                    Walk::Active => {
                        let k = path.iter().position(|&x| x == j).unwrap_or(0);
                        let cycle: Vec<&PieceDecl> =
                            path[k..].iter().filter_map(|&i| piece(i)).collect();
                        self.extends_cycle(&cycle);
                        for &i in &path[k..] {
                            walk[i] = Walk::Done;
                            self.poisoned_child(piece(i), 0, Vec::new());
                        }
                        path.truncate(k);
                        break;
                    }
                }
            }
            for &i in path.iter().rev() {
                walk[i] = Walk::Done;
                let Some(child) = piece(i) else { continue };
                let Some(base) = &child.extends else { continue };
                let Some(&j) = first.get(base.name.as_str()) else {
                    self.unknown("piece", base, names.iter().copied(), None);
                    self.poisoned_child(Some(child), 1, Vec::new());
                    continue;
                };
                let Some(bp) = piece(j) else { continue };
                let parent = self.inheritance.children.get(&bp.name.name);
                if parent.is_some_and(|c| c.poisoned) {
                    self.poisoned_child(Some(child), 1, Vec::new());
                    continue;
                }
                let depth = parent.map_or(0, |c| c.depth) + 1;
                let mut ancestors = vec![(bp.name.name.clone(), bp.span)];
                ancestors.extend(parent.map(|c| c.ancestors.clone()).unwrap_or_default());
                if depth > MAX_EXTENDS_DEPTH {
                    self.error(
                        Diagnostic::error(
                            codes::TOO_MUCH_REUSE,
                            format!("`extends` chain too deep: `{}` is {depth} levels below a plain piece", child.name.name),
                            base.span,
                            format!("`{}` is already {} levels deep", base.name, depth - 1),
                        )
                        .with_hint(format!("a piece may be at most {MAX_EXTENDS_DEPTH} `extends` below a piece declared in full")),
                    );
                    self.poisoned_child(Some(child), depth, ancestors);
                    continue;
                }
                let inherited = expanded[j].as_deref().unwrap_or(&bp.stmts);
                if inherited.len() > budget {
                    if !std::mem::replace(&mut budget_reported, true) {
                        self.error(
                            Diagnostic::error(
                                codes::TOO_MUCH_REUSE,
                                format!("inheritance copies more than {MAX_INHERITED} statements"),
                                base.span,
                                "this `extends` passes the limit",
                            )
                            .with_hint("every `extends` copies its base's statements; declare fewer or smaller pieces through `extends`"),
                        );
                    }
                    self.poisoned_child(Some(child), depth, ancestors);
                    continue;
                }
                budget -= inherited.len();
                let (stmts, failed) = self.inherit(child, inherited, &ancestors);
                expanded[i] = Some(stmts);
                self.inheritance.children.insert(
                    child.name.name.clone(),
                    Child {
                        own: child.span,
                        base: base.name.clone(),
                        depth,
                        ancestors,
                        poisoned: false,
                        failed,
                    },
                );
            }
        }
        for (i, stmts) in expanded.into_iter().enumerate() {
            if let (Some(stmts), Item::Piece(p)) = (stmts, &mut file.items[i]) {
                p.stmts = stmts;
            }
        }
    }

    fn poisoned_child(
        &mut self,
        child: Option<&PieceDecl>,
        depth: usize,
        ancestors: Vec<(String, Span)>,
    ) {
        let Some(child) = child else { return };
        self.inheritance.children.insert(
            child.name.name.clone(),
            Child {
                own: child.span,
                base: child
                    .extends
                    .as_ref()
                    .map(|b| b.name.clone())
                    .unwrap_or_default(),
                depth,
                ancestors,
                poisoned: true,
                failed: true,
            },
        );
    }

    /// E062 for the pieces of one cycle, in the order they extend each other.
    fn extends_cycle(&mut self, cycle: &[&PieceDecl]) {
        let Some((head, rest)) = cycle.split_first() else {
            return;
        };
        let Some(at) = &head.extends else { return };
        let mut d = if rest.is_empty() {
            Diagnostic::error(
                codes::EXTENDS_CYCLE,
                format!("piece `{}` extends itself", head.name.name),
                at.span,
                "the piece's own name",
            )
        } else {
            let mut names: Vec<String> =
                cycle.iter().map(|p| format!("`{}`", p.name.name)).collect();
            names.push(format!("`{}`", head.name.name));
            // A long cycle is named by its first pieces and how many there are.
            if names.len() > MAX_CYCLE_SHOWN + 1 {
                let n = cycle.len();
                names.truncate(MAX_CYCLE_SHOWN);
                names.push(format!("... ({n} pieces in all)"));
            }
            Diagnostic::error(
                codes::EXTENDS_CYCLE,
                format!(
                    "`extends` cycle: {} extends {}",
                    names[0],
                    names[1..].join(", which extends ")
                ),
                at.span,
                format!("`{}` extends `{}` here", head.name.name, at.name),
            )
        };
        for p in rest.iter().take(MAX_CYCLE_SHOWN) {
            if let Some(b) = &p.extends {
                d = d.with_secondary(
                    b.span,
                    format!("`{}` extends `{}` here", p.name.name, b.name),
                );
            }
        }
        self.error(
            d.with_hint("a piece cannot inherit from itself: declare one of these pieces in full"),
        );
    }

    /// The child's statements after inheriting `inherited` (its base's, expanded), and whether
    /// errors of the child were reported.
    // Long because: one pass over the child's statements, each kind with its own clash check.
    fn inherit(
        &mut self,
        child: &PieceDecl,
        inherited: &[PieceStmt],
        ancestors: &[(String, Span)],
    ) -> (Vec<PieceStmt>, bool) {
        let owner = |s: Span| {
            ancestors
                .iter()
                .find(|(_, d)| inside(*d, s))
                .or(ancestors.first())
                .map_or("", |(n, _)| n.as_str())
                .to_string()
        };
        let mut vertices: HashMap<&str, Span> = HashMap::new();
        let mut sites: HashMap<&str, Span> = HashMap::new();
        let mut states: HashMap<&str, Span> = HashMap::new();
        let mut axis: Option<Span> = None;
        for s in inherited {
            match s {
                PieceStmt::Vertex(v) => {
                    vertices.entry(v.name.name.as_str()).or_insert(v.name.span);
                }
                PieceStmt::Site(x) => {
                    sites.entry(x.name.name.as_str()).or_insert(x.name.span);
                }
                PieceStmt::State(x) => {
                    states.entry(x.name.name.as_str()).or_insert(x.name.span);
                }
                PieceStmt::Axis(a) => {
                    axis.get_or_insert(a.span);
                }
                PieceStmt::Edges(_) | PieceStmt::Geometry(_) => {}
            }
        }
        let replaces = child
            .stmts
            .iter()
            .any(|s| matches!(s, PieceStmt::Geometry(_)));
        let mut out: Vec<PieceStmt> = inherited
            .iter()
            .filter(|s| !(replaces && matches!(s, PieceStmt::Geometry(_))))
            .cloned()
            .collect();
        let mut failed = false;
        let mut added: Vec<&Ident> = Vec::new();
        for s in &child.stmts {
            let axis_id;
            let clash = match s {
                PieceStmt::Vertex(v) => vertices
                    .get(v.name.name.as_str())
                    .map(|&f| ("vertex", &v.name, f)),
                PieceStmt::Site(x) => sites
                    .get(x.name.name.as_str())
                    .map(|&f| ("site", &x.name, f)),
                PieceStmt::State(x) => states
                    .get(x.name.name.as_str())
                    .map(|&f| ("state", &x.name, f)),
                PieceStmt::Axis(a) => {
                    axis_id = Ident {
                        name: "axis".into(),
                        span: a.span,
                    };
                    axis.map(|f| ("declaration", &axis_id, f))
                }
                PieceStmt::Edges(_) | PieceStmt::Geometry(_) => None,
            };
            if let Some((what, ident, first)) = clash {
                let from = owner(first);
                self.error(
                    Diagnostic::error(
                        codes::DUPLICATE,
                        format!("{what} `{}` is defined twice", ident.name),
                        ident.span,
                        "defined again here",
                    )
                    .with_secondary(first, format!("inherited from `{from}` here"))
                    .with_hint(format!(
                        "`{}` extends `{from}`, so it has this {what} already; a piece that extends another adds to it and cannot redeclare what it inherits: rename this one or remove it",
                        child.name.name
                    )),
                );
                failed = true;
                continue;
            }
            if let PieceStmt::Vertex(v) = s {
                added.push(&v.name);
            }
            out.push(s.clone());
        }
        if let Some(&new) = added.first() {
            // An inherited alternative state gives no position for a vertex the child adds.
            let lacking: Vec<(String, Span)> = out
                .iter()
                .filter_map(|s| match s {
                    // A state without positions lists none to miss (one derived from the
                    // piece's vertices covers the child's too).
                    PieceStmt::State(st)
                        if !inside(child.span, st.span)
                            && !st.positions.is_empty()
                            && added
                                .iter()
                                .any(|a| !st.positions.iter().any(|p| p.name.name == a.name)) =>
                    {
                        Some((st.name.name.clone(), st.name.span))
                    }
                    _ => None,
                })
                .collect();
            if let Some((state, span)) = lacking.first() {
                let list: Vec<String> = lacking.iter().map(|(n, _)| format!("`{n}`")).collect();
                let from = owner(*span);
                self.error(
                    Diagnostic::error(
                        codes::STATE_VERTICES,
                        format!(
                            "piece `{}` adds vertex `{}`, but its inherited state {} gives no position for it",
                            child.name.name,
                            new.name,
                            list.join(", ")
                        ),
                        new.span,
                        "added here",
                    )
                    .with_secondary(*span, format!("state `{state}` inherited from `{from}` here"))
                    .with_hint(format!(
                        "every rest state gives a position for every vertex, and an inherited state cannot be restated; declare `{}` in full instead of extending `{from}`, or add the vertex to `{from}` and its states",
                        child.name.name
                    )),
                );
                out.retain(|s| !matches!(s, PieceStmt::State(st) if lacking.iter().any(|(_, sp)| *sp == st.name.span)));
                failed = true;
            }
        }
        (out, failed)
    }

    /// Compiles one `piece` item. A child's diagnostics wait in `pending` for [`Self::settle_children`].
    pub(super) fn piece_item(&mut self, decl: &PieceDecl) {
        let child = self
            .inheritance
            .children
            .get(&decl.name.name)
            .is_some_and(|c| c.own == decl.span);
        if !child {
            self.piece_decl(decl);
            return;
        }
        let outer = std::mem::take(&mut self.diags);
        self.piece_decl(decl);
        let mine = std::mem::replace(&mut self.diags, outer);
        self.inheritance
            .pending
            .push((decl.name.name.clone(), mine));
    }

    /// After all pieces are compiled, bases before children: a child of a sound base reports
    /// the diagnostics about its own statements (the inherited ones were reported on the base);
    /// any other child is poisoned and silent.
    pub(super) fn settle_children(&mut self) {
        let mut pending = std::mem::take(&mut self.inheritance.pending);
        pending.sort_by_key(|(name, _)| self.inheritance.children.get(name).map_or(0, |c| c.depth));
        for (name, diags) in pending {
            let (Some(child), Some(&pi)) = (
                self.inheritance.children.get(&name),
                self.piece_index.get(&name),
            ) else {
                continue;
            };
            let own = child.own;
            let base_sound = self
                .piece_index
                .get(&child.base)
                .is_some_and(|&b| self.piece_spans[b].sound && !self.piece_spans[b].poisoned);
            let poisoned = child.poisoned
                || !base_sound
                || diags
                    .iter()
                    .any(|d| d.is_error() && !inside(own, d.primary.span));
            let failed = child.failed;
            if poisoned {
                self.piece_spans[pi].sound = false;
                self.piece_spans[pi].poisoned = true;
                if let Some(c) = self.inheritance.children.get_mut(&name) {
                    c.poisoned = true;
                }
                continue;
            }
            let kept: Vec<Diagnostic> = diags
                .items
                .into_iter()
                .filter(|d| inside(own, d.primary.span))
                .collect();
            if failed || kept.iter().any(Diagnostic::is_error) {
                self.piece_spans[pi].sound = false;
            }
            self.diags.items.extend(kept);
        }
    }

    /// Whether skinned geometry at `span` of piece `decl` (without an axis) goes unreported:
    /// it is inherited from a piece that has no axis either, which reported it (or whose failed
    /// stretch rule did).
    pub(super) fn inherited_skinned_is_quiet(&self, decl: &PieceDecl, span: Span) -> bool {
        let owner = self.inheritance.owner(&decl.name.name, span);
        owner != decl.name.name
            && self
                .piece_index
                .get(owner)
                .is_none_or(|&o| self.pieces[o].axis.is_none())
    }

    /// The extra hint for skinned geometry a piece inherited (None when it is its own).
    pub(super) fn inherited_skinned_hint(&self, decl: &PieceDecl, span: Span) -> Option<String> {
        let owner = self.inheritance.owner(&decl.name.name, span);
        (owner != decl.name.name).then(|| {
            format!(
                "`{}` inherits this geometry from `{owner}`, whose axis it does not inherit (a stretch rule's axis belongs to the rule's pieces); declare an `axis` in `{0}`, or give it its own geometry, which replaces the inherited one",
                decl.name.name
            )
        })
    }

    /// Whether a rule names a poisoned piece: it is then not compiled and nothing is said about
    /// it (a stretch rule still counts as naming its pieces, so their chains stay quiet too).
    pub(super) fn quiet_rule(&mut self, item: &Item) -> bool {
        let names: Vec<&str> = match item {
            Item::Stretch(s) => std::iter::once(&s.piece)
                .chain(
                    s.variants
                        .iter()
                        .flat_map(|v| v.entries.iter().map(|e| &e.piece)),
                )
                .map(|i| i.name.as_str())
                .collect(),
            Item::Merge(m) => std::iter::once(&m.mover)
                .chain(std::iter::once(&m.target))
                .chain(m.junction.as_ref())
                .map(|p| p.piece.name.as_str())
                .collect(),
            Item::Cut(c) => vec![c.junction.piece.name.as_str(), c.into.name.as_str()],
            _ => return false,
        };
        let poisoned = |n: &str| {
            self.piece_index
                .get(n)
                .is_some_and(|&i| self.piece_spans[i].poisoned)
        };
        if !names.iter().any(|n| poisoned(n)) {
            return false;
        }
        if matches!(item, Item::Stretch(_)) {
            for n in &names {
                if let Some(&i) = self.piece_index.get(*n)
                    && let Some(named) = self.stretch_named.get_mut(i)
                {
                    *named = true;
                }
            }
        }
        true
    }

    /// Drops the diagnostics that speak about a poisoned piece (a rule naming it, its unused
    /// warning): its base's error already explains it.
    pub(super) fn drop_poisoned(&mut self) {
        let names: Vec<Span> = self
            .piece_spans
            .iter()
            .filter(|s| s.poisoned)
            .map(|s| s.name)
            .collect();
        if names.is_empty() {
            return;
        }
        self.diags.items.retain(|d| {
            d.code == codes::DUPLICATE
                || !std::iter::once(&d.primary)
                    .chain(&d.secondary)
                    .any(|l| names.contains(&l.span))
        });
    }
}
