//! What a compiled grammar must hold for the code that reads it not to fail: every index in
//! range, every rest state one position per vertex, every coordinate finite and within the
//! +/-1e9 m a grammar may write (the model's within +/-1e12 m), and every setting in the settings table's range. The compiler
//! makes only such grammars; a compiled grammar read back from JSON (`clayc build`'s output, edited or damaged) is checked here before anything
//! uses it, and every problem is named.

use glam::DVec2;

use crate::compile::limits::{MAX_COORDINATE, MAX_HEIGHT};

use crate::compiled::{CompiledGrammar, Piece, ProxyShape, SiteRef};

impl CompiledGrammar {
    /// Every problem of the grammar and its model, one line each (none: it can be used).
    pub fn problems(&self) -> Vec<String> {
        let mut out = Vec::new();
        self.solver_problems(&mut out);
        let types = self.site_types.len();
        for (t, st) in self.site_types.iter().enumerate() {
            if st.docks_with.iter().any(|&d| d >= types) {
                out.push(format!(
                    "site type {t} (`{}`) docks with a type that does not exist",
                    st.name
                ));
            }
        }
        for (pi, piece) in self.pieces.iter().enumerate() {
            piece_problems(pi, piece, types, &mut out);
        }
        self.rule_problems(&mut out);
        // the model is read through the pieces: its problems are named once theirs are gone
        if out.is_empty() {
            out.extend(self.assembly.problems(self));
        }
        out
    }

    fn solver_problems(&self, out: &mut Vec<String>) {
        let s = &self.solver;
        for (name, x) in [
            ("hysteresis", s.hysteresis),
            ("norm", s.norm),
            ("irls_epsilon", s.irls_epsilon),
            ("merge_distance", s.merge_distance),
        ] {
            if let Some(setting) = crate::settings::setting(name)
                && !setting.range.allows(x)
            {
                out.push(format!(
                    "solver `{name}` is {x}: must be {}",
                    setting.range.words()
                ));
            }
        }
        for p in &self.params {
            let finite = |v: &crate::compiled::ParamValue| v.number().is_none_or(f64::is_finite);
            if !(finite(&p.value) && finite(&p.default))
                || p.range
                    .is_some_and(|r| !(r[0].is_finite() && r[1].is_finite()))
            {
                out.push(format!(
                    "parameter `{}` has a number that is not finite",
                    p.name
                ));
            }
        }
    }

    fn rule_problems(&self, out: &mut Vec<String>) {
        let site = |r: &SiteRef| {
            self.pieces
                .get(r.piece)
                .is_some_and(|p| r.site < p.sites.len())
        };
        for (ri, rule) in self.stretch_rules.iter().enumerate() {
            let pieces = std::iter::once(rule.piece).chain(rule.variants.iter().map(|v| v.piece));
            for p in pieces {
                let ok = self.pieces.get(p).is_some_and(|piece| {
                    rule.from < piece.sites.len() && rule.to < piece.sites.len()
                });
                if !ok {
                    out.push(format!(
                        "stretch rule {ri} names piece {p} or a site it does not have"
                    ));
                }
            }
            if rule
                .variants
                .iter()
                .any(|v| !(v.frequency.is_finite() && v.frequency > 0.0))
            {
                out.push(format!(
                    "stretch rule {ri} has a variant frequency that is not above 0"
                ));
            }
            if rule.min < 2 || rule.max.is_some_and(|m| m < rule.min) {
                out.push(format!(
                    "stretch rule {ri} has a `min` below 2 or a `max` below its `min`"
                ));
            }
            let n = self.pieces.get(rule.piece).map_or(0, |p| p.vertices.len());
            let part = &rule.part;
            if part
                .vertices
                .iter()
                .any(|ev| ev.element > 1 || ev.vertex >= n)
            {
                out.push(format!(
                    "stretch rule {ri}'s part names a vertex its piece does not have"
                ));
            }
            let m = part.vertices.len();
            if part.edges.iter().flatten().any(|&e| e >= m) {
                out.push(format!(
                    "stretch rule {ri}'s part has an edge to a vertex it does not have"
                ));
            }
            if part.states.len() != 3
                || part
                    .states
                    .iter()
                    .any(|s| s.positions.len() != m || !finite(&s.positions))
            {
                out.push(format!(
                    "stretch rule {ri}'s part needs three rest states of {m} finite positions"
                ));
            }
        }
        for (mi, rule) in self.merge_rules.iter().enumerate() {
            let junction = rule.junction.as_ref().is_none_or(site);
            let within = rule.within.is_none_or(|d| d.is_finite() && d >= 0.0);
            if !(site(&rule.mover) && site(&rule.target) && junction && within) {
                out.push(format!(
                    "merge rule {mi} names a piece or site that does not exist, or a bad `within`"
                ));
            }
        }
        for (ci, rule) in self.cut_rules.iter().enumerate() {
            if !site(&rule.junction) || rule.into >= self.pieces.len() {
                out.push(format!(
                    "cut rule {ci} names a piece or site that does not exist"
                ));
            }
        }
    }
}

/// A piece's problems: its edges, sites, axis, rest states and proxy geometry.
fn piece_problems(pi: usize, piece: &Piece, types: usize, out: &mut Vec<String>) {
    let name = format!("piece {pi} (`{}`)", piece.name);
    let n = piece.vertices.len();
    if n == 0 {
        out.push(format!("{name} has no vertices"));
    }
    if piece.edges.iter().flatten().any(|&v| v >= n) {
        out.push(format!("{name} has an edge to a vertex it does not have"));
    }
    for s in &piece.sites {
        if s.site_type >= types || s.vertices.iter().any(|&v| v >= n) || !s.out.is_finite() {
            out.push(format!(
                "{name}: site `{}` names a type or vertex that does not exist, or faces nowhere",
                s.name
            ));
        }
    }
    if piece
        .axis
        .is_some_and(|[a, b]| a >= piece.sites.len() || b >= piece.sites.len())
    {
        out.push(format!("{name}'s axis names a site it does not have"));
    }
    if piece.states.is_empty() {
        out.push(format!("{name} has no rest state"));
    }
    for st in &piece.states {
        if st.positions.len() != n || !finite(&st.positions) {
            out.push(format!(
                "{name}: rest state `{}` needs {n} finite positions, has {}",
                st.name,
                st.positions.len()
            ));
        }
        if st.geometry_frame >= piece.states.len() {
            out.push(format!(
                "{name}: rest state `{}` draws with a state that does not exist",
                st.name
            ));
        }
        for g in &st.geometry {
            let ok = match &g.shape {
                ProxyShape::Polygon { outer, holes } => {
                    finite(outer) && holes.iter().all(|h| finite(h))
                }
                ProxyShape::Polyline { points, width } => {
                    finite(points) && *width > 0.0 && *width <= MAX_COORDINATE
                }
                ProxyShape::Mesh {
                    points,
                    heights,
                    triangles,
                } => {
                    finite(points)
                        && heights.len() == points.len()
                        && heights.iter().all(|h| h.abs() <= MAX_COORDINATE)
                        && triangles
                            .iter()
                            .flatten()
                            .all(|&k| (k as usize) < points.len())
                }
            };
            // the compiler's bounds (E013): 0 < height <= 10000, |base| <= 10000
            let extrude = g.extrude.is_none_or(|e| {
                e.height > 0.0 && e.height <= MAX_HEIGHT && e.base.abs() <= MAX_HEIGHT
            });
            if !(ok && extrude) {
                out.push(format!(
                    "{name}: rest state `{}` has proxy geometry with a coordinate beyond +/-{MAX_COORDINATE} m, a height beyond {MAX_HEIGHT} m, a number that is not finite or an index out of range",
                    st.name
                ));
            }
        }
    }
}

/// Finite and within the coordinates a grammar may write (`MAX_COORDINATE`, E013): no later
/// computation can overflow.
fn finite(points: &[DVec2]) -> bool {
    points
        .iter()
        .all(|p| p.is_finite() && p.abs().max_element() <= MAX_COORDINATE)
}
