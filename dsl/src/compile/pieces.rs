//! Compiling a `piece` declaration: its vertices, edges, docking sites, proxy geometry and
//! alternative rest states (paper 4.1), with the checks on each.

use std::collections::HashMap;

use crate::compiled::*;
use crate::diagnostic::Diagnostic;
use crate::suggest::closest;
use crate::syntax::{self, Ident, PieceStmt, Span};
use glam::DVec2;

use super::limits::{COINCIDENT_EPS, MAX_COORDINATE, MAX_HEIGHT};
use super::state::{Compiler, PieceSpans, fmt};
use super::{codes, derive};

/// The colour of a `mesh` whose asset gives none and that has no `fill` (a light stone grey).
const MESH_FILL: Rgba = Rgba([0xb8, 0xb2, 0xa7, 0xff]);

impl Compiler {
    // Long because: one pass over the piece's statements in source order, each a short arm of one match.
    pub(super) fn piece_decl(&mut self, decl: &syntax::PieceDecl) {
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
        // each vertex's index by name: a lookup per vertex, not a scan (a piece may have
        // 100,000 of them)
        let mut named: HashMap<String, usize> = HashMap::new();
        // Vertices first: statements may come in any order and refer to later vertices.
        for s in &decl.stmts {
            if let PieceStmt::Vertex(v) = s {
                if let Some(&i) = named.get(&v.name.name) {
                    self.duplicate("vertex", &v.name, spans.vertices[i]);
                    spans.partial = true;
                    continue;
                }
                named.insert(v.name.name.clone(), piece.vertices.len());
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
        let mut list = EdgeList::default();
        let mut axis: Option<&syntax::AxisDecl> = None;
        let mut geometry = Vec::new();
        for s in &decl.stmts {
            match s {
                PieceStmt::Edges(e) => {
                    list.edges = std::mem::take(&mut piece.edges);
                    if !self.edges(&piece, &named, e, &mut list) {
                        spans.partial = true;
                    }
                    piece.edges = std::mem::take(&mut list.edges);
                }
                PieceStmt::Site(site) => {
                    if let Some(i) = piece.sites.iter().position(|x| x.name == site.name.name) {
                        self.duplicate("site", &site.name, spans.sites[i]);
                        spans.partial = true;
                        continue;
                    }
                    match self.site(&piece, &named, site) {
                        Some(compiled) => {
                            piece.sites.push(compiled);
                            spans.sites.push(site.name.span);
                        }
                        None => {
                            spans.failed_sites.push(site.name.name.clone());
                            spans.partial = true;
                        }
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
            &list.spans,
        );
        piece.states.push(RestState {
            name: "base".into(),
            positions: base.clone(),
            geometry: geometry.clone(),
            geometry_frame: 0,
        });
        spans.edges = list.spans;
        let derive_axis = derive::AxisState::resolve(&piece, axis, &base);
        let mut made = vec![derive::Made::Listed];
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
                let state = match &st.derive {
                    Some(d) => {
                        let cx = derive::DeriveContext {
                            decl,
                            spans: &spans,
                            axis: derive_axis,
                            base_geometry: &geometry,
                            made: &made,
                        };
                        let (state, how) = self.derived_state(&piece, &cx, st, d, index);
                        made.push(how);
                        state
                    }
                    None => {
                        let before = self.diags.error_count();
                        let state = self.state(&piece, &named, &spans, st, index, &geometry);
                        made.push(if self.diags.error_count() == before {
                            derive::Made::Listed
                        } else {
                            derive::Made::Failed
                        });
                        state
                    }
                };
                piece.states.push(state);
                state_spans.push(st.name.span);
                spans
                    .states
                    .push(Span::new(st.span.start, st.name.span.end));
            }
        }
        if let Some(a) = axis
            && ![&a.from, &a.to]
                .iter()
                .any(|s| spans.failed_sites.contains(&s.name))
        {
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
    pub(super) fn site_on(&mut self, piece: &Piece, ident: &Ident) -> Option<usize> {
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

    pub(super) fn vertex_index(
        &mut self,
        piece: &Piece,
        named: &HashMap<String, usize>,
        ident: &Ident,
    ) -> Option<usize> {
        let known = (named.get(&ident.name).copied())
            .filter(|&i| piece.vertices.get(i) == Some(&ident.name));
        match known.or_else(|| piece.vertices.iter().position(|v| *v == ident.name)) {
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
    /// False when an edge written was dropped for an error (an unknown vertex, a loop); a
    /// repeat is only a warning and drops nothing.
    pub(super) fn edges(
        &mut self,
        piece: &Piece,
        named: &HashMap<String, usize>,
        e: &syntax::EdgesDecl,
        list: &mut EdgeList,
    ) -> bool {
        let mut whole = true;
        for path in &e.paths {
            let ids: Vec<Option<usize>> = (path.iter())
                .map(|v| self.vertex_index(piece, named, v))
                .collect();
            whole &= ids.iter().all(Option::is_some);
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
                    whole = false;
                    continue;
                }
                if let Some(i) = list.find(a, b) {
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
                        .with_secondary(list.spans[i], "first listed here")
                        .with_hint("edges are undirected: `a-b` and `b-a` are the same edge"),
                    );
                    continue;
                }
                list.push([a, b], span);
            }
        }
        whole
    }

    pub(super) fn site(
        &mut self,
        piece: &Piece,
        named: &HashMap<String, usize>,
        s: &syntax::SiteDecl,
    ) -> Option<Site> {
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
            match self.vertex_index(piece, named, v) {
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
        if !out.is_finite() {
            // Out of range: E013 was reported; the site fails quietly with it.
            ok = false;
        } else if len < COINCIDENT_EPS {
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

    /// The proxies of a geometry statement: one, or none after an error; a `mesh` gives one
    /// per colour of its asset.
    pub(super) fn geometry(&mut self, g: &syntax::GeometryDecl) -> Vec<Proxy> {
        let binding = match g.binding {
            Some((syntax::BindingKw::Skinned, _)) => Binding::Skinned,
            _ => Binding::Rigid,
        };
        if let syntax::ShapeDecl::Mesh { path, fill } = &g.shape {
            let parts = self.meshes.get(path.span).unwrap_or_default();
            return parts
                .iter()
                .map(|part| Proxy {
                    shape: part.shape.clone(),
                    fill: fill
                        .as_ref()
                        .map(|c| Rgba(c.rgba))
                        .or(part.fill)
                        .unwrap_or(MESH_FILL),
                    binding,
                    extrude: None,
                })
                .collect();
        }
        self.flat_geometry(g, binding).into_iter().collect()
    }

    fn flat_geometry(&mut self, g: &syntax::GeometryDecl, binding: Binding) -> Option<Proxy> {
        let fill = Rgba(g.fill.rgba);
        let shape = match &g.shape {
            syntax::ShapeDecl::Mesh { .. } => return None,
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
        let extrude = match &g.extrude {
            None => None,
            Some(e) => {
                let height = self.in_range(
                    &e.height,
                    "`extrude` height",
                    |h| h > 0.0 && h <= MAX_HEIGHT,
                    &format!("above 0 and at most {MAX_HEIGHT} metres"),
                );
                let base = match &e.above {
                    None => Some(0.0),
                    Some(b) => self.in_range(
                        b,
                        "`above` (the base height)",
                        |b| b.abs() <= MAX_HEIGHT,
                        &format!("within +/-{MAX_HEIGHT} metres"),
                    ),
                };
                Some(Extrude {
                    height: height?,
                    base: base?,
                })
            }
        };
        Some(Proxy {
            shape,
            fill,
            binding,
            extrude,
        })
    }

    pub(super) fn enough_points(&mut self, n: usize, min: usize, what: &str, span: Span) -> bool {
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
    pub(super) fn check_state_geometry(
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

    // Long because: a rest state's checks in order (names, vertex coverage, geometry), each reporting its own diagnostic.
    pub(super) fn state(
        &mut self,
        piece: &Piece,
        named: &HashMap<String, usize>,
        spans: &PieceSpans,
        st: &syntax::StateDecl,
        index: usize,
        base_geometry: &[Proxy],
    ) -> RestState {
        let n = piece.vertices.len();
        let mut pos: Vec<Option<DVec2>> = vec![None; n];
        let mut vspans: Vec<Span> = vec![st.name.span; n];
        for p in &st.positions {
            match named.get(&p.name.name).copied().filter(|&i| i < n) {
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
            let mut list = EdgeList::default();
            // An edge dropped here or in the piece was reported where it was written: the two
            // lists then differ by that mistake, not by a second one.
            if !self.edges(piece, named, e, &mut list) || spans.partial {
                continue;
            }
            let list = list.edges;
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
        let own: Vec<Proxy> = st.geometry.iter().flat_map(|g| self.geometry(g)).collect();
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
}

/// A piece's edges as an `edges` statement adds them, with where each was written and an
/// index by its (unordered) ends: a repeat is found by a lookup, not a scan of every edge.
#[derive(Default)]
pub(super) struct EdgeList {
    pub edges: Vec<[usize; 2]>,
    pub spans: Vec<Span>,
    index: HashMap<[usize; 2], usize>,
}

impl EdgeList {
    /// The position of edge `a-b` (either way) when listed.
    fn find(&mut self, a: usize, b: usize) -> Option<usize> {
        // `edges` may have been refilled from the piece: index what the index lacks
        for (k, &[x, y]) in self.edges.iter().enumerate().skip(self.index.len()) {
            self.index.entry([x.min(y), x.max(y)]).or_insert(k);
        }
        self.index.get(&[a.min(b), a.max(b)]).copied()
    }

    fn push(&mut self, edge: [usize; 2], span: Span) {
        self.index
            .entry([edge[0].min(edge[1]), edge[0].max(edge[1])])
            .or_insert(self.edges.len());
        self.edges.push(edge);
        self.spans.push(span);
    }
}
