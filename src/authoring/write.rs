//! A design made stretchable and written out: the stretch choice (paper 5.1), the design's
//! chains, and its `.clay` syntax tree (`Design::to_syntax`).

use std::collections::{BTreeMap, HashMap, HashSet};

use clay_dsl::syntax::*;
use glam::DVec2;

use super::drawing::AuthorError;
use super::pieces::*;

/// Width (metres) of the polylines that draw regions without a closed outline.
const STROKE_WIDTH: f64 = 0.05;

impl Design {
    /// Makes one piece stretchable (paper 5.1) between two opposite sites.
    pub fn make_stretchable(&mut self, choice: &StretchChoice) -> Result<(), AuthorError> {
        let (piece, from, to) = match *choice {
            StretchChoice::Sites { piece, from, to } => (piece, from, to),
            StretchChoice::Auto => self.auto_stretch()?,
        };
        let p = self
            .pieces
            .get(piece)
            .ok_or_else(|| AuthorError(format!("there is no piece {piece}")))?;
        let (Some(a), Some(b)) = (p.sites.get(from), p.sites.get(to)) else {
            return Err(AuthorError(format!(
                "piece `{}` has no sites {from} and {to}",
                p.name
            )));
        };
        if from == to || a.out.dot(b.out) >= -0.5 {
            return Err(AuthorError(format!(
                "sites `{}` and `{}` of piece `{}` do not point opposite ways; a stretchable piece repeats between two opposite sites",
                a.name, b.name, p.name
            )));
        }
        if !self.self_docks(piece, from, to) {
            return Err(AuthorError(format!(
                "sites `{}` and `{}` of piece `{}` are not the same shape (docked end to end, copies of it miss by {} m), so it cannot repeat between them; draw its repeated shapes alike within the tolerance",
                a.name,
                b.name,
                p.name,
                round6(self.self_dock_gap(piece, from, to))
            )));
        }
        self.pieces[piece].stretch = Some([from, to]);
        Ok(())
    }

    fn auto_stretch(&self) -> Result<(usize, usize, usize), AuthorError> {
        let mut counts = vec![0usize; self.pieces.len()];
        for i in &self.instances {
            counts[i.piece] += 1;
        }
        let piece = (0..self.pieces.len())
            .max_by_key(|&p| (counts[p], std::cmp::Reverse(p)))
            .unwrap_or(0);
        let mut pairs: BTreeMap<(usize, usize), usize> = BTreeMap::new();
        for d in &self.docks {
            if self.instances[d.a.0].piece == piece
                && self.instances[d.b.0].piece == piece
                && d.a.1 != d.b.1
            {
                *pairs
                    .entry((d.a.1.min(d.b.1), d.a.1.max(d.b.1)))
                    .or_default() += 1;
            }
        }
        let sites = &self.pieces[piece].sites;
        let best = pairs
            .into_iter()
            .filter(|((a, b), _)| sites[*a].out.dot(sites[*b].out) < -0.5)
            .filter(|((a, b), _)| self.self_docks(piece, *a, *b) && self.self_docks(piece, *b, *a))
            .max_by_key(|&((a, b), n)| (n, std::cmp::Reverse((a, b))))
            .map(|(k, _)| k);
        let Some((a, b)) = best else {
            return Err(AuthorError(format!(
                "no two instances of `{}` are docked through opposite sites of one shape, so there is no row to stretch",
                self.pieces[piece].name
            )));
        };
        // From the west (or south) site to the east (or north) one, so rows read left to right.
        let key = |s: usize| (sites[s].out.x, sites[s].out.y);
        let (from, to) = if key(a) < key(b) { (a, b) } else { (b, a) };
        Ok((piece, from, to))
    }

    /// Maximal runs of instances of a stretchable piece docked `to` -> `from`, in order; runs
    /// of two or more are written as chains.
    pub fn chains(&self) -> Vec<Vec<usize>> {
        let mut next: HashMap<usize, usize> = HashMap::new();
        let mut has_prev: HashSet<usize> = HashSet::new();
        for d in &self.docks {
            for (x, y) in [(d.a, d.b), (d.b, d.a)] {
                let pi = self.instances[x.0].piece;
                let Some([from, to]) = self.pieces[pi].stretch else {
                    continue;
                };
                if self.instances[y.0].piece == pi
                    && x.1 == to
                    && y.1 == from
                    && !next.contains_key(&x.0)
                    && !has_prev.contains(&y.0)
                {
                    next.insert(x.0, y.0);
                    has_prev.insert(y.0);
                }
            }
        }
        let mut seen = HashSet::new();
        let mut chains = Vec::new();
        // Starts: instances with a successor and no predecessor; then whatever is left (rings).
        let starts: Vec<usize> = (0..self.instances.len())
            .filter(|i| next.contains_key(i) && !has_prev.contains(i))
            .chain((0..self.instances.len()).filter(|i| next.contains_key(i)))
            .collect();
        for s in starts {
            if seen.contains(&s) {
                continue;
            }
            let mut run = vec![s];
            seen.insert(s);
            let mut cur = s;
            while let Some(&n) = next.get(&cur) {
                if !seen.insert(n) {
                    break;
                }
                run.push(n);
                cur = n;
            }
            if run.len() >= 2 {
                chains.push(run);
            }
        }
        chains
    }

    /// The design as a `.clay` syntax tree (default spans); print it with
    /// [`clay_dsl::print_file`].
    pub fn to_syntax(&self) -> File {
        let mut items = Vec::new();
        for t in &self.site_types {
            items.push(Item::SiteType(SiteTypeDecl {
                name: ident(t),
                docks: Vec::new(),
                span: Span::default(),
            }));
        }
        for p in &self.pieces {
            items.push(Item::Piece(self.piece_decl(p)));
        }
        for p in &self.pieces {
            if let Some([from, to]) = p.stretch {
                items.push(Item::Stretch(StretchDecl {
                    piece: ident(&p.name),
                    from: ident(&p.sites[from].name),
                    to: ident(&p.sites[to].name),
                    min: vec![number(2.0)],
                    max: Vec::new(),
                    variants: Vec::new(),
                    span: Span::default(),
                }));
            }
        }
        items.push(Item::Model(self.model_block()));
        File {
            items,
            span: Span::default(),
        }
    }

    fn piece_decl(&self, p: &PieceDesign) -> PieceDecl {
        let v = |i: usize| ident(&format!("v{i}"));
        let mut stmts: Vec<PieceStmt> = p
            .positions
            .iter()
            .enumerate()
            .map(|(i, pos)| {
                PieceStmt::Vertex(VertexDecl {
                    name: v(i),
                    pos: point(*pos),
                    span: Span::default(),
                })
            })
            .collect();
        let mut paths: Vec<Vec<Ident>> = Vec::new();
        let mut written: HashSet<[usize; 2]> = HashSet::new();
        if let Some(o) = &p.outline {
            let mut path: Vec<Ident> = o.iter().map(|&i| v(i)).collect();
            path.push(v(o[0]));
            paths.push(path);
            for k in 0..o.len() {
                let (a, b) = (o[k], o[(k + 1) % o.len()]);
                written.insert([a.min(b), a.max(b)]);
            }
        }
        for e in &p.edges {
            if written.insert(*e) {
                paths.push(vec![v(e[0]), v(e[1])]);
            }
        }
        if !paths.is_empty() {
            stmts.push(PieceStmt::Edges(EdgesDecl {
                paths,
                span: Span::default(),
            }));
        }
        for s in &p.sites {
            stmts.push(PieceStmt::Site(SiteDecl {
                name: ident(&s.name),
                site_type: ident(&self.site_types[s.site_type]),
                vertices: s.vertices.iter().map(|&i| v(i)).collect(),
                vertices_span: Span::default(),
                out: point(s.out),
                span: Span::default(),
            }));
        }
        let binding = Some((
            if p.stretch.is_some() {
                BindingKw::Skinned
            } else {
                BindingKw::Rigid
            },
            Span::default(),
        ));
        let fill = Colour {
            rgba: [p.fill[0], p.fill[1], p.fill[2], 255],
            span: Span::default(),
        };
        match &p.outline {
            Some(o) => stmts.push(PieceStmt::Geometry(GeometryDecl {
                shape: ShapeDecl::Polygon {
                    outer: o.iter().map(|&i| point(p.positions[i])).collect(),
                    holes: Vec::new(),
                },
                binding,
                fill,
                extrude: None,
                keyword: Span::default(),
                span: Span::default(),
            })),
            None => {
                for e in &p.edges {
                    stmts.push(PieceStmt::Geometry(GeometryDecl {
                        shape: ShapeDecl::Polyline {
                            width: number(STROKE_WIDTH),
                            points: vec![point(p.positions[e[0]]), point(p.positions[e[1]])],
                        },
                        binding,
                        fill,
                        extrude: None,
                        keyword: Span::default(),
                        span: Span::default(),
                    }));
                }
            }
        }
        PieceDecl {
            name: ident(&p.name),
            extends: None,
            stmts,
            span: Span::default(),
        }
    }

    // Long because: the model block's items in order (instances, chains, placement, docks).
    fn model_block(&self) -> ModelBlock {
        let layout = self.layout();
        let (chains, chain_of) = (&layout.chains, &layout.chain_of);
        let mut chain_names = Vec::new();
        let mut per_piece: HashMap<usize, usize> = HashMap::new();
        let mut taken: HashSet<String> = self.instances.iter().map(|i| i.name.clone()).collect();
        for run in chains {
            let piece = self.instances[run[0]].piece;
            let n = per_piece.entry(piece).or_insert(0);
            // A chain's name is an instance name too (E010): skip those taken.
            let base = format!("{}_chain", self.pieces[piece].name);
            let name = loop {
                *n += 1;
                let name = if *n == 1 {
                    base.clone()
                } else {
                    format!("{base}{n}")
                };
                if !taken.contains(name.as_str()) {
                    break name;
                }
            };
            taken.insert(name.clone());
            chain_names.push(name);
        }
        // One instance per connected group is placed with `at`; the rest through their docks.
        let place = |i: usize| -> (Option<Point>, Option<Expr>) {
            if !layout.anchored.contains(&i) {
                return (None, None);
            }
            let (deg, at) = self.written_motion(i);
            (Some(point(at)), (deg != 0.0).then(|| number(deg)))
        };
        let mut stmts = Vec::new();
        for (i, inst) in self.instances.iter().enumerate() {
            let (at, rotate) = place(i);
            match chain_of.get(&i) {
                Some(&(c, 0)) => stmts.push(ModelStmt::Chain(ChainDecl {
                    name: ident(&chain_names[c]),
                    piece: ident(&self.pieces[inst.piece].name),
                    count: number(chains[c].len() as f64),
                    along: None,
                    at,
                    rotate,
                    span: Span::default(),
                })),
                Some(_) => {}
                None => stmts.push(ModelStmt::Instance(InstanceDecl {
                    name: ident(&inst.name),
                    piece: ident(&self.pieces[inst.piece].name),
                    at,
                    rotate,
                    span: Span::default(),
                })),
            }
        }
        let site_path = |(i, s): (usize, usize)| -> InstanceSitePath {
            let site = ident(&self.pieces[self.instances[i].piece].sites[s].name);
            match chain_of.get(&i) {
                Some(&(c, k)) => InstanceSitePath {
                    instance: ident(&chain_names[c]),
                    index: Some(ElementIndex {
                        index: ElementIndexKind::At(k as u64),
                        span: Span::default(),
                    }),
                    site,
                    span: Span::default(),
                },
                None => InstanceSitePath {
                    instance: ident(&self.instances[i].name),
                    index: None,
                    site,
                    span: Span::default(),
                },
            }
        };
        for (k, d) in self.docks.iter().enumerate() {
            // Docks inside a chain are implied by the chain.
            if self.implied_by_chain(&layout, k) {
                continue;
            }
            stmts.push(ModelStmt::Dock(DockDecl {
                a: site_path(d.a),
                b: site_path(d.b),
                span: Span::default(),
            }));
        }
        ModelBlock {
            stmts,
            keyword: Span::default(),
            span: Span::default(),
        }
    }
}

fn ident(name: &str) -> Ident {
    Ident {
        name: name.to_string(),
        span: Span::default(),
    }
}

fn number(value: f64) -> Expr {
    Expr::number(value, Span::default())
}

fn point(p: DVec2) -> Point {
    Point {
        x: number(round6(p.x)),
        y: number(round6(p.y)),
        span: Span::default(),
    }
}
