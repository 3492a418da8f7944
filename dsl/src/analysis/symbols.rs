//! The symbol table of one syntax tree: every declaration with its span, and every use resolved
//! to its declaration. Built from the tree alone, so it exists for any text that parses (or a
//! parsed prefix of one), whatever the compiler thinks of it.

use std::collections::HashMap;

use crate::syntax::*;

/// What a declaration declares.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SymbolKind {
    Constant,
    SiteType,
    Piece,
    Vertex,
    Site,
    State,
    Rule,
    Instance,
    Chain,
}

impl SymbolKind {
    /// The word used in hovers and messages.
    pub fn word(self) -> &'static str {
        match self {
            SymbolKind::Constant => "constant",
            SymbolKind::SiteType => "site type",
            SymbolKind::Piece => "piece",
            SymbolKind::Vertex => "vertex",
            SymbolKind::Site => "site",
            SymbolKind::State => "rest state",
            SymbolKind::Rule => "rule",
            SymbolKind::Instance => "instance",
            SymbolKind::Chain => "chain",
        }
    }
}

/// One declaration.
#[derive(Clone, Debug, PartialEq)]
pub struct Symbol {
    pub kind: SymbolKind,
    pub name: String,
    /// The name as written in the declaration.
    pub span: Span,
    /// The whole declaration.
    pub full: Span,
    /// The piece a vertex, site or state belongs to (an index into the symbols).
    pub container: Option<usize>,
    /// For an instance or chain, the piece it is made of (by name).
    pub piece: Option<String>,
}

/// One use of a declared name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Reference {
    pub span: Span,
    pub symbol: usize,
}

/// Declarations and resolved uses of one tree, in source order.
#[derive(Clone, Debug, Default)]
pub struct Symbols {
    pub symbols: Vec<Symbol>,
    pub references: Vec<Reference>,
    /// Spans of solver parameter names (no declaration; coloured as properties).
    pub parameters: Vec<Span>,
    /// Spans of calls' function names and of built-in constants.
    pub builtins: Vec<Span>,
}

/// Name tables used while resolving.
#[derive(Default)]
struct Scope {
    site_types: HashMap<String, usize>,
    pieces: HashMap<String, usize>,
    constants: HashMap<String, usize>,
    instances: HashMap<String, usize>,
    /// (piece symbol, member name, kind) -> member symbol.
    members: HashMap<(usize, String, SymbolKind), usize>,
    /// The piece each `extends` piece extends (by symbol), for inherited members.
    bases: HashMap<usize, usize>,
}

impl Symbols {
    /// Builds the table: declarations first (so a use may come before its declaration, as
    /// pieces and site types may), then every use.
    pub fn of(file: &File) -> Self {
        let mut s = Symbols::default();
        let mut scope = Scope::default();
        for item in &file.items {
            s.declare_item(item, &mut scope);
        }
        for item in &file.items {
            if let Item::Piece(p) = item
                && let (Some(&child), Some(base)) = (scope.pieces.get(&p.name.name), &p.extends)
                && let Some(&parent) = scope.pieces.get(&base.name)
            {
                scope.bases.insert(child, parent);
            }
        }
        for item in &file.items {
            s.resolve_item(item, &scope);
        }
        s.references.sort_by_key(|r| r.span.start);
        s
    }

    fn push(
        &mut self,
        kind: SymbolKind,
        id: &Ident,
        full: Span,
        container: Option<usize>,
    ) -> usize {
        self.symbols.push(Symbol {
            kind,
            name: id.name.clone(),
            span: id.span,
            full,
            container,
            piece: None,
        });
        self.symbols.len() - 1
    }

    fn declare_item(&mut self, item: &Item, scope: &mut Scope) {
        match item {
            Item::Let(l) => {
                let i = self.push(SymbolKind::Constant, &l.name, l.span, None);
                scope.constants.entry(l.name.name.clone()).or_insert(i);
            }
            // A parameter is a constant a user may set: the same namespace and uses.
            Item::Param(p) => {
                let i = self.push(SymbolKind::Constant, &p.name, p.span, None);
                scope.constants.entry(p.name.name.clone()).or_insert(i);
                // A choice stands for its default piece where a piece's name goes.
                if let (Some(ParamTypeKind::Choice(_)), ParamDefault::Text(t)) =
                    (p.ty.as_ref().map(|t| &t.kind), &p.value)
                {
                    self.symbols[i].piece = Some(t.value.clone());
                }
            }
            Item::SiteType(t) => {
                let i = self.push(SymbolKind::SiteType, &t.name, t.span, None);
                scope.site_types.entry(t.name.name.clone()).or_insert(i);
            }
            Item::Piece(p) => {
                let pi = self.push(SymbolKind::Piece, &p.name, p.span, None);
                scope.pieces.entry(p.name.name.clone()).or_insert(pi);
                for stmt in &p.stmts {
                    let (kind, id, full) = match stmt {
                        PieceStmt::Vertex(v) => (SymbolKind::Vertex, &v.name, v.span),
                        PieceStmt::Site(x) => (SymbolKind::Site, &x.name, x.span),
                        PieceStmt::State(x) => (SymbolKind::State, &x.name, x.span),
                        _ => continue,
                    };
                    let i = self.push(kind, id, full, Some(pi));
                    scope
                        .members
                        .entry((pi, id.name.clone(), kind))
                        .or_insert(i);
                }
            }
            Item::Stretch(r) => {
                let id = Ident {
                    name: format!("stretch {}", r.piece.name),
                    span: r.piece.span,
                };
                self.push(SymbolKind::Rule, &id, r.span, None);
            }
            Item::Merge(r) => {
                let id = Ident {
                    name: format!(
                        "merge {}.{} onto {}.{}",
                        r.mover.piece.name,
                        r.mover.site.name,
                        r.target.piece.name,
                        r.target.site.name
                    ),
                    span: r.mover.span,
                };
                self.push(SymbolKind::Rule, &id, r.span, None);
            }
            Item::Cut(r) => {
                let id = Ident {
                    name: format!("cut {}.{}", r.junction.piece.name, r.junction.site.name),
                    span: r.junction.span,
                };
                self.push(SymbolKind::Rule, &id, r.span, None);
            }
            Item::Model(m) => {
                let mut all = Vec::new();
                ModelStmt::walk(&m.stmts, &mut all);
                for stmt in all {
                    let (kind, id, piece, full) = match stmt {
                        ModelStmt::Instance(d) => (SymbolKind::Instance, &d.name, &d.piece, d.span),
                        ModelStmt::Chain(d) => (SymbolKind::Chain, &d.name, &d.piece, d.span),
                        ModelStmt::Dock(_) | ModelStmt::If(_) => continue,
                    };
                    let chosen = (scope.constants.get(&piece.name))
                        .and_then(|&c| self.symbols[c].piece.clone());
                    let i = self.push(kind, id, full, None);
                    self.symbols[i].piece = Some(chosen.unwrap_or_else(|| piece.name.clone()));
                    scope.instances.entry(id.name.clone()).or_insert(i);
                }
            }
            Item::Solver(_) | Item::Import(_) => {}
        }
    }

    fn use_of(&mut self, id: &Ident, found: Option<&usize>) {
        if let Some(&symbol) = found
            && self.symbols[symbol].span != id.span
        {
            self.references.push(Reference {
                span: id.span,
                symbol,
            });
        }
    }

    fn member(&mut self, scope: &Scope, piece: Option<usize>, id: &Ident, kind: SymbolKind) {
        // Own members first, then inherited ones up the `extends` chain (bounded: the compiler
        // rejects deeper chains and cycles).
        let mut at = piece;
        for _ in 0..64 {
            let Some(p) = at else { return };
            if let Some(found) = scope.members.get(&(p, id.name.clone(), kind)).copied() {
                self.use_of(id, Some(&found));
                return;
            }
            at = scope.bases.get(&p).copied();
        }
    }

    fn expr(&mut self, e: &Expr, scope: &Scope) {
        match &e.kind {
            ExprKind::Number(_) => {}
            ExprKind::Name(id) => match scope.constants.get(&id.name) {
                Some(i) => self.use_of(id, Some(i)),
                None if id.name == "pi" => self.builtins.push(id.span),
                None => {}
            },
            ExprKind::Unary(_, x) | ExprKind::Paren(x) => self.expr(x, scope),
            ExprKind::Binary(_, a, b) => {
                self.expr(a, scope);
                self.expr(b, scope);
            }
            ExprKind::Call(call) => {
                let (f, args) = (&call.func, &call.args);
                self.builtins.push(f.span);
                for a in args {
                    self.expr(a, scope);
                }
            }
        }
    }

    fn point(&mut self, p: &Point, scope: &Scope) {
        self.expr(&p.x, scope);
        self.expr(&p.y, scope);
    }

    fn geometry(&mut self, g: &GeometryDecl, scope: &Scope) {
        match &g.shape {
            ShapeDecl::Polygon { outer, holes } => {
                for p in outer.iter().chain(holes.iter().flat_map(|h| &h.points)) {
                    self.point(p, scope);
                }
            }
            ShapeDecl::Polyline { width, points } => {
                self.expr(width, scope);
                for p in points {
                    self.point(p, scope);
                }
            }
            ShapeDecl::Mesh { .. } => {}
        }
    }

    fn site_path(&mut self, p: &SitePath, scope: &Scope) {
        let piece = scope.pieces.get(&p.piece.name).copied();
        self.use_of(&p.piece, piece.as_ref());
        self.member(scope, piece, &p.site, SymbolKind::Site);
    }

    // Long because: one arm per item kind, each walking its own names.
    fn resolve_item(&mut self, item: &Item, scope: &Scope) {
        match item {
            Item::Let(l) => self.expr(&l.value, scope),
            Item::Param(p) => {
                if let ParamDefault::Expr(e) = &p.value {
                    self.expr(e, scope);
                }
                if let Some(ParamTypeKind::Choice(strings)) = p.ty.as_ref().map(|t| &t.kind) {
                    for s in strings {
                        // The name inside the quotes is a use of the piece.
                        let id = Ident {
                            name: s.value.clone(),
                            span: Span::new(s.span.start + 1, s.span.end.saturating_sub(1)),
                        };
                        let found = scope.pieces.get(&s.value).copied();
                        self.use_of(&id, found.as_ref());
                    }
                }
                if let Some(r) = &p.range {
                    self.expr(&r.low, scope);
                    self.expr(&r.high, scope);
                }
            }
            Item::Import(_) => {}
            Item::Solver(s) => {
                for e in &s.entries {
                    self.parameters.push(e.name.span);
                    self.expr(&e.value, scope);
                }
            }
            Item::SiteType(t) => {
                for d in &t.docks {
                    let found = scope.site_types.get(&d.name).copied();
                    self.use_of(d, found.as_ref());
                }
            }
            Item::Piece(p) => {
                let pi = scope.pieces.get(&p.name.name).copied();
                if let Some(base) = &p.extends {
                    let found = scope.pieces.get(&base.name).copied();
                    self.use_of(base, found.as_ref());
                }
                for stmt in &p.stmts {
                    self.piece_stmt(stmt, pi, scope);
                }
            }
            Item::Stretch(r) => {
                let pi = scope.pieces.get(&r.piece.name).copied();
                self.use_of(&r.piece, pi.as_ref());
                self.member(scope, pi, &r.from, SymbolKind::Site);
                self.member(scope, pi, &r.to, SymbolKind::Site);
                for m in r.min.iter().chain(&r.max) {
                    self.expr(m, scope);
                }
                for v in r.variants.iter().flat_map(|v| &v.entries) {
                    let found = scope.pieces.get(&v.piece.name).copied();
                    self.use_of(&v.piece, found.as_ref());
                    self.expr(&v.frequency, scope);
                }
            }
            Item::Merge(r) => {
                self.site_path(&r.mover, scope);
                self.site_path(&r.target, scope);
                if let Some(j) = &r.junction {
                    self.site_path(j, scope);
                }
                if let Some(w) = &r.within {
                    self.expr(w, scope);
                }
            }
            Item::Cut(r) => {
                self.site_path(&r.junction, scope);
                let found = scope.pieces.get(&r.into.name).copied();
                self.use_of(&r.into, found.as_ref());
            }
            Item::Model(m) => {
                for stmt in &m.stmts {
                    self.model_stmt(stmt, scope);
                }
            }
        }
    }

    fn piece_stmt(&mut self, stmt: &PieceStmt, pi: Option<usize>, scope: &Scope) {
        match stmt {
            PieceStmt::Vertex(v) => self.point(&v.pos, scope),
            PieceStmt::Edges(e) => self.edges(e, pi, scope),
            PieceStmt::Site(s) => {
                let found = scope.site_types.get(&s.site_type.name).copied();
                self.use_of(&s.site_type, found.as_ref());
                for v in &s.vertices {
                    self.member(scope, pi, v, SymbolKind::Vertex);
                }
                self.point(&s.out, scope);
            }
            PieceStmt::Axis(a) => {
                self.member(scope, pi, &a.from, SymbolKind::Site);
                self.member(scope, pi, &a.to, SymbolKind::Site);
            }
            PieceStmt::Geometry(g) => self.geometry(g, scope),
            PieceStmt::State(st) => {
                for p in &st.positions {
                    self.member(scope, pi, &p.name, SymbolKind::Vertex);
                    self.point(&p.pos, scope);
                }
                for e in &st.edges {
                    self.edges(e, pi, scope);
                }
                for g in &st.geometry {
                    self.geometry(g, scope);
                }
            }
        }
    }

    fn edges(&mut self, e: &EdgesDecl, pi: Option<usize>, scope: &Scope) {
        for v in e.paths.iter().flatten() {
            self.member(scope, pi, v, SymbolKind::Vertex);
        }
    }

    fn model_stmt(&mut self, stmt: &ModelStmt, scope: &Scope) {
        let placement = |s: &mut Self, at: &Option<Point>, rotate: &Option<Expr>| {
            if let Some(p) = at {
                s.point(p, scope);
            }
            if let Some(r) = rotate {
                s.expr(r, scope);
            }
        };
        // A piece's name, or a choice parameter's (then its default piece has the sites).
        let piece = |s: &mut Self, id: &Ident| match scope.constants.get(&id.name) {
            Some(&c) if s.symbols[c].piece.is_some() => {
                s.use_of(id, Some(&c));
                let chosen = s.symbols[c].piece.clone().unwrap_or_default();
                scope.pieces.get(&chosen).copied()
            }
            _ => {
                let found = scope.pieces.get(&id.name).copied();
                s.use_of(id, found.as_ref());
                found
            }
        };
        match stmt {
            ModelStmt::If(b) => {
                let found = scope.constants.get(&b.cond.name).copied();
                self.use_of(&b.cond, found.as_ref());
                for s in b.then.iter().chain(b.otherwise.iter().flatten()) {
                    self.model_stmt(s, scope);
                }
            }
            ModelStmt::Instance(d) => {
                piece(self, &d.piece);
                placement(self, &d.at, &d.rotate);
            }
            ModelStmt::Chain(d) => {
                let pi = piece(self, &d.piece);
                self.expr(&d.count, scope);
                if let Some((f, t)) = &d.along {
                    self.member(scope, pi, f, SymbolKind::Site);
                    self.member(scope, pi, t, SymbolKind::Site);
                }
                placement(self, &d.at, &d.rotate);
            }
            ModelStmt::Dock(d) => {
                for side in [&d.a, &d.b] {
                    let inst = scope.instances.get(&side.instance.name).copied();
                    self.use_of(&side.instance, inst.as_ref());
                    let piece = inst
                        .and_then(|i| self.symbols[i].piece.clone())
                        .and_then(|p| scope.pieces.get(&p).copied());
                    self.member(scope, piece, &side.site, SymbolKind::Site);
                }
            }
        }
    }
}
