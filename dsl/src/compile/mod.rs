//! The compiler: syntax tree -> [`CompiledGrammar`]. This file drives the passes and compiles
//! the declarations (solver, site types, pieces); `rules.rs` compiles stretch, merge and cut
//! rules, `assembly.rs` places the model, and `usage.rs` finds unused pieces and dead rules.

pub mod codes;

mod assembly;
mod rules;
mod usage;

use std::collections::HashMap;

use glam::DVec2;

use crate::compiled::*;
use crate::diagnostic::{Diagnostic, Diagnostics};
use crate::suggest::closest;
use crate::syntax::{self, Ident, Item, Number, PieceStmt, Point, Span};

/// The result of a successful compilation: the grammar, and the warnings found on the way.
#[derive(Clone, Debug, PartialEq)]
pub struct Compiled {
    pub grammar: CompiledGrammar,
    pub warnings: Diagnostics,
}

/// Largest absolute coordinate accepted, in metres; keeps every later computation finite.
pub const MAX_COORDINATE: f64 = 1e9;
/// Most instances a model may have (chains included).
pub const MAX_INSTANCES: usize = 1_000_000;
/// Distance below which two positions count as the same place.
pub const COINCIDENT_EPS: f64 = 1e-9;
/// Tolerance for docked vertices meeting after placement, in metres.
pub const DOCK_TOLERANCE: f64 = 1e-4;

/// Compiles the text of a `.clay` file. `path` is only recorded in the result.
pub fn compile(source: &str, path: &str) -> Result<Compiled, Diagnostics> {
    let file = crate::parse::parse(source)?;
    let mut c = Compiler::new(path);
    c.run(&file);
    let mut diags = c.diags;
    diags.sort();
    match c.grammar {
        Some(grammar) if !diags.has_errors() => Ok(Compiled {
            grammar,
            warnings: diags,
        }),
        _ => Err(diags),
    }
}

/// Compiles raw bytes; text that is not UTF-8 is reported (E003) at the first bad byte. Render
/// the diagnostics against `String::from_utf8_lossy(bytes)`: offsets before that byte agree.
pub fn compile_bytes(bytes: &[u8], path: &str) -> Result<Compiled, Diagnostics> {
    match std::str::from_utf8(bytes) {
        Ok(source) => compile(source, path),
        Err(e) => {
            let at = e.valid_up_to();
            Err(Diagnostic::error(
                codes::NOT_UTF8,
                "file is not valid UTF-8 text",
                Span::new(at, at + 1),
                "invalid byte here",
            )
            .with_hint("save the file as UTF-8")
            .into())
        }
    }
}

/// Where things were declared, for secondary labels.
#[derive(Clone, Debug, Default)]
pub(crate) struct PieceSpans {
    pub name: Span,
    pub vertices: Vec<Span>,
    pub sites: Vec<Span>,
    /// Where each of the piece's edges was written.
    pub edges: Vec<Span>,
    /// `state NAME` of each alternative rest state that was compiled, in order.
    pub states: Vec<Span>,
    /// False when the piece had errors: later passes skip geometric checks on it.
    pub sound: bool,
}

pub(crate) struct Compiler {
    pub path: String,
    pub diags: Diagnostics,
    pub solver: SolverParams,
    pub site_types: Vec<SiteType>,
    pub site_type_spans: Vec<Span>,
    pub pieces: Vec<Piece>,
    pub piece_spans: Vec<PieceSpans>,
    pub piece_index: HashMap<String, usize>,
    pub stretch_rules: Vec<StretchRule>,
    pub stretch_spans: Vec<Span>,
    pub merge_rules: Vec<MergeRule>,
    pub merge_spans: Vec<Span>,
    pub cut_rules: Vec<CutRule>,
    pub cut_spans: Vec<Span>,
    /// Pieces named by a stretch rule (written, even if the rule had errors).
    pub stretch_named: Vec<bool>,
    /// Set when a `dock` statement had errors: unplaced instances are then not reported.
    pub dock_failed: bool,
    pub grammar: Option<CompiledGrammar>,
}

impl Compiler {
    fn new(path: &str) -> Self {
        Self {
            path: path.to_string(),
            diags: Diagnostics::new(),
            solver: SolverParams::default(),
            site_types: Vec::new(),
            site_type_spans: Vec::new(),
            pieces: Vec::new(),
            piece_spans: Vec::new(),
            piece_index: HashMap::new(),
            stretch_rules: Vec::new(),
            stretch_spans: Vec::new(),
            merge_rules: Vec::new(),
            merge_spans: Vec::new(),
            cut_rules: Vec::new(),
            cut_spans: Vec::new(),
            stretch_named: Vec::new(),
            dock_failed: false,
            grammar: None,
        }
    }

    pub fn error(&mut self, d: Diagnostic) {
        self.diags.push(d);
    }

    pub fn duplicate(&mut self, what: &str, ident: &Ident, first: Span) {
        self.diags.push(
            Diagnostic::error(
                codes::DUPLICATE,
                format!("{what} `{}` is defined twice", ident.name),
                ident.span,
                "defined again here",
            )
            .with_secondary(first, "first defined here")
            .with_hint(format!("rename one of them or remove the second {what}")),
        );
    }

    /// Reports an unknown name, suggesting the closest known one.
    pub fn unknown<'a>(
        &mut self,
        what: &str,
        ident: &Ident,
        known: impl IntoIterator<Item = &'a str>,
        context: Option<String>,
    ) {
        let known: Vec<&str> = known.into_iter().collect();
        let mut d = Diagnostic::error(
            codes::UNKNOWN,
            match &context {
                Some(ctx) => format!("unknown {what} `{}` {ctx}", ident.name),
                None => format!("unknown {what} `{}`", ident.name),
            },
            ident.span,
            format!("no {what} of this name"),
        );
        if let Some(c) = closest(&ident.name, known.iter().copied()) {
            d = d.with_hint(format!("did you mean `{c}`?"));
        } else if known.is_empty() {
            d = d.with_hint(format!("no {what} is declared here"));
        } else if known.len() <= 8 {
            let list: Vec<String> = known.iter().map(|k| format!("`{k}`")).collect();
            d = d.with_hint(format!("known: {}", list.join(", ")));
        }
        self.diags.push(d);
    }

    /// A number that must lie in a range; reports and returns `None` otherwise.
    pub fn in_range(
        &mut self,
        n: &Number,
        what: &str,
        ok: impl Fn(f64) -> bool,
        allowed: &str,
    ) -> Option<f64> {
        if ok(n.value) {
            Some(n.value)
        } else {
            self.diags.push(
                Diagnostic::error(
                    codes::OUT_OF_RANGE,
                    format!("{what} is out of range"),
                    n.span,
                    format!("must be {allowed}"),
                )
                .with_hint(format!(
                    "{what} must be {allowed}; see the table in docs/language.md"
                )),
            );
            None
        }
    }

    /// A whole number at least `min`.
    pub fn whole(&mut self, n: &Number, what: &str, min: u64) -> Option<u64> {
        let v = n.value;
        if v.fract() == 0.0 && v >= min as f64 && v <= u64::MAX as f64 / 2.0 {
            Some(v as u64)
        } else {
            self.diags.push(
                Diagnostic::error(
                    codes::OUT_OF_RANGE,
                    format!("{what} must be a whole number of at least {min}"),
                    n.span,
                    format!("expected a whole number >= {min}"),
                )
                .with_hint(format!(
                    "write {what} as a whole number, like `{}`",
                    min.max(2)
                )),
            );
            None
        }
    }

    /// A point whose coordinates are within [`MAX_COORDINATE`].
    pub fn point(&mut self, p: &Point) -> DVec2 {
        for n in [&p.x, &p.y] {
            if n.value.abs() > MAX_COORDINATE {
                self.diags.push(
                    Diagnostic::error(
                        codes::OUT_OF_RANGE,
                        "coordinate is out of range",
                        n.span,
                        "too far from the origin",
                    )
                    .with_hint(format!(
                        "coordinates are metres and must lie within +/-{MAX_COORDINATE:e}"
                    )),
                );
                return DVec2::ZERO;
            }
        }
        DVec2::new(p.x.value, p.y.value)
    }

    pub fn site_type_index(&self, name: &str) -> Option<usize> {
        self.site_types.iter().position(|t| t.name == name)
    }

    /// Resolves a piece name, reporting it when unknown.
    pub fn resolve_piece(&mut self, ident: &Ident) -> Option<usize> {
        match self.piece_index.get(&ident.name) {
            Some(&i) => Some(i),
            None => {
                let names: Vec<String> = self.pieces.iter().map(|p| p.name.clone()).collect();
                self.unknown("piece", ident, names.iter().map(String::as_str), None);
                None
            }
        }
    }

    /// Resolves a site of a piece, reporting it when unknown.
    pub fn resolve_site(&mut self, piece: usize, ident: &Ident) -> Option<usize> {
        let p = &self.pieces[piece];
        match p.sites.iter().position(|s| s.name == ident.name) {
            Some(i) => Some(i),
            None => {
                let names: Vec<String> = p.sites.iter().map(|s| s.name.clone()).collect();
                let ctx = Some(format!("on piece `{}`", p.name));
                self.unknown("site", ident, names.iter().map(String::as_str), ctx);
                None
            }
        }
    }

    fn run(&mut self, file: &syntax::File) {
        let mut solver_seen: Option<Span> = None;
        let mut model: Option<&syntax::ModelBlock> = None;
        for item in &file.items {
            match item {
                Item::Solver(s) => {
                    if let Some(first) = solver_seen {
                        let id = Ident {
                            name: "solver".into(),
                            span: s.keyword,
                        };
                        self.duplicate("block", &id, first);
                    } else {
                        solver_seen = Some(s.keyword);
                        self.solver_block(s);
                    }
                }
                Item::Model(m) => {
                    if let Some(first) = model {
                        let id = Ident {
                            name: "model".into(),
                            span: m.keyword,
                        };
                        self.duplicate("block", &id, first.keyword);
                    } else {
                        model = Some(m);
                    }
                }
                _ => {}
            }
        }
        let decls: Vec<&syntax::SiteTypeDecl> = file
            .items
            .iter()
            .filter_map(|i| {
                if let Item::SiteType(s) = i {
                    Some(s)
                } else {
                    None
                }
            })
            .collect();
        self.site_type_decls(&decls);
        for item in &file.items {
            if let Item::Piece(p) = item {
                self.piece_decl(p);
            }
        }
        self.rules(file);
        self.check_skinned(file);
        let usage = usage::Usage::find(self, file, model);
        let assembly = assembly::build(self, model);
        usage.report(self, file);
        let grammar = CompiledGrammar {
            format_version: FORMAT_VERSION,
            source: self.path.clone(),
            solver: self.solver,
            site_types: std::mem::take(&mut self.site_types),
            pieces: std::mem::take(&mut self.pieces),
            stretch_rules: std::mem::take(&mut self.stretch_rules),
            merge_rules: std::mem::take(&mut self.merge_rules),
            cut_rules: std::mem::take(&mut self.cut_rules),
            assembly: AssemblyData::default(),
        };
        if self.diags.has_errors() {
            return;
        }
        let mut grammar = grammar;
        grammar.assembly = assembly;
        grammar.assembly.parts = grammar.parts(&grammar.assembly);
        if !grammar.all_finite() {
            // Guarded by MAX_COORDINATE; kept so that no NaN or infinity can ever reach output.
            self.error(Diagnostic::error(
                codes::OUT_OF_RANGE,
                "the compiled grammar has coordinates that are not finite",
                file.span,
                "somewhere in this file",
            ));
            return;
        }
        self.grammar = Some(grammar);
    }

    fn solver_block(&mut self, s: &syntax::SolverBlock) {
        let mut seen: HashMap<&str, Span> = HashMap::new();
        for e in &s.entries {
            if let Some(&first) = seen.get(e.name.name.as_str()) {
                self.duplicate("solver parameter", &e.name, first);
                continue;
            }
            seen.insert(&e.name.name, e.name.span);
            let v = &e.value;
            match e.name.name.as_str() {
                "hysteresis" => {
                    if let Some(x) = self.in_range(
                        v,
                        "`hysteresis`",
                        |x| (0.0..1.0).contains(&x),
                        "at least 0 and below 1",
                    ) {
                        self.solver.hysteresis = x;
                    }
                }
                "norm" => {
                    if let Some(x) = self.in_range(
                        v,
                        "`norm`",
                        |x| x > 0.0 && x <= 2.0,
                        "above 0 and at most 2",
                    ) {
                        self.solver.norm = x;
                    }
                }
                "irls_epsilon" => {
                    if let Some(x) = self.in_range(v, "`irls_epsilon`", |x| x > 0.0, "above 0") {
                        self.solver.irls_epsilon = x;
                    }
                }
                "merge_distance" => {
                    if let Some(x) = self.in_range(v, "`merge_distance`", |x| x > 0.0, "above 0") {
                        self.solver.merge_distance = x;
                    }
                }
                _ => self.unknown(
                    "solver parameter",
                    &e.name,
                    ["hysteresis", "norm", "irls_epsilon", "merge_distance"],
                    None,
                ),
            }
        }
    }

    fn site_type_decls(&mut self, decls: &[&syntax::SiteTypeDecl]) {
        for d in decls {
            if let Some(i) = self.site_type_index(&d.name.name) {
                self.duplicate("site type", &d.name, self.site_type_spans[i]);
                continue;
            }
            self.site_types.push(SiteType {
                name: d.name.name.clone(),
                docks_with: Vec::new(),
            });
            self.site_type_spans.push(d.name.span);
        }
        let n = self.site_types.len();
        let mut dock = vec![vec![false; n]; n];
        for d in decls {
            let Some(me) = self.site_type_index(&d.name.name) else {
                continue;
            };
            if self.site_type_spans[me] != d.name.span {
                continue; // a duplicate, already reported
            }
            if d.docks.is_empty() {
                dock[me][me] = true;
            }
            for other in &d.docks {
                match self.site_type_index(&other.name) {
                    Some(o) => {
                        dock[me][o] = true;
                        dock[o][me] = true;
                    }
                    None => {
                        let names: Vec<String> =
                            self.site_types.iter().map(|t| t.name.clone()).collect();
                        self.unknown("site type", other, names.iter().map(String::as_str), None);
                    }
                }
            }
        }
        for (i, row) in dock.iter().enumerate() {
            self.site_types[i].docks_with = (0..n).filter(|&j| row[j]).collect();
        }
    }

    fn piece_decl(&mut self, decl: &syntax::PieceDecl) {
        if let Some(&first) = self.piece_index.get(&decl.name.name) {
            let span = self.piece_spans[first].name;
            self.duplicate("piece", &decl.name, span);
            return;
        }
        let errors_before = self.diags.error_count();
        let mut piece = Piece {
            name: decl.name.name.clone(),
            vertices: Vec::new(),
            edges: Vec::new(),
            sites: Vec::new(),
            states: Vec::new(),
            axis: None,
        };
        let mut spans = PieceSpans {
            name: decl.name.span,
            ..Default::default()
        };
        let mut base = Vec::new();
        // Vertices first: statements may come in any order and refer to later vertices.
        for s in &decl.stmts {
            if let PieceStmt::Vertex(v) = s {
                if let Some(i) = piece.vertices.iter().position(|n| *n == v.name.name) {
                    self.duplicate("vertex", &v.name, spans.vertices[i]);
                    continue;
                }
                piece.vertices.push(v.name.name.clone());
                spans.vertices.push(v.name.span);
                base.push(self.point(&v.pos));
            }
        }
        if piece.vertices.is_empty() {
            self.error(
                Diagnostic::error(
                    codes::DEGENERATE,
                    format!("piece `{}` has no vertices", decl.name.name),
                    decl.name.span,
                    "declared here",
                )
                .with_hint("add vertices with `vertex NAME (x, y)`"),
            );
        }
        let mut edge_spans: Vec<Span> = Vec::new();
        let mut axis: Option<&syntax::AxisDecl> = None;
        let mut geometry = Vec::new();
        for s in &decl.stmts {
            match s {
                PieceStmt::Edges(e) => {
                    let mut edges = std::mem::take(&mut piece.edges);
                    self.edges(&piece, e, &mut edges, &mut edge_spans);
                    piece.edges = edges;
                }
                PieceStmt::Site(site) => {
                    if let Some(i) = piece.sites.iter().position(|x| x.name == site.name.name) {
                        self.duplicate("site", &site.name, spans.sites[i]);
                        continue;
                    }
                    if let Some(compiled) = self.site(&piece, site) {
                        piece.sites.push(compiled);
                        spans.sites.push(site.name.span);
                    }
                }
                PieceStmt::Axis(a) => {
                    if let Some(first) = axis {
                        let id = Ident {
                            name: "axis".into(),
                            span: a.span,
                        };
                        self.duplicate("declaration", &id, first.span);
                    } else {
                        axis = Some(a);
                    }
                }
                PieceStmt::Geometry(g) => geometry.extend(self.geometry(g)),
                PieceStmt::Vertex(_) | PieceStmt::State(_) => {}
            }
        }
        // Edges are stored as given (first-written orientation) and deduplicated.
        self.check_state_geometry(
            &piece,
            "base",
            &base,
            &spans.vertices,
            decl.name.span,
            &edge_spans,
        );
        piece.states.push(RestState {
            name: "base".into(),
            positions: base.clone(),
            geometry: geometry.clone(),
            geometry_frame: 0,
        });
        spans.edges = edge_spans;
        let mut state_spans: Vec<Span> = Vec::new();
        for s in &decl.stmts {
            if let PieceStmt::State(st) = s {
                if st.name.name == "base" {
                    self.error(
                        Diagnostic::error(
                            codes::DUPLICATE,
                            "state `base` is defined twice",
                            st.name.span,
                            "defined again here",
                        )
                        .with_secondary(
                            decl.name.span,
                            "`base` is the state given by the piece's `vertex` positions",
                        )
                        .with_hint("give the alternative state another name"),
                    );
                    continue;
                }
                if let Some(i) = piece
                    .states
                    .iter()
                    .skip(1)
                    .position(|x| x.name == st.name.name)
                {
                    self.duplicate("state", &st.name, state_spans[i]);
                    continue;
                }
                let index = piece.states.len();
                let state = self.state(&piece, &spans, st, index, &geometry);
                piece.states.push(state);
                state_spans.push(st.name.span);
                spans
                    .states
                    .push(Span::new(st.span.start, st.name.span.end));
            }
        }
        if let Some(a) = axis {
            let from = self.site_on(&piece, &a.from);
            let to = self.site_on(&piece, &a.to);
            if let (Some(f), Some(t)) = (from, to)
                && self.opposite(&piece, f, t, a.span, "axis")
            {
                piece.axis = Some([f, t]);
            }
        }
        spans.sound = self.diags.error_count() == errors_before;
        let index = self.pieces.len();
        self.piece_index.insert(piece.name.clone(), index);
        self.pieces.push(piece);
        self.piece_spans.push(spans);
    }

    /// Resolves a site name against a piece under construction.
    fn site_on(&mut self, piece: &Piece, ident: &Ident) -> Option<usize> {
        match piece.sites.iter().position(|s| s.name == ident.name) {
            Some(i) => Some(i),
            None => {
                let names: Vec<&str> = piece.sites.iter().map(|s| s.name.as_str()).collect();
                self.unknown(
                    "site",
                    ident,
                    names,
                    Some(format!("on piece `{}`", piece.name)),
                );
                None
            }
        }
    }

    /// Checks that sites `from` and `to` of a piece point roughly opposite ways.
    pub fn opposite(
        &mut self,
        piece: &Piece,
        from: usize,
        to: usize,
        span: Span,
        what: &str,
    ) -> bool {
        let (f, t) = (&piece.sites[from], &piece.sites[to]);
        let ok = from != to && f.out.dot(t.out) < -0.5;
        if !ok {
            let mut d = Diagnostic::error(
                codes::NOT_OPPOSITE,
                format!(
                    "the {what} of piece `{}` needs two opposite sites",
                    piece.name
                ),
                span,
                if from == to {
                    format!("`{}` is used at both ends", f.name)
                } else {
                    format!(
                        "`{}` points ({}, {}) and `{}` points ({}, {})",
                        f.name,
                        fmt(f.out.x),
                        fmt(f.out.y),
                        t.name,
                        fmt(t.out.x),
                        fmt(t.out.y)
                    )
                },
            );
            d = d.with_hint("the `out` directions of the two sites must point roughly opposite ways (their dot product below -0.5)");
            self.error(d);
        }
        ok
    }

    fn vertex_index(&mut self, piece: &Piece, ident: &Ident) -> Option<usize> {
        match piece.vertices.iter().position(|v| *v == ident.name) {
            Some(i) => Some(i),
            None => {
                let names: Vec<&str> = piece.vertices.iter().map(String::as_str).collect();
                self.unknown(
                    "vertex",
                    ident,
                    names,
                    Some(format!("in piece `{}`", piece.name)),
                );
                None
            }
        }
    }

    /// Adds the edges of one `edges` statement, reporting unknown vertices, loops and repeats.
    fn edges(
        &mut self,
        piece: &Piece,
        e: &syntax::EdgesDecl,
        edges: &mut Vec<[usize; 2]>,
        spans: &mut Vec<Span>,
    ) {
        for path in &e.paths {
            let ids: Vec<Option<usize>> =
                path.iter().map(|v| self.vertex_index(piece, v)).collect();
            for k in 0..path.len().saturating_sub(1) {
                let (Some(a), Some(b)) = (ids[k], ids[k + 1]) else {
                    continue;
                };
                let span = path[k].span.to(path[k + 1].span);
                if a == b {
                    self.error(
                        Diagnostic::error(
                            codes::ZERO_EDGE,
                            format!("edge `{0}-{0}` joins a vertex to itself", path[k].name),
                            span,
                            "zero-length edge",
                        )
                        .with_hint("remove the repeated vertex from the path"),
                    );
                    continue;
                }
                if let Some(i) = edges
                    .iter()
                    .position(|&[x, y]| (x, y) == (a, b) || (x, y) == (b, a))
                {
                    self.diags.push(
                        Diagnostic::warning(
                            codes::REPEATED_EDGE,
                            format!(
                                "edge `{}-{}` is listed twice",
                                path[k].name,
                                path[k + 1].name
                            ),
                            span,
                            "repeated here",
                        )
                        .with_secondary(spans[i], "first listed here")
                        .with_hint("edges are undirected: `a-b` and `b-a` are the same edge"),
                    );
                    continue;
                }
                edges.push([a, b]);
                spans.push(span);
            }
        }
    }

    fn site(&mut self, piece: &Piece, s: &syntax::SiteDecl) -> Option<Site> {
        let site_type = match self.site_type_index(&s.site_type.name) {
            Some(t) => Some(t),
            None => {
                let names: Vec<String> = self.site_types.iter().map(|t| t.name.clone()).collect();
                self.unknown(
                    "site type",
                    &s.site_type,
                    names.iter().map(String::as_str),
                    None,
                );
                None
            }
        };
        let mut vertices = Vec::new();
        let mut ok = true;
        for (k, v) in s.vertices.iter().enumerate() {
            match self.vertex_index(piece, v) {
                Some(i) => {
                    if let Some(j) = s.vertices[..k].iter().position(|w| w.name == v.name) {
                        self.duplicate("site vertex", v, s.vertices[j].span);
                        ok = false;
                    }
                    vertices.push(i);
                }
                None => ok = false,
            }
        }
        let out = self.point(&s.out);
        let len = out.length();
        if len < COINCIDENT_EPS {
            self.error(
                Diagnostic::error(codes::ZERO_OUT, format!("site `{}` has no outward direction", s.name.name), s.out.span, "zero vector")
                    .with_hint("`out` is the direction pointing away from the piece, like `(1, 0)` for a site on the east side"),
            );
            ok = false;
        }
        if !ok {
            return None;
        }
        Some(Site {
            name: s.name.name.clone(),
            site_type: site_type?,
            vertices,
            out: out / len,
        })
    }

    fn geometry(&mut self, g: &syntax::GeometryDecl) -> Option<Proxy> {
        let binding = match g.binding {
            Some((syntax::BindingKw::Skinned, _)) => Binding::Skinned,
            _ => Binding::Rigid,
        };
        let fill = Rgba(g.fill.rgba);
        let shape = match &g.shape {
            syntax::ShapeDecl::Polygon { outer, holes } => {
                let mut ok = self.enough_points(outer.len(), 3, "polygon", g.keyword);
                let outer: Vec<DVec2> = outer.iter().map(|p| self.point(p)).collect();
                let mut hs = Vec::new();
                for h in holes {
                    ok &= self.enough_points(h.points.len(), 3, "hole", h.span);
                    hs.push(h.points.iter().map(|p| self.point(p)).collect());
                }
                if !ok {
                    return None;
                }
                ProxyShape::Polygon { outer, holes: hs }
            }
            syntax::ShapeDecl::Polyline { width, points } => {
                let ok = self.enough_points(points.len(), 2, "polyline", g.keyword);
                let w = self.in_range(
                    width,
                    "polyline `width`",
                    |w| w > 0.0 && w <= MAX_COORDINATE,
                    "above 0",
                );
                let points = points.iter().map(|p| self.point(p)).collect();
                if !ok {
                    return None;
                }
                ProxyShape::Polyline { points, width: w? }
            }
        };
        Some(Proxy {
            shape,
            fill,
            binding,
        })
    }

    fn enough_points(&mut self, n: usize, min: usize, what: &str, span: Span) -> bool {
        if n >= min {
            return true;
        }
        self.error(
            Diagnostic::error(
                codes::DEGENERATE,
                format!(
                    "{what} has {n} point{}, needs at least {min}",
                    if n == 1 { "" } else { "s" }
                ),
                span,
                "too few points",
            )
            .with_hint(format!("a {what} needs at least {min} points `(x, y)`")),
        );
        false
    }

    /// Zero-length edges and coincident vertices of one rest state.
    fn check_state_geometry(
        &mut self,
        piece: &Piece,
        state: &str,
        pos: &[DVec2],
        vspans: &[Span],
        fallback: Span,
        edge_spans: &[Span],
    ) {
        if pos.len() != piece.vertices.len() {
            return;
        }
        let mut reported = vec![false; pos.len()];
        for (k, &[a, b]) in piece.edges.iter().enumerate() {
            if pos[a].distance(pos[b]) < COINCIDENT_EPS {
                reported[a] = true;
                reported[b] = true;
                let mut d = Diagnostic::error(
                    codes::ZERO_EDGE,
                    format!(
                        "edge `{}-{}` has zero length in state `{state}`",
                        piece.vertices[a], piece.vertices[b]
                    ),
                    vspans.get(b).copied().unwrap_or(fallback),
                    format!(
                        "`{}` is at the same place as `{}`: ({}, {})",
                        piece.vertices[b],
                        piece.vertices[a],
                        fmt(pos[b].x),
                        fmt(pos[b].y)
                    ),
                );
                if let Some(&e) = edge_spans.get(k) {
                    d = d.with_secondary(e, "the edge is declared here");
                }
                self.error(d.with_hint("move one of the vertices, or merge them into one vertex"));
            }
        }
        // Sorting by x keeps this near-linear for big pieces.
        let mut order: Vec<usize> = (0..pos.len()).collect();
        order.sort_by(|&i, &j| pos[i].x.total_cmp(&pos[j].x));
        for (k, &i) in order.iter().enumerate() {
            for &j in &order[k + 1..] {
                if pos[j].x - pos[i].x >= COINCIDENT_EPS {
                    break;
                }
                if pos[i].distance(pos[j]) < COINCIDENT_EPS && !(reported[i] && reported[j]) {
                    let (a, b) = (i.min(j), i.max(j));
                    reported[a] = true;
                    reported[b] = true;
                    self.error(
                        Diagnostic::error(
                            codes::COINCIDENT,
                            format!(
                                "vertices `{}` and `{}` are at the same place in state `{state}`",
                                piece.vertices[a], piece.vertices[b]
                            ),
                            vspans.get(b).copied().unwrap_or(fallback),
                            format!(
                                "`{}` is at ({}, {})",
                                piece.vertices[b],
                                fmt(pos[b].x),
                                fmt(pos[b].y)
                            ),
                        )
                        .with_secondary(
                            vspans.get(a).copied().unwrap_or(fallback),
                            format!("`{}` is here too", piece.vertices[a]),
                        )
                        .with_hint("every vertex of a rest state needs its own position"),
                    );
                }
            }
        }
    }

    fn state(
        &mut self,
        piece: &Piece,
        spans: &PieceSpans,
        st: &syntax::StateDecl,
        index: usize,
        base_geometry: &[Proxy],
    ) -> RestState {
        let n = piece.vertices.len();
        let mut pos: Vec<Option<DVec2>> = vec![None; n];
        let mut vspans: Vec<Span> = vec![st.name.span; n];
        for p in &st.positions {
            match piece.vertices.iter().position(|v| *v == p.name.name) {
                Some(i) => {
                    if pos[i].is_some() {
                        self.duplicate("vertex position", &p.name, vspans[i]);
                        continue;
                    }
                    pos[i] = Some(self.point(&p.pos));
                    vspans[i] = p.name.span;
                }
                None => {
                    let mut d = Diagnostic::error(
                        codes::STATE_VERTICES,
                        format!(
                            "state `{}` adds vertex `{}`, which piece `{}` does not have",
                            st.name.name, p.name.name, piece.name
                        ),
                        p.name.span,
                        "not a vertex of the piece",
                    )
                    .with_secondary(spans.name, "piece declared here");
                    if let Some(c) =
                        closest(&p.name.name, piece.vertices.iter().map(String::as_str))
                    {
                        d = d.with_hint(format!("did you mean `{c}`?"));
                    } else {
                        d = d.with_hint("an alternative state may not add vertices: it gives new positions to the piece's own vertices");
                    }
                    self.error(d);
                }
            }
        }
        let missing: Vec<usize> = (0..n).filter(|&i| pos[i].is_none()).collect();
        if !missing.is_empty() {
            let names: Vec<String> = missing
                .iter()
                .map(|&i| format!("`{}`", piece.vertices[i]))
                .collect();
            let mut d = Diagnostic::error(
                codes::STATE_VERTICES,
                format!(
                    "state `{}` gives no position for vertex {}",
                    st.name.name,
                    names.join(", ")
                ),
                st.name.span,
                format!("missing {}", names.join(", ")),
            );
            if let Some(&i) = missing.first() {
                d = d.with_secondary(
                    spans.vertices.get(i).copied().unwrap_or(spans.name),
                    format!("`{}` is declared here", piece.vertices[i]),
                );
            }
            self.error(
                d.with_hint("an alternative state gives a position for every vertex of its piece"),
            );
        }
        // Restated edges must equal the piece's: the part's edge set is shared by all states.
        for e in &st.edges {
            let mut list = Vec::new();
            let mut espans = Vec::new();
            self.edges(piece, e, &mut list, &mut espans);
            let key = |[a, b]: [usize; 2]| [a.min(b), a.max(b)];
            let mine: Vec<[usize; 2]> = piece.edges.iter().map(|&e| key(e)).collect();
            let theirs: Vec<[usize; 2]> = list.iter().map(|&e| key(e)).collect();
            let extra: Vec<String> = theirs
                .iter()
                .filter(|e| !mine.contains(e))
                .map(|&[a, b]| format!("`{}-{}`", piece.vertices[a], piece.vertices[b]))
                .collect();
            let missing: Vec<String> = mine
                .iter()
                .filter(|e| !theirs.contains(e))
                .map(|&[a, b]| format!("`{}-{}`", piece.vertices[a], piece.vertices[b]))
                .collect();
            if !extra.is_empty() || !missing.is_empty() {
                let mut parts = Vec::new();
                if !extra.is_empty() {
                    parts.push(format!("adds {}", extra.join(", ")));
                }
                if !missing.is_empty() {
                    parts.push(format!("lacks {}", missing.join(", ")));
                }
                self.error(
                    Diagnostic::error(
                        codes::STATE_EDGES,
                        format!("the edges of state `{}` differ from piece `{}`'s", st.name.name, piece.name),
                        e.span,
                        parts.join("; "),
                    )
                    .with_secondary(spans.name, "piece declared here")
                    .with_hint("a restated edge list must equal the piece's; or leave it out, the piece's edges apply"),
                );
            }
        }
        let positions: Vec<DVec2> = pos.iter().map(|p| p.unwrap_or(DVec2::ZERO)).collect();
        if missing.is_empty() {
            self.check_state_geometry(
                piece,
                &st.name.name,
                &positions,
                &vspans,
                st.name.span,
                &spans.edges,
            );
        }
        let own: Vec<Proxy> = st
            .geometry
            .iter()
            .filter_map(|g| self.geometry(g))
            .collect();
        let (geometry, geometry_frame) = if st.geometry.is_empty() {
            (base_geometry.to_vec(), 0)
        } else {
            (own, index)
        };
        RestState {
            name: st.name.name.clone(),
            positions,
            geometry,
            geometry_frame,
        }
    }

    /// Skinned geometry needs an axis (set by `axis` or by a stretch rule).
    fn check_skinned(&mut self, file: &syntax::File) {
        for item in &file.items {
            let Item::Piece(decl) = item else { continue };
            let Some(&pi) = self.piece_index.get(&decl.name.name) else {
                continue;
            };
            if self.piece_spans[pi].name != decl.name.span || self.pieces[pi].axis.is_some() {
                continue;
            }
            let mut geoms: Vec<&syntax::GeometryDecl> = Vec::new();
            for s in &decl.stmts {
                match s {
                    PieceStmt::Geometry(g) => geoms.push(g),
                    PieceStmt::State(st) => geoms.extend(st.geometry.iter()),
                    _ => {}
                }
            }
            for g in geoms {
                if let Some((syntax::BindingKw::Skinned, span)) = g.binding {
                    self.error(
                        Diagnostic::error(codes::NO_AXIS, format!("skinned geometry in piece `{}`, which has no axis", decl.name.name), span, "needs an axis to skin along")
                            .with_secondary(decl.name.span, "piece declared here")
                            .with_hint("add `axis FROM -> TO` to the piece, name it in a `stretch` rule, or make the geometry `rigid`"),
                    );
                    break;
                }
            }
        }
    }
}

/// Formats a number for messages: short, no trailing zeros.
pub(crate) fn fmt(x: f64) -> String {
    let r = (x * 1e4).round() / 1e4;
    let r = if r == 0.0 { 0.0 } else { r };
    format!("{r}")
}

impl CompiledGrammar {
    /// Whether every number in the grammar is finite.
    pub(crate) fn all_finite(&self) -> bool {
        let v = |p: &DVec2| p.is_finite();
        let proxies = |g: &[Proxy]| {
            g.iter().all(|p| match &p.shape {
                ProxyShape::Polygon { outer, holes } => {
                    outer.iter().all(v) && holes.iter().flatten().all(v)
                }
                ProxyShape::Polyline { points, width } => points.iter().all(v) && width.is_finite(),
            })
        };
        self.pieces.iter().all(|p| {
            p.sites.iter().all(|s| v(&s.out))
                && p.states
                    .iter()
                    .all(|s| s.positions.iter().all(v) && proxies(&s.geometry))
        }) && self
            .stretch_rules
            .iter()
            .all(|r| r.part.states.iter().all(|s| s.positions.iter().all(v)))
            && self.assembly.positions.iter().all(v)
            && self
                .assembly
                .parts
                .iter()
                .all(|p| p.states.iter().all(|s| s.positions.iter().all(v)))
    }
}
