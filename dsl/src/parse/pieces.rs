//! A `site type` and a `piece`: vertices, edges, sites, the axis, proxy geometry (polygons,
//! polylines, meshes, their fill and extrusion) and rest states (listed, bent or mirrored).

use pest::iterators::Pair;

use super::grammar::Rule;
use super::lower::{Lower, first, kids, of, span_of};
use crate::syntax::*;

impl Lower {
    pub(super) fn site_type(&mut self, p: Pair<Rule>) -> SiteTypeDecl {
        let span = span_of(&p);
        let mut names = self.idents(&kids(p)).into_iter();
        let name = names.next().unwrap_or(Ident {
            name: String::new(),
            span,
        });
        SiteTypeDecl {
            name,
            docks: names.collect(),
            span,
        }
    }

    pub(super) fn piece(&mut self, p: Pair<Rule>) -> PieceDecl {
        let span = span_of(&p);
        let ch = kids(p);
        let name = self.name_or(&ch, span);
        let extends = first(&ch, Rule::extends)
            .and_then(|e| first(&kids(e), Rule::name))
            .map(|n| self.ident(n));
        let mut stmts = Vec::new();
        for c in ch {
            let stmt = match c.as_rule() {
                Rule::vertex_decl => PieceStmt::Vertex(self.vertex(c)),
                Rule::edges_decl => PieceStmt::Edges(self.edges(c)),
                Rule::site_decl => PieceStmt::Site(self.site(c)),
                Rule::axis_decl => {
                    let aspan = span_of(&c);
                    let names = self.idents(&kids(c));
                    let (Some(from), Some(to)) = (names.first(), names.get(1)) else {
                        continue;
                    };
                    PieceStmt::Axis(AxisDecl {
                        from: from.clone(),
                        to: to.clone(),
                        span: aspan,
                    })
                }
                Rule::polygon_decl | Rule::polyline_decl | Rule::mesh_decl => {
                    PieceStmt::Geometry(self.geometry(c))
                }
                Rule::state_decl => PieceStmt::State(self.state(c)),
                _ => continue,
            };
            stmts.push(stmt);
        }
        PieceDecl {
            name,
            extends,
            stmts,
            span,
        }
    }

    fn vertex(&mut self, p: Pair<Rule>) -> VertexDecl {
        let span = span_of(&p);
        let ch = kids(p);
        let name = self.name_or(&ch, span);
        let pos = first(&ch, Rule::point).map(|q| self.point(q));
        let zero = Expr::number(0.0, span);
        VertexDecl {
            name,
            pos: pos.unwrap_or(Point {
                x: zero.clone(),
                y: zero,
                span,
            }),
            span,
        }
    }

    fn edges(&mut self, p: Pair<Rule>) -> EdgesDecl {
        let span = span_of(&p);
        let paths = of(&kids(p), Rule::edge_path)
            .into_iter()
            .map(|path| self.idents(&kids(path)))
            .collect();
        EdgesDecl { paths, span }
    }

    fn site(&mut self, p: Pair<Rule>) -> SiteDecl {
        let span = span_of(&p);
        let ch = kids(p);
        let names = self.idents(&ch);
        let empty = Ident {
            name: String::new(),
            span,
        };
        let list = first(&ch, Rule::vertex_list);
        let vertices_span = list.as_ref().map_or(span, span_of);
        let vertices = list.map(|l| self.idents(&kids(l))).unwrap_or_default();
        let out = first(&ch, Rule::point).map(|q| self.point(q));
        let zero = Expr::number(0.0, span);
        SiteDecl {
            name: names.first().cloned().unwrap_or(empty.clone()),
            site_type: names.get(1).cloned().unwrap_or(empty),
            vertices,
            vertices_span,
            out: out.unwrap_or(Point {
                x: zero.clone(),
                y: zero,
                span,
            }),
            span,
        }
    }

    fn geometry(&mut self, p: Pair<Rule>) -> GeometryDecl {
        let span = span_of(&p);
        let rule = p.as_rule();
        let ch = kids(p);
        let keyword = ch.first().map_or(span, span_of);
        let binding = first(&ch, Rule::binding).map(|b| {
            let bspan = span_of(&b);
            let kind = if b.as_str().starts_with("skinned") {
                BindingKw::Skinned
            } else {
                BindingKw::Rigid
            };
            (kind, bspan)
        });
        let fill = first(&ch, Rule::colour).map_or(
            Colour {
                rgba: [255; 4],
                span,
            },
            |c| self.colour(c),
        );
        let points = first(&ch, Rule::point_list)
            .map(|l| self.points(l))
            .unwrap_or_default();
        let shape = if rule == Rule::mesh_decl {
            ShapeDecl::Mesh {
                path: self.string_or(first(&ch, Rule::string), span),
                fill: first(&ch, Rule::colour).map(|c| self.colour(c)),
            }
        } else if rule == Rule::polygon_decl {
            let holes = of(&ch, Rule::hole)
                .into_iter()
                .map(|h| {
                    let hspan = span_of(&h);
                    let points = first(&kids(h), Rule::point_list)
                        .map(|l| self.points(l))
                        .unwrap_or_default();
                    HoleDecl {
                        points,
                        span: hspan,
                    }
                })
                .collect();
            ShapeDecl::Polygon {
                outer: points,
                holes,
            }
        } else {
            let width = self.expr_or(first(&ch, Rule::expr), span);
            ShapeDecl::Polyline { width, points }
        };
        let extrude = first(&ch, Rule::extrude).map(|e| {
            let espan = span_of(&e);
            let mut exprs = of(&kids(e), Rule::expr).into_iter();
            let height = self.expr_or(exprs.next(), espan);
            let above = exprs.next().map(|b| self.expr(b).0);
            ExtrudeDecl {
                height,
                above,
                span: espan,
            }
        });
        GeometryDecl {
            shape,
            binding,
            fill,
            extrude,
            keyword,
            span,
        }
    }

    fn state(&mut self, p: Pair<Rule>) -> StateDecl {
        let span = span_of(&p);
        let ch = kids(p);
        let name = self.name_or(&ch, span);
        let mut positions = Vec::new();
        let mut edges = Vec::new();
        let mut geometry = Vec::new();
        let mut derive = None;
        for c in ch {
            match c.as_rule() {
                Rule::state_position => positions.push(self.vertex(c)),
                Rule::edges_decl => edges.push(self.edges(c)),
                Rule::polygon_decl | Rule::polyline_decl => geometry.push(self.geometry(c)),
                Rule::state_bend | Rule::state_mirror => derive = self.state_derive(c),
                Rule::derived_body => {
                    for g in kids(c) {
                        geometry.push(self.geometry(g));
                    }
                }
                _ => {}
            }
        }
        StateDecl {
            name,
            positions,
            edges,
            geometry,
            derive,
            span,
        }
    }

    /// `bend ANGLE` or `mirror OTHER`.
    fn state_derive(&mut self, p: Pair<Rule>) -> Option<StateDerive> {
        let span = span_of(&p);
        let is_bend = p.as_rule() == Rule::state_bend;
        let ch = kids(p);
        let keyword = span_of(ch.first()?);
        let kind = if is_bend {
            DeriveKind::Bend(self.expr(first(&ch, Rule::expr)?).0)
        } else {
            DeriveKind::Mirror(self.ident(first(&ch, Rule::name)?))
        };
        Some(StateDerive {
            kind,
            keyword,
            span,
        })
    }
}
