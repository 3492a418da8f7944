//! Compiles the rules: stretch (with its derived two-element part and the `one`/`two`/`three`
//! rest states), merge, and cut (written ones, then those derived from merges into junctions).

use glam::DVec2;

use super::codes;
use super::limits::DOCK_TOLERANCE;
use super::state::{Compiler, fmt};
use crate::compiled::*;
use crate::diagnostic::Diagnostic;
use crate::syntax::{self, Item, Span};

/// Axis scale factors of the stretch part's rest states `one`, `two`, `three`.
pub const STRETCH_STATES: [(&str, f64); 3] = [("one", 0.5), ("two", 1.0), ("three", 1.5)];

/// Rotation by `angle` radians.
pub(crate) fn rotate(v: DVec2, angle: f64) -> DVec2 {
    // Snap cos/sin near 0 or +-1 so quarter turns are exact: a wall turned by 180 degrees
    // should not carry 1e-16 noise into every position.
    let snap = |x: f64| {
        let r = x.round();
        if (x - r).abs() < 1e-12 { r } else { x }
    };
    let (sin, cos) = angle.sin_cos();
    DVec2::new(snap(cos), snap(sin)).rotate(v)
}

/// The rigid motion `(angle, translation)` that docks site `sb` of a piece with base positions
/// `pos_b` onto a site whose global centre and out direction are `centre_a`, `out_a`: `sb`'s
/// out turns opposite `out_a` and the centres meet.
pub(crate) fn dock_motion(
    centre_a: DVec2,
    out_a: DVec2,
    sb: &Site,
    pos_b: &[DVec2],
) -> (f64, DVec2) {
    let angle = (-out_a).to_angle() - sb.out.to_angle();
    let centre_b = site_centre(sb, pos_b);
    (angle, centre_a - rotate(centre_b, angle))
}

/// The centre (mean of its vertices) of a site.
pub(crate) fn site_centre(site: &Site, pos: &[DVec2]) -> DVec2 {
    let sum: DVec2 = site.vertices.iter().map(|&v| pos[v]).sum();
    sum / site.vertices.len().max(1) as f64
}

impl Compiler {
    pub(super) fn rules(&mut self, file: &syntax::File) {
        // Which stretch rule (by its span) first claimed each piece.
        let mut claimed: Vec<Option<Span>> = vec![None; self.pieces.len()];
        self.stretch_named = vec![false; self.pieces.len()];
        for item in &file.items {
            if let Item::Stretch(s) = item
                && !self.quiet_rule(item)
            {
                self.stretch(s, &mut claimed);
            }
        }
        for item in &file.items {
            if let Item::Merge(m) = item
                && !self.quiet_rule(item)
            {
                self.merge(m);
            }
        }
        for item in &file.items {
            if let Item::Cut(c) = item
                && !self.quiet_rule(item)
            {
                self.cut(c);
            }
        }
        // Derived cuts: undo every merge into a junction unless a cut for that site is written.
        for m in self.merge_rules.clone() {
            let Some(j) = m.junction else { continue };
            if !self.cut_index.contains_key(&j) {
                self.cut_index.insert(j, self.cut_rules.len());
                self.cut_rules.push(CutRule {
                    junction: j,
                    into: m.target.piece,
                    derived: true,
                });
            }
        }
    }

    // Long because: the stretch rule's checks in order, each with its own diagnostic.
    fn stretch(&mut self, s: &syntax::StretchDecl, claimed: &mut [Option<Span>]) {
        let Some(pi) = self.resolve_piece(&s.piece) else {
            return;
        };
        self.stretch_named[pi] = true;
        // Its variants are chain elements too (their axis comes from the rule), even when the
        // rule fails: no "no axis" error follows for them.
        for e in s.variants.iter().flat_map(|v| &v.entries) {
            if let Some(&vp) = self.piece_index.get(&e.piece.name) {
                self.stretch_named[vp] = true;
            }
        }
        // `stretch PIECE from A to B`, without its `{ ... }` block: what messages point at.
        let head = Span::new(s.span.start, s.to.span.end);
        let from = self.resolve_site(pi, &s.from);
        let to = self.resolve_site(pi, &s.to);
        let min = match s.min.as_slice() {
            [] => Some(2),
            [m, rest @ ..] => {
                for r in rest {
                    let id = syntax::Ident {
                        name: "min".into(),
                        span: r.span,
                    };
                    self.duplicate("setting", &id, m.span);
                }
                self.whole(m, "`min`", 2).map(|v| v as usize)
            }
        };
        // `Some(None)`: no `max` written; `None`: a `max` that failed (reported).
        let max = match s.max.as_slice() {
            [] => Some(None),
            [m, rest @ ..] => {
                for r in rest {
                    let id = syntax::Ident {
                        name: "max".into(),
                        span: r.span,
                    };
                    self.duplicate("setting", &id, m.span);
                }
                match (self.whole(m, "`max`", 2), min, s.min.first()) {
                    (None, ..) => None,
                    // Below a written `min` (the default 2 is the least `whole` accepts).
                    (Some(v), Some(lo), Some(written)) if v < lo as u64 => {
                        self.error(
                            Diagnostic::error(codes::OUT_OF_RANGE, format!("`max` {v} is below `min` {lo}"), m.span, format!("must be at least {lo}"))
                                .with_secondary(written.span, "the `min` of this rule")
                                .with_hint("a chain never grows beyond `max` elements nor shrinks below `min`: raise `max` to at least `min`, or lower `min`"),
                        );
                        None
                    }
                    (Some(v), ..) => Some(Some(v as usize)),
                }
            }
        };
        let mut variants = Vec::new();
        let mut ok = true;
        if let Some((first, rest)) = s.variants.split_first() {
            for r in rest {
                let id = syntax::Ident {
                    name: "variants".into(),
                    span: r.span,
                };
                self.duplicate("setting", &id, first.span);
            }
            let mut sum = 0.0;
            // A frequency already reported leaves the sum unknown: no second error about it.
            let mut sum_known = true;
            for (k, e) in first.entries.iter().enumerate() {
                if let Some(j) = first.entries[..k]
                    .iter()
                    .position(|x| x.piece.name == e.piece.name)
                {
                    self.duplicate("variant", &e.piece, first.entries[j].piece.span);
                    ok = false;
                    continue;
                }
                let f = self.in_range(
                    &e.frequency,
                    "a variant frequency",
                    |f| f > 0.0 && f <= 1.0,
                    "above 0 and at most 1",
                );
                match f {
                    Some(f) => sum += f,
                    None => sum_known = false,
                }
                let Some(vp) = self.resolve_piece(&e.piece) else {
                    ok = false;
                    continue;
                };
                if !self.same_shape(pi, vp, e.piece.span) {
                    ok = false;
                }
                match f {
                    Some(frequency) => variants.push(Variant {
                        piece: vp,
                        frequency,
                    }),
                    None => ok = false,
                }
            }
            if sum_known && (sum - 1.0).abs() > 1e-6 {
                self.error(
                    Diagnostic::error(codes::FREQUENCIES, format!("variant frequencies sum to {}, not 1", fmt(sum)), first.span, "these frequencies")
                        .with_hint("the frequencies are target proportions of the chain's elements and must sum to 1"),
                );
                ok = false;
            }
        } else {
            variants.push(Variant {
                piece: pi,
                frequency: 1.0,
            });
        }
        for v in &variants {
            if let Some(first) = claimed[v.piece] {
                let name = self.pieces[v.piece].name.clone();
                self.error(
                    Diagnostic::error(codes::TWO_STRETCH, format!("piece `{name}` belongs to two stretch rules"), head, "second rule here")
                        .with_secondary(first, "first rule here")
                        .with_hint("a piece may be the piece or a variant of one stretch rule only, so chains are unambiguous"),
                );
                ok = false;
            } else {
                claimed[v.piece] = Some(head);
                // Checked at the first claim only, so a piece gets one E047 however it is named.
                self.no_element_states(v.piece, head);
            }
        }
        let (Some(from), Some(to), Some(min), Some(max)) = (from, to, min, max) else {
            return;
        };
        let piece = self.pieces[pi].clone();
        if !self.opposite(&piece, from, to, head, "stretch rule") {
            return;
        }
        let (ff, tt) = (&piece.sites[from], &piece.sites[to]);
        if !self.sites_fit(ff, tt, s.from.span, s.to.span) {
            return;
        }
        if !ok || !self.piece_spans[pi].sound {
            return;
        }
        let Some(part) = self.stretch_part(&piece, from, to, s) else {
            return;
        };
        for v in &variants {
            if self.pieces[v.piece].axis.is_none() {
                self.pieces[v.piece].axis = Some([from, to]);
            }
        }
        self.stretch_rules.push(StretchRule {
            piece: pi,
            variants,
            from,
            to,
            min,
            max,
            part,
        });
        self.stretch_spans.push(s.span);
    }

    /// A chain element may not declare alternative rest states: the solver covers every chain
    /// with two-element stretch parts, whose only states are `one`/`two`/`three`, so the piece's
    /// own states could never become active. Reports the first of them (E047) against `rule`.
    fn no_element_states(&mut self, piece: usize, rule: Span) {
        let Some(&first) = self.piece_spans[piece].states.first() else {
            return;
        };
        let p = &self.pieces[piece];
        // `states[0]` is `base`; the first alternative is the one `first` points at.
        let (name, state) = (p.name.clone(), p.states[1].name.clone());
        self.error(
            Diagnostic::error(codes::ELEMENT_STATES, format!("piece `{name}` is a chain element, so it cannot have alternative rest states"), first, format!("state `{state}` would never become active"))
                .with_secondary(rule, format!("this rule makes `{name}` a chain element"))
                .with_hint("alternative states on a stretch element would never become active: the chain's two-element parts only have the one/two/three states; move the states to a piece outside the chain, or drop the stretch rule"),
        );
    }

    /// Site types compatible and vertex counts equal; reports otherwise.
    pub(super) fn sites_fit(&mut self, a: &Site, b: &Site, span_a: Span, span_b: Span) -> bool {
        let mut ok = true;
        if !self.site_types[a.site_type]
            .docks_with
            .contains(&b.site_type)
        {
            let (ta, tb) = (
                self.site_types[a.site_type].name.clone(),
                self.site_types[b.site_type].name.clone(),
            );
            self.error(
                Diagnostic::error(
                    codes::INCOMPATIBLE,
                    format!("site types `{ta}` and `{tb}` cannot dock"),
                    span_b,
                    format!("`{}` has type `{tb}`", b.name),
                )
                .with_secondary(span_a, format!("`{}` has type `{ta}`", a.name))
                .with_hint(format!("declare `site type {ta} docks {tb}` to allow it")),
            );
            ok = false;
        }
        if a.vertices.len() != b.vertices.len() {
            self.error(
                Diagnostic::error(
                    codes::SITE_COUNT,
                    format!("docked sites have different vertex counts: `{}` has {}, `{}` has {}", a.name, a.vertices.len(), b.name, b.vertices.len()),
                    span_b,
                    format!("{} vertices", b.vertices.len()),
                )
                .with_secondary(span_a, format!("{} vertices", a.vertices.len()))
                .with_hint("vertex i of one site meets vertex n-1-i of the other, so both need the same count"),
            );
            ok = false;
        }
        ok
    }

    /// Variants share vertex names (in order), edges and site names (in order) with the piece.
    /// Silent (and false) when either piece lost a vertex, edge or site to an error reported
    /// in it: their shapes then differ by that mistake, not by a second one.
    fn same_shape(&mut self, pi: usize, vi: usize, span: Span) -> bool {
        if pi == vi {
            return true;
        }
        if self.piece_spans[pi].partial || self.piece_spans[vi].partial {
            return false;
        }
        let (p, v) = (&self.pieces[pi], &self.pieces[vi]);
        let key = |e: &[usize; 2]| [e[0].min(e[1]), e[0].max(e[1])];
        let mut pe: Vec<[usize; 2]> = p.edges.iter().map(key).collect();
        let mut ve: Vec<[usize; 2]> = v.edges.iter().map(key).collect();
        pe.sort();
        ve.sort();
        let ps: Vec<&str> = p.sites.iter().map(|s| s.name.as_str()).collect();
        let vs: Vec<&str> = v.sites.iter().map(|s| s.name.as_str()).collect();
        let problem = if p.vertices != v.vertices {
            Some(format!(
                "vertices [{}] differ from [{}]",
                v.vertices.join(", "),
                p.vertices.join(", ")
            ))
        } else if pe != ve {
            let name = |e: &[usize; 2]| format!("`{}-{}`", p.vertices[e[0]], p.vertices[e[1]]);
            let extra: Vec<String> = ve.iter().filter(|e| !pe.contains(e)).map(name).collect();
            let missing: Vec<String> = pe.iter().filter(|e| !ve.contains(e)).map(name).collect();
            Some(format!(
                "edges differ (extra: {}; missing: {})",
                or_none(&extra),
                or_none(&missing)
            ))
        } else if ps != vs {
            Some(format!(
                "sites [{}] differ from [{}]",
                vs.join(", "),
                ps.join(", ")
            ))
        } else if let Some((a, b)) = p
            .sites
            .iter()
            .zip(&v.sites)
            .find(|(a, b)| a.vertices != b.vertices || a.site_type != b.site_type)
        {
            // Site indices and vertex lists are shared by every variant of the rule.
            Some(if a.site_type != b.site_type {
                format!(
                    "site `{}` has type `{}`, not `{}`",
                    b.name, self.site_types[b.site_type].name, self.site_types[a.site_type].name
                )
            } else {
                let names = |s: &Site| {
                    s.vertices
                        .iter()
                        .map(|&i| p.vertices[i].as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                };
                format!("site `{}` lists [{}], not [{}]", b.name, names(b), names(a))
            })
        } else {
            None
        };
        let Some(problem) = problem else {
            return self.same_geometry(pi, vi, span);
        };
        let (pname, vname) = (p.name.clone(), v.name.clone());
        let def = self.piece_spans[vi].name;
        self.error(
            Diagnostic::error(codes::VARIANT_SHAPE, format!("variant `{vname}` does not have the shape of `{pname}`"), span, problem)
                .with_secondary(def, format!("`{vname}` declared here"))
                .with_hint(format!("variants share `{pname}`'s vertices (same names, same order), edges and sites (names, types, vertices); only their proxy geometry may differ")),
        );
        false
    }

    /// The two-element part: element 1 docked to element 0 through `to` -> `from`.
    // Long because: the two-element part's vertices, edges and three rest states, built in order.
    fn stretch_part(
        &mut self,
        piece: &Piece,
        from: usize,
        to: usize,
        s: &syntax::StretchDecl,
    ) -> Option<StretchPart> {
        let base = &piece.states[0].positions;
        let (sf, st) = (&piece.sites[from], &piece.sites[to]);
        let n = sf.vertices.len();
        let (angle, shift) = dock_motion(site_centre(st, base), st.out, sf, base);
        let elem1: Vec<DVec2> = base.iter().map(|&p| rotate(p, angle) + shift).collect();
        for i in 0..n {
            let (a, b) = (st.vertices[n - 1 - i], sf.vertices[i]);
            let gap = base[a].distance(elem1[b]);
            if gap > DOCK_TOLERANCE {
                self.error(
                    Diagnostic::error(
                        codes::NOT_COINCIDENT,
                        format!("piece `{}` does not dock with itself from `{}` to `{}`", piece.name, sf.name, st.name),
                        Span::new(s.span.start, s.to.span.end),
                        format!("vertex `{}` of the next element misses `{}` by {} m", piece.vertices[b], piece.vertices[a], fmt(gap)),
                    )
                    .with_secondary(s.from.span, "the next element docks through this site")
                    .with_hint("the two sites must have the same shape: listed counter-clockwise, vertex i of one meets vertex n-1-i of the other"),
                );
                return None;
            }
        }
        let nv = piece.vertices.len();
        let mut vertices: Vec<ElementVertex> = (0..nv)
            .map(|v| ElementVertex {
                element: 0,
                vertex: v,
            })
            .collect();
        let mut map1 = vec![0usize; nv];
        for (v, slot) in map1.iter_mut().enumerate() {
            if let Some(i) = sf.vertices.iter().position(|&x| x == v) {
                *slot = st.vertices[n - 1 - i];
            } else {
                *slot = vertices.len();
                vertices.push(ElementVertex {
                    element: 1,
                    vertex: v,
                });
            }
        }
        let mut edges: Vec<[usize; 2]> = piece.edges.clone();
        for &[a, b] in &piece.edges {
            let e = [map1[a], map1[b]];
            if !edges
                .iter()
                .any(|&[x, y]| (x, y) == (e[0], e[1]) || (x, y) == (e[1], e[0]))
            {
                edges.push(e);
            }
        }
        let two: Vec<DVec2> = vertices
            .iter()
            .map(|ev| {
                if ev.element == 0 {
                    base[ev.vertex]
                } else {
                    elem1[ev.vertex]
                }
            })
            .collect();
        let origin = site_centre(sf, base);
        let end = site_centre(st, &elem1);
        if !(end - origin).is_finite() {
            // A coordinate that failed (reported, or a poisoned constant's use): no length
            // to measure, and nothing more to say.
            return None;
        }
        let axis = (end - origin).normalize_or_zero();
        if axis == DVec2::ZERO {
            self.error(
                Diagnostic::error(
                    codes::NOT_OPPOSITE,
                    format!(
                        "piece `{}` has no length along its stretch axis",
                        piece.name
                    ),
                    Span::new(s.span.start, s.to.span.end),
                    "from and to sites are at the same place",
                )
                .with_hint("the `from` and `to` sites must be at opposite ends of the piece"),
            );
            return None;
        }
        let states = STRETCH_STATES
            .iter()
            .map(|&(name, scale)| PartState {
                name: name.to_string(),
                positions: two
                    .iter()
                    .map(|&p| {
                        let d = p - origin;
                        let along = d.dot(axis);
                        origin + axis * (along * scale) + (d - axis * along)
                    })
                    .collect(),
            })
            .collect();
        Some(StretchPart {
            vertices,
            edges,
            states,
        })
    }

    fn site_ref(&mut self, p: &syntax::SitePath) -> Option<SiteRef> {
        let piece = self.resolve_piece(&p.piece)?;
        let site = self.resolve_site(piece, &p.site)?;
        Some(SiteRef { piece, site })
    }

    fn merge(&mut self, m: &syntax::MergeDecl) {
        let mover = self.site_ref(&m.mover);
        let target = self.site_ref(&m.target);
        let junction = m.junction.as_ref().map(|j| (self.site_ref(j), j));
        let distance = match &m.within {
            Some(n) => self
                .in_range(n, "`within`", |d| d > 0.0, "above 0")
                .map(Some),
            None => Some(None),
        };
        let (Some(mover), Some(target), Some(distance)) = (mover, target, distance) else {
            return;
        };
        let ms = self.pieces[mover.piece].sites[mover.site].clone();
        let junction = match junction {
            None => {
                let ts = self.pieces[target.piece].sites[target.site].clone();
                if !self.sites_fit(&ts, &ms, m.target.span, m.mover.span) {
                    return;
                }
                None
            }
            Some((None, _)) => return,
            Some((Some(j), jpath)) => {
                let js = self.pieces[j.piece].sites[j.site].clone();
                if !self.sites_fit(&js, &ms, jpath.span, m.mover.span) {
                    return;
                }
                // J takes over the replaced instance's connections by site name.
                let have: Vec<String> = self.pieces[j.piece]
                    .sites
                    .iter()
                    .map(|s| s.name.clone())
                    .collect();
                let missing: Vec<String> = self.pieces[target.piece]
                    .sites
                    .iter()
                    .map(|s| s.name.clone())
                    .filter(|n| !have.contains(n))
                    .map(|n| format!("`{n}`"))
                    .collect();
                if !missing.is_empty() {
                    let (jn, tn) = (
                        self.pieces[j.piece].name.clone(),
                        self.pieces[target.piece].name.clone(),
                    );
                    self.error(
                        Diagnostic::error(codes::JUNCTION_SITES, format!("junction `{jn}` lacks site {} of `{tn}`", missing.join(", ")), jpath.piece.span, format!("lacks {}", missing.join(", ")))
                            .with_secondary(self.piece_spans[j.piece].name, format!("`{jn}` declared here"))
                            .with_hint(format!("the junction replaces an instance of `{tn}` and takes over its connections by site name, so it needs every site `{tn}` has")),
                    );
                    return;
                }
                if !self.fits_in_place(target.piece, j.piece, None, jpath.piece.span) {
                    return;
                }
                Some(j)
            }
        };
        // `within` as bits, -0 as 0 (a NaN is never equal, so it is never a key).
        let key = match distance {
            Some(d) if d.is_nan() => None,
            Some(d) => Some((mover, target, Some((d + 0.0).to_bits()))),
            None => Some((mover, target, None)),
        };
        if let Some(&first) = key.as_ref().and_then(|k| self.merge_first.get(k)) {
            // The runtime takes the nearest match and, at equal distance, the earlier rule:
            // for the same two sites within the same reach that is always the first. (With
            // another `within`, the later rule still fires between the two distances.)
            self.diags.push(
                Diagnostic::warning(
                    codes::SHADOWED_MERGE,
                    format!(
                        "a merge of `{}` onto `{}` is already declared: this one never fires",
                        path_text(&m.mover),
                        path_text(&m.target)
                    ),
                    m.span,
                    "never fires",
                )
                .with_secondary(self.merge_spans[first], "this rule is tried first and always wins")
                .with_hint("keep one merge rule per pair of sites; to change what the merge puts in place, change the first rule's `into`"),
            );
        }
        if let Some(k) = key {
            self.merge_first.entry(k).or_insert(self.merge_rules.len());
        }
        self.merge_rules.push(MergeRule {
            mover,
            target,
            junction,
            within: distance,
        });
        self.merge_spans.push(m.span);
    }

    fn cut(&mut self, c: &syntax::CutDecl) {
        let junction = self.site_ref(&c.junction);
        let into = self.resolve_piece(&c.into);
        let (Some(junction), Some(into)) = (junction, into) else {
            return;
        };
        if let Some(&i) = self.cut_index.get(&junction) {
            let id = syntax::Ident {
                name: format!("{}.{}", c.junction.piece.name, c.junction.site.name),
                span: c.junction.span,
            };
            self.duplicate("cut rule for", &id, self.cut_spans[i]);
            return;
        }
        // The replacement takes over the junction's other connections by site name.
        let jp = &self.pieces[junction.piece];
        let have: Vec<&str> = self.pieces[into]
            .sites
            .iter()
            .map(|s| s.name.as_str())
            .collect();
        let missing: Vec<String> = jp
            .sites
            .iter()
            .enumerate()
            .filter(|(i, s)| *i != junction.site && !have.contains(&s.name.as_str()))
            .map(|(_, s)| format!("`{}`", s.name))
            .collect();
        if !missing.is_empty() {
            let (jn, iname) = (jp.name.clone(), self.pieces[into].name.clone());
            self.error(
                Diagnostic::error(codes::JUNCTION_SITES, format!("`{iname}` lacks site {} of junction `{jn}`", missing.join(", ")), c.into.span, format!("lacks {}", missing.join(", ")))
                    .with_secondary(self.piece_spans[into].name, format!("`{iname}` declared here"))
                    .with_hint(format!("the cut replaces `{jn}` by `{iname}`, which takes over its other connections by site name")),
            );
            return;
        }
        if !self.fits_in_place(junction.piece, into, Some(junction.site), c.into.span) {
            return;
        }
        self.cut_index.insert(junction, self.cut_rules.len());
        self.cut_rules.push(CutRule {
            junction,
            into,
            derived: false,
        });
        self.cut_spans.push(c.span);
    }
}

impl Compiler {
    /// A piece that takes another's place (a merge's junction, a cut's piece) is laid where
    /// the other was by the best rigid fit of the sites they share by name, and takes over
    /// their connections: unless those sites sit (in their rest states) as the other's do, the
    /// pieces docked to them could never rest (E044). `except`: a site of `old` not taken over
    /// (the cut one). Reports the site that sits furthest off, at `span` (where the rule
    /// names the piece).
    fn fits_in_place(&mut self, old: usize, new: usize, except: Option<usize>, span: Span) -> bool {
        let (op, np) = (&self.pieces[old], &self.pieces[new]);
        let (Some(os), Some(ns)) = (op.states.first(), np.states.first()) else {
            return true;
        };
        let mut pairs = Vec::new();
        for (k, s) in op
            .sites
            .iter()
            .enumerate()
            .filter(|(k, _)| Some(*k) != except)
        {
            let Some(t) = np.sites.iter().find(|t| t.name == s.name) else {
                continue;
            };
            if t.vertices.len() != s.vertices.len() {
                let problem = format!(
                    "site `{}` has {} vertices in `{}` and {} in `{}`",
                    s.name,
                    t.vertices.len(),
                    np.name,
                    s.vertices.len(),
                    op.name
                );
                let hint = format!(
                    "`{}` takes the place of `{}` and its connections by site name: the sites must have the same vertices",
                    np.name, op.name
                );
                self.error(
                    Diagnostic::error(
                        codes::NOT_IN_PLACE,
                        format!("`{}` does not fit where `{}` is", np.name, op.name),
                        span,
                        problem,
                    )
                    .with_hint(hint),
                );
                return false;
            }
            for (&a, &b) in s.vertices.iter().zip(&t.vertices) {
                pairs.push((k, os.positions[a], ns.positions[b]));
            }
        }
        if pairs.len() < 2 {
            return true;
        }
        let from: Vec<DVec2> = pairs.iter().map(|p| p.2).collect();
        let to: Vec<DVec2> = pairs.iter().map(|p| p.1).collect();
        let moved = rigid_fit(&from, &to);
        let Some((k, off)) = (pairs.iter().zip(&moved))
            .map(|(p, &m)| (p.0, m.distance(p.1)))
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .filter(|(_, off)| *off > DOCK_TOLERANCE)
        else {
            return true;
        };
        let (on, nn, site) = (op.name.clone(), np.name.clone(), op.sites[k].name.clone());
        self.error(
            Diagnostic::error(codes::NOT_IN_PLACE, format!("`{nn}` does not fit where `{on}` is"), span, format!("laid over `{on}` by their shared sites, its site `{site}` is {} m from where `{on}` has it", fmt(off)))
                .with_secondary(self.piece_spans[new].name, format!("`{nn}` declared here"))
                .with_hint(format!("`{nn}` takes the place of `{on}` and the connections of its sites: put those sites where `{on}` has them, relative to each other")),
        );
        false
    }

    /// A variant that names its piece's vertices, edges and sites must also put them where
    /// the piece has them (its rest state) and face its sites the same way: the chain's
    /// two-element parts are built from the rule's piece, so a variant of another shape
    /// would be held in the piece's shape, never its own (E041). Reports the first vertex or
    /// site that differs, at its declaration.
    fn same_geometry(&mut self, pi: usize, vi: usize, span: Span) -> bool {
        let (p, v) = (&self.pieces[pi], &self.pieces[vi]);
        let (Some(ps), Some(vs)) = (p.states.first(), v.states.first()) else {
            return true;
        };
        let fmt_point = |q: DVec2| format!("({}, {})", fmt(q.x), fmt(q.y));
        let moved = (ps.positions.iter().zip(&vs.positions).enumerate())
            .find(|(_, (a, b))| a.distance(**b) > DOCK_TOLERANCE);
        let (problem, at) = if let Some((k, (a, b))) = moved {
            (
                format!(
                    "vertex `{}` is at {}, where `{}` has it at {}",
                    v.vertices[k],
                    fmt_point(*b),
                    p.name,
                    fmt_point(*a)
                ),
                self.piece_spans[vi].vertices.get(k).copied(),
            )
        } else if let Some((k, (a, b))) =
            (p.sites.iter().zip(&v.sites).enumerate()).find(|(_, (a, b))| {
                a.out
                    .normalize_or_zero()
                    .distance(b.out.normalize_or_zero())
                    > 1e-6
            })
        {
            (
                format!(
                    "site `{}` faces {}, where `{}`'s faces {}",
                    b.name,
                    fmt_point(b.out.normalize_or_zero()),
                    p.name,
                    fmt_point(a.out.normalize_or_zero())
                ),
                self.piece_spans[vi].sites.get(k).copied(),
            )
        } else {
            return true;
        };
        let (pname, vname) = (p.name.clone(), v.name.clone());
        let primary = at.unwrap_or(span);
        self.error(
            Diagnostic::error(codes::VARIANT_SHAPE, format!("variant `{vname}` does not have the shape of `{pname}`"), primary, problem)
                .with_secondary(span, format!("`{vname}` is a variant of `{pname}` here"))
                .with_hint(format!("a chain is solved in `{pname}`'s shape, so its variants may differ only in proxy geometry: put the vertices where `{pname}` has them, or make `{vname}` a chain of its own")),
        );
        false
    }
}

/// `from` moved by the rigid motion that best takes it onto `to` (2D Procrustes).
fn rigid_fit(from: &[DVec2], to: &[DVec2]) -> Vec<DVec2> {
    let n = from.len().max(1) as f64;
    let (cf, ct) = (from.iter().sum::<DVec2>() / n, to.iter().sum::<DVec2>() / n);
    let (mut dot, mut cross) = (0.0, 0.0);
    for (&a, &b) in from.iter().zip(to) {
        let (p, q) = (a - cf, b - ct);
        dot += p.dot(q);
        cross += p.perp_dot(q);
    }
    let r = DVec2::new(dot, cross).normalize_or(DVec2::X);
    from.iter().map(|&a| ct + r.rotate(a - cf)).collect()
}

fn or_none(v: &[String]) -> String {
    if v.is_empty() {
        "none".into()
    } else {
        v.join(", ")
    }
}

/// `piece.site` as written.
fn path_text(p: &syntax::SitePath) -> String {
    format!("{}.{}", p.piece.name, p.site.name)
}
