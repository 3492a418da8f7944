//! Derived rest states (docs/language.md, "Derived rest states"): `state NAME bend ANGLE` lays
//! the piece's axis on a circular arc of the same length, `state NAME mirror OTHER` reflects
//! another state across the axis line. The geometric maps come first (plain functions of the
//! axis line); the compiler's part, resolving names and reporting, is at the end.
//!
//! Coordinates along the axis: a point p has the arc-length coordinate s = (p - O).a and the
//! signed offset d = (p - O).n, where O is the centre of the axis's `from` site, a the unit
//! vector towards the `to` site's centre and n = a turned 90 degrees counter-clockwise (the
//! left of the axis). The axis is the stretch 0 <= s <= L, L the distance between the centres.

use glam::DVec2;

use crate::compiled::*;
use crate::diagnostic::Diagnostic;
use crate::syntax::{self, DeriveKind};

use super::codes;
use super::limits::COINCIDENT_EPS;
use super::state::{Compiler, PieceSpans, fmt};

/// Largest turn, in degrees, of one straight segment of bent proxy geometry: a polygon or
/// polyline edge alongside the axis is cut into pieces that each turn by at most this much (16
/// per quarter turn), so bent geometry follows the arc between the end sites, not only its ends.
pub const MAX_ARC_STEP_DEGREES: f64 = 5.625;

/// How close (metres) a vertex's reflection must come to another vertex to be its mirror image.
pub const MIRROR_TOLERANCE: f64 = 1e-6;

/// Largest bend, in degrees, either way: one full turn.
pub const MAX_BEND_DEGREES: f64 = 360.0;

/// The axis line of a piece in its base state: from the `from` site's centre towards the `to`
/// site's centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct AxisLine {
    pub origin: DVec2,
    /// Unit vector along the axis.
    pub dir: DVec2,
    pub length: f64,
}

impl AxisLine {
    /// `None` when a centre is not finite or the two centres (nearly) coincide.
    pub fn new(from: DVec2, to: DVec2) -> Option<Self> {
        let v = to - from;
        let length = v.length();
        (from.is_finite() && to.is_finite() && length.is_finite() && length >= COINCIDENT_EPS).then(
            || Self {
                origin: from,
                dir: v / length,
                length,
            },
        )
    }

    /// `(s, d)`: arc length along the axis and signed offset to its left.
    pub fn local(&self, p: DVec2) -> DVec2 {
        let q = p - self.origin;
        DVec2::new(q.dot(self.dir), q.dot(self.dir.perp()))
    }

    pub fn global(&self, l: DVec2) -> DVec2 {
        self.origin + self.dir * l.x + self.dir.perp() * l.y
    }

    /// The reflection of `p` across the axis line.
    pub fn mirror(&self, p: DVec2) -> DVec2 {
        let l = self.local(p);
        self.global(DVec2::new(l.x, -l.y))
    }
}

/// `sin(x) / x`, exact near 0.
fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-6 {
        1.0 - x * x / 6.0
    } else {
        x.sin() / x
    }
}

/// `(1 - cos(x)) / x`, exact near 0.
fn versinc(x: f64) -> f64 {
    if x.abs() < 1e-6 {
        x / 2.0 - x * x * x / 24.0
    } else {
        let h = (x / 2.0).sin();
        2.0 * h * h / x
    }
}

/// The bend map: the axis stretch 0 <= s <= L goes onto a circular arc of length L that starts
/// at O along a and turns by `angle` (counter-clockwise when positive); a point at (s, d) goes
/// to the arc point at arc length s, moved d along the arc's left normal there. Points before
/// the axis (s < 0) stay where they are (they extend the arc's start tangent), points past it
/// (s > L) extend its end tangent: they move rigidly with the `to` end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Bend {
    pub axis: AxisLine,
    /// Turn in radians.
    pub angle: f64,
    /// Turn per metre of axis (1 / signed radius).
    pub curvature: f64,
}

impl Bend {
    pub fn new(axis: AxisLine, degrees: f64) -> Self {
        let angle = degrees.to_radians();
        Self {
            axis,
            angle,
            curvature: angle / axis.length,
        }
    }

    /// The arc's radius (infinite for no bend).
    pub fn radius(&self) -> f64 {
        1.0 / self.curvature.abs()
    }

    pub fn apply(&self, p: DVec2) -> DVec2 {
        if self.angle == 0.0 {
            return p;
        }
        let l = self.axis.local(p);
        let (s, beyond) = if l.x < 0.0 {
            (0.0, l.x)
        } else if l.x > self.axis.length {
            (self.axis.length, l.x - self.axis.length)
        } else {
            (l.x, 0.0)
        };
        let phi = self.curvature * s;
        let arc = DVec2::new(s * sinc(phi), s * versinc(phi));
        let tangent = DVec2::new(phi.cos(), phi.sin());
        self.axis
            .global(arc + tangent * beyond + tangent.perp() * l.y)
    }

    /// Whether `p` lies alongside the axis at or past the arc's centre on the inside of the
    /// bend, where the map would fold the piece onto itself. Returns `p`'s offset then.
    pub fn folds(&self, p: DVec2) -> Option<f64> {
        let l = self.axis.local(p);
        let alongside = (0.0..=self.axis.length).contains(&l.x);
        (alongside && self.curvature * l.y >= 1.0 - 1e-9).then_some(l.y.abs())
    }

    /// The path through `points` (closed back to the first when `closed`) with every segment
    /// cut where it enters or leaves the axis stretch and into pieces turning by at most
    /// [`MAX_ARC_STEP_DEGREES`]; in the base state's coordinates, not yet bent.
    pub fn subdivide(&self, points: &[DVec2], closed: bool) -> Vec<DVec2> {
        let Some(&first) = points.first() else {
            return Vec::new();
        };
        if self.curvature == 0.0 {
            return points.to_vec(); // no turn: nothing to follow
        }
        let step = MAX_ARC_STEP_DEGREES.to_radians();
        let len = self.axis.length;
        let mut out = vec![first];
        let segments = points.len() - 1 + usize::from(closed && points.len() > 2);
        for k in 0..segments {
            let (a, b) = (points[k], points[(k + 1) % points.len()]);
            let (sa, sb) = (self.axis.local(a).x, self.axis.local(b).x);
            // Cut where the segment crosses the ends of the axis stretch.
            let mut cuts = vec![0.0];
            for edge in [0.0, len] {
                let t = (edge - sa) / (sb - sa);
                if t > 0.0 && t < 1.0 {
                    cuts.push(t);
                }
            }
            cuts.push(1.0);
            cuts.sort_by(f64::total_cmp);
            for w in cuts.windows(2) {
                let s = |t: f64| (sa + (sb - sa) * t).clamp(0.0, len);
                let turn = (self.curvature * (s(w[1]) - s(w[0]))).abs();
                // The slack keeps an exact quarter turn at 16 pieces despite rounding.
                let pieces = (turn / step - 1e-9).ceil().clamp(1.0, 1e6) as usize;
                for i in 1..=pieces {
                    let t = w[0] + (w[1] - w[0]) * i as f64 / pieces as f64;
                    out.push(a + (b - a) * t);
                }
            }
        }
        if closed && points.len() > 2 {
            out.pop(); // the closing segment ends on the first point
        }
        out
    }
}

/// Every ring and polyline of a proxy, transformed by `f(points, closed)`.
///
/// A mesh's vertices are mapped one by one (bend cuts no triangle); when `reflects`, its
/// triangles are turned round so that they still face out of the solid.
fn map_proxy(p: &Proxy, f: &impl Fn(&[DVec2], bool) -> Vec<DVec2>, reflects: bool) -> Proxy {
    let shape = match &p.shape {
        ProxyShape::Mesh {
            points,
            heights,
            triangles,
        } => ProxyShape::Mesh {
            points: points
                .iter()
                .map(|&q| f(&[q], false).first().copied().unwrap_or(q))
                .collect(),
            heights: heights.clone(),
            triangles: if reflects {
                triangles.iter().map(|&[a, b, c]| [a, c, b]).collect()
            } else {
                triangles.clone()
            },
        },
        ProxyShape::Polygon { outer, holes } => ProxyShape::Polygon {
            outer: f(outer, true),
            holes: holes.iter().map(|h| f(h, true)).collect(),
        },
        ProxyShape::Polyline { points, width } => ProxyShape::Polyline {
            points: f(points, false),
            width: *width,
        },
    };
    Proxy {
        shape,
        fill: p.fill,
        binding: p.binding,
        extrude: p.extrude,
    }
}

/// Proxy geometry bent along the arc, its straight segments cut to follow it.
pub(crate) fn bend_geometry(bend: &Bend, geometry: &[Proxy]) -> Vec<Proxy> {
    let f = |pts: &[DVec2], closed: bool| -> Vec<DVec2> {
        bend.subdivide(pts, closed)
            .into_iter()
            .map(|p| bend.apply(p))
            .collect()
    };
    geometry.iter().map(|p| map_proxy(p, &f, false)).collect()
}

/// Proxy geometry reflected across the axis line. A reflection turns every ring the other way
/// round, so rings are also reversed: a counter-clockwise outline stays counter-clockwise.
pub(crate) fn mirror_geometry(axis: &AxisLine, geometry: &[Proxy]) -> Vec<Proxy> {
    let f = |pts: &[DVec2], closed: bool| -> Vec<DVec2> {
        let mut m: Vec<DVec2> = pts.iter().map(|&p| axis.mirror(p)).collect();
        if closed {
            m.reverse();
        }
        m
    };
    geometry.iter().map(|p| map_proxy(p, &f, true)).collect()
}

/// The axis of a piece as far as derived states need it, resolved without reporting (the
/// piece's own `axis` check reports its errors).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum AxisState {
    /// The piece declares no `axis`.
    Missing,
    /// The `axis` statement has an error of its own (already reported).
    Failed,
    /// The two sites' centres coincide in the base state.
    Degenerate,
    Line(AxisLine),
}

impl AxisState {
    pub fn resolve(piece: &Piece, axis: Option<&syntax::AxisDecl>, base: &[DVec2]) -> Self {
        let Some(a) = axis else {
            return Self::Missing;
        };
        let site = |name: &str| piece.sites.iter().position(|s| s.name == name);
        let (Some(f), Some(t)) = (site(&a.from.name), site(&a.to.name)) else {
            return Self::Failed;
        };
        if f == t || piece.sites[f].out.dot(piece.sites[t].out) >= -0.5 {
            return Self::Failed;
        }
        let centre = |s: usize| {
            let vs = &piece.sites[s].vertices;
            vs.iter()
                .filter_map(|&v| base.get(v).copied())
                .sum::<DVec2>()
                / vs.len().max(1) as f64
        };
        let (c0, c1) = (centre(f), centre(t));
        if !(c0.is_finite() && c1.is_finite()) {
            return Self::Failed;
        }
        AxisLine::new(c0, c1).map_or(Self::Degenerate, Self::Line)
    }
}

/// How a compiled rest state was made, which decides how `mirror` treats it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Made {
    /// Positions written out (or `base`, or the mirror of such a state).
    Listed,
    /// A bend by `degrees` of the base state (also a mirror of one); `own_geometry` when its
    /// geometry was written (or reflected from written geometry) rather than bent.
    Bend { degrees: f64, own_geometry: bool },
    /// Reported with an error: a mirror of it stays silent.
    Failed,
}

/// What a derived state needs of its piece besides the piece itself.
pub(crate) struct DeriveContext<'a> {
    pub decl: &'a syntax::PieceDecl,
    pub spans: &'a PieceSpans,
    pub axis: AxisState,
    pub base_geometry: &'a [Proxy],
    /// How each state of `piece.states` so far was made.
    pub made: &'a [Made],
}

impl Compiler {
    /// Compiles `state NAME bend ANGLE` / `state NAME mirror OTHER` as state number `index`.
    /// A state with an error gets the base positions (the grammar is not produced anyway).
    pub(super) fn derived_state(
        &mut self,
        piece: &Piece,
        cx: &DeriveContext,
        st: &syntax::StateDecl,
        d: &syntax::StateDerive,
        index: usize,
    ) -> (RestState, Made) {
        let base = &piece.states[0].positions;
        let failed = RestState {
            name: st.name.name.clone(),
            positions: base.clone(),
            geometry: Vec::new(),
            geometry_frame: index,
        };
        let errors_before = self.diags.error_count();
        let made = match &d.kind {
            DeriveKind::Bend(n) => {
                let angle = self.in_range(
                    n,
                    "the bend angle",
                    |a| a.abs() <= MAX_BEND_DEGREES,
                    "between -360 and 360 degrees",
                );
                let axis = self.derive_axis(piece, cx, d);
                match (angle, axis) {
                    (Some(degrees), Some(_)) => Made::Bend {
                        degrees,
                        own_geometry: false,
                    },
                    _ => Made::Failed,
                }
            }
            DeriveKind::Mirror(other) => {
                let j = self.mirrored_state(piece, cx, st, other);
                let axis = self.derive_axis(piece, cx, d);
                match (j, axis) {
                    (Some(j), Some(_)) => match cx.made[j] {
                        Made::Bend {
                            degrees,
                            own_geometry,
                        } => Made::Bend {
                            degrees: -degrees,
                            own_geometry,
                        },
                        other => other,
                    },
                    _ => Made::Failed,
                }
            }
        };
        let AxisState::Line(axis) = cx.axis else {
            return (failed, Made::Failed);
        };
        let body: Vec<Proxy> = st.geometry.iter().flat_map(|g| self.geometry(g)).collect();
        let own_body = !st.geometry.is_empty();
        let (state, made) = match made {
            Made::Failed => return (failed, Made::Failed),
            Made::Bend {
                degrees,
                own_geometry,
            } => {
                let bend = Bend::new(axis, degrees);
                let positions: Vec<DVec2> = base.iter().map(|&p| bend.apply(p)).collect();
                let bent_geometry = !(own_body || own_geometry);
                self.check_fold(piece, cx, st, d, &bend, bent_geometry);
                let geometry = match (&d.kind, own_body) {
                    (_, true) => body,
                    // The mirror of a state whose geometry was written: reflect that geometry.
                    (DeriveKind::Mirror(other), false) if own_geometry => {
                        let j = piece.states.iter().position(|s| s.name == other.name);
                        mirror_geometry(&axis, &piece.states[j.unwrap_or(0)].geometry)
                    }
                    _ => bend_geometry(&bend, cx.base_geometry),
                };
                let state = RestState {
                    name: st.name.name.clone(),
                    positions,
                    geometry,
                    geometry_frame: index,
                };
                let made = Made::Bend {
                    degrees,
                    own_geometry: own_body || own_geometry,
                };
                (state, made)
            }
            Made::Listed => {
                let DeriveKind::Mirror(other) = &d.kind else {
                    unreachable!("a bend is never listed")
                };
                let j = piece.states.iter().position(|s| s.name == other.name);
                let of = &piece.states[j.unwrap_or(0)];
                match self.mirror_listed(piece, cx, st, d, &axis, of, index) {
                    Some(mut state) => {
                        if own_body {
                            state.geometry = body;
                            state.geometry_frame = index;
                        }
                        (state, Made::Listed)
                    }
                    None => return (failed, Made::Failed),
                }
            }
        };
        if self.diags.error_count() != errors_before {
            return (failed, Made::Failed);
        }
        let vspans = vec![d.span; piece.vertices.len()];
        self.check_state_geometry(
            piece,
            &st.name.name,
            &state.positions,
            &vspans,
            d.span,
            &cx.spans.edges,
        );
        (state, made)
    }

    /// The axis a derived state needs; E055 when the piece has none (silent when the `axis`
    /// statement failed on its own).
    fn derive_axis(
        &mut self,
        piece: &Piece,
        cx: &DeriveContext,
        d: &syntax::StateDerive,
    ) -> Option<AxisLine> {
        let what = match d.kind {
            DeriveKind::Bend(_) => "bent",
            DeriveKind::Mirror(_) => "mirrored",
        };
        let message = match cx.axis {
            AxisState::Line(line) => return Some(line),
            AxisState::Failed => return None,
            AxisState::Missing => format!("piece `{}` has no axis to be {what} about", piece.name),
            AxisState::Degenerate => format!(
                "the axis of piece `{}` has no length: its two sites' centres coincide",
                piece.name
            ),
        };
        let sites = &piece.sites;
        let pair = (0..sites.len())
            .flat_map(|i| (i + 1..sites.len()).map(move |j| (i, j)))
            .find(|&(i, j)| sites[i].out.dot(sites[j].out) < -0.5);
        let hint = match (cx.axis, pair) {
            (AxisState::Missing, Some((i, j))) => format!(
                "declare the axis in the piece, e.g. `axis {} -> {}`: a derived state bends or \
                 mirrors the piece about the line between the centres of its two axis sites",
                sites[i].name, sites[j].name
            ),
            (AxisState::Missing, None) => "declare `axis A -> B` with two opposite sites of the \
                 piece: a derived state bends or mirrors the piece about the line between their \
                 centres"
                .to_string(),
            _ => "choose axis sites whose centres are apart, or list the state's positions"
                .to_string(),
        };
        self.error(
            Diagnostic::error(
                codes::DERIVE_NO_AXIS,
                message,
                d.keyword,
                "needs the piece's axis",
            )
            .with_secondary(cx.spans.name, "piece declared here")
            .with_hint(hint),
        );
        None
    }

    /// The index of the state a `mirror` names; E057 for itself or a later state, E011 for an
    /// unknown one.
    fn mirrored_state(
        &mut self,
        piece: &Piece,
        cx: &DeriveContext,
        st: &syntax::StateDecl,
        other: &syntax::Ident,
    ) -> Option<usize> {
        if let Some(j) = piece.states.iter().position(|s| s.name == other.name) {
            return Some(j);
        }
        let declared: Vec<&syntax::StateDecl> = cx
            .decl
            .stmts
            .iter()
            .filter_map(|s| match s {
                syntax::PieceStmt::State(s) => Some(s),
                _ => None,
            })
            .collect();
        if other.name == st.name.name {
            self.error(
                Diagnostic::error(
                    codes::MIRROR_ORDER,
                    format!("state `{}` is the mirror of itself", st.name.name),
                    other.span,
                    "the state being declared",
                )
                .with_hint(
                    "a mirror reflects an earlier state (or `base`) across the axis, e.g. \
                     `state right mirror left` after `state left bend 90`",
                ),
            );
            return None;
        }
        let later = declared
            .iter()
            .find(|s| s.name.name == other.name && s.span.start > st.span.start);
        if let Some(later) = later {
            self.error(
                Diagnostic::error(
                    codes::MIRROR_ORDER,
                    format!(
                        "state `{}` mirrors `{}`, which is declared after it",
                        st.name.name, other.name
                    ),
                    other.span,
                    "declared later",
                )
                .with_secondary(
                    later.name.span,
                    format!("`{}` is declared here", other.name),
                )
                .with_hint(format!(
                    "declare `{}` before `{}`: a mirror refers to an earlier state (or `base`), \
                     so mirrors never go round in a circle",
                    other.name, st.name.name
                )),
            );
            return None;
        }
        // A state that was declared but failed (a duplicate, `base`) is already reported.
        if declared.iter().any(|s| s.name.name == other.name) {
            return None;
        }
        let names: Vec<&str> = piece.states.iter().map(|s| s.name.as_str()).collect();
        self.unknown(
            "state",
            other,
            names,
            Some(format!("in piece `{}`", piece.name)),
        );
        None
    }

    /// E056 when the bend folds a vertex or a point of the bent proxy geometry.
    fn check_fold(
        &mut self,
        piece: &Piece,
        cx: &DeriveContext,
        st: &syntax::StateDecl,
        d: &syntax::StateDerive,
        bend: &Bend,
        geometry: bool,
    ) {
        let base = &piece.states[0].positions;
        let vertex = base.iter().enumerate().find_map(|(i, &p)| {
            bend.folds(p).map(|off| {
                (
                    format!(
                        "vertex `{}` is {} m from the axis",
                        piece.vertices[i],
                        fmt(off)
                    ),
                    cx.spans.vertices.get(i).copied(),
                )
            })
        });
        let point = || {
            if !geometry {
                return None;
            }
            let f = |pts: &[DVec2], closed: bool| bend.subdivide(pts, closed);
            cx.base_geometry
                .iter()
                .map(|p| map_proxy(p, &f, false))
                .flat_map(|p| match p.shape {
                    ProxyShape::Polygon { outer, holes } => outer
                        .into_iter()
                        .chain(holes.into_iter().flatten())
                        .collect(),
                    ProxyShape::Polyline { points, .. } | ProxyShape::Mesh { points, .. } => points,
                })
                .find_map(|p| {
                    bend.folds(p).map(|off| {
                        (
                            format!(
                                "the proxy point ({}, {}) is {} m from the axis",
                                fmt(p.x),
                                fmt(p.y),
                                fmt(off)
                            ),
                            None,
                        )
                    })
                })
        };
        let Some((what, at)) = vertex.or_else(point) else {
            return;
        };
        let degrees = bend.angle.to_degrees();
        let side = if degrees > 0.0 { "left" } else { "right" };
        let mut diag = Diagnostic::error(
            codes::BEND_FOLDS,
            format!(
                "state `{}` bends piece `{}` by {} degrees, which folds it onto itself",
                st.name.name,
                piece.name,
                fmt(degrees)
            ),
            d.span,
            format!(
                "the arc's radius is {} m and {what}, on the inside ({side}) of the bend",
                fmt(bend.radius())
            ),
        );
        if let Some(at) = at {
            diag = diag.with_secondary(at, "this vertex");
        }
        self.error(diag.with_hint(format!(
            "a bend's radius is the axis length over the angle in radians ({} m / {} rad here); \
             everything alongside the axis must be closer to the axis than that on the inside \
             of the bend: bend by less",
            fmt(bend.axis.length),
            fmt(bend.angle.abs())
        )));
    }

    /// The mirror of a state that lists positions: vertex v goes to the reflection of where
    /// `of` puts v's mirror image (E058 when some vertex has none); its geometry is `of`'s,
    /// reflected.
    #[allow(clippy::too_many_arguments)]
    fn mirror_listed(
        &mut self,
        piece: &Piece,
        cx: &DeriveContext,
        st: &syntax::StateDecl,
        d: &syntax::StateDerive,
        axis: &AxisLine,
        of: &RestState,
        index: usize,
    ) -> Option<RestState> {
        let base = &piece.states[0].positions;
        // Vertices sorted by x, so finding each image is a binary search, not a scan.
        let mut by_x: Vec<usize> = (0..base.len()).collect();
        by_x.sort_by(|&i, &j| base[i].x.total_cmp(&base[j].x));
        let image_of = |image: DVec2| {
            let from = by_x.partition_point(|&i| base[i].x < image.x - MIRROR_TOLERANCE);
            by_x[from..]
                .iter()
                .take_while(|&&i| base[i].x <= image.x + MIRROR_TOLERANCE)
                .copied()
                .find(|&i| base[i].distance(image) <= MIRROR_TOLERANCE)
        };
        let mut partner = Vec::with_capacity(base.len());
        for (v, &p) in base.iter().enumerate() {
            let image = axis.mirror(p);
            match image_of(image) {
                Some(w) => partner.push(w),
                None => {
                    let mut diag = Diagnostic::error(
                        codes::NOT_SYMMETRIC,
                        format!(
                            "state `{}` mirrors `{}`, which lists its positions, but piece `{}` \
                             is not symmetric about its axis",
                            st.name.name, of.name, piece.name
                        ),
                        d.span,
                        format!("vertex `{}` has no mirror image", piece.vertices[v]),
                    );
                    if let Some(&at) = cx.spans.vertices.get(v) {
                        diag = diag.with_secondary(
                            at,
                            format!(
                                "`{}` is at ({}, {}); its reflection ({}, {}) is no vertex",
                                piece.vertices[v],
                                fmt(p.x),
                                fmt(p.y),
                                fmt(image.x),
                                fmt(image.y)
                            ),
                        );
                    }
                    self.error(diag.with_hint(
                        "mirroring a listed state swaps each vertex with its mirror image, so \
                         every vertex needs one; write the state as a `bend` (whose mirror works \
                         for any piece) or list the mirrored positions",
                    ));
                    return None;
                }
            }
        }
        let positions = partner
            .iter()
            .map(|&w| axis.mirror(of.positions[w]))
            .collect();
        let own = of.geometry_frame == piece.states.iter().position(|s| s.name == of.name)?;
        Some(RestState {
            name: st.name.name.clone(),
            positions,
            geometry: mirror_geometry(axis, &of.geometry),
            geometry_frame: if own { index } else { of.geometry_frame },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn road_axis() -> AxisLine {
        AxisLine::new(DVec2::ZERO, DVec2::new(2.0, 0.0)).unwrap()
    }

    #[test]
    fn a_quarter_bend_of_a_2_m_axis_ends_a_quarter_turn_round() {
        let b = Bend::new(road_axis(), 90.0);
        let r = 2.0 / std::f64::consts::FRAC_PI_2;
        assert!((b.radius() - r).abs() < 1e-12);
        let end = b.apply(DVec2::new(2.0, 0.0));
        assert!(end.distance(DVec2::new(r, r)) < 1e-12, "{end}");
        // Offsets keep their length along the normal: the south rail ends r + 0.5 east.
        let s2 = b.apply(DVec2::new(2.0, -0.5));
        assert!(s2.distance(DVec2::new(r + 0.5, r)) < 1e-12, "{s2}");
        // Beyond the end: along the end tangent (north).
        let past = b.apply(DVec2::new(3.0, 0.0));
        assert!(past.distance(DVec2::new(r, r + 1.0)) < 1e-12, "{past}");
        // Before the start: unchanged.
        assert_eq!(b.apply(DVec2::new(-1.0, 0.3)), DVec2::new(-1.0, 0.3));
    }

    #[test]
    fn no_bend_is_the_identity_and_a_tiny_one_is_finite() {
        let p = DVec2::new(1.3, -0.4);
        assert_eq!(Bend::new(road_axis(), 0.0).apply(p), p);
        let q = Bend::new(road_axis(), 1e-300).apply(p);
        assert!(q.is_finite() && q.distance(p) < 1e-12);
    }

    #[test]
    fn bending_keeps_arc_length_and_offset() {
        let b = Bend::new(road_axis(), 73.0);
        let pts: Vec<DVec2> = (0..=200)
            .map(|i| b.apply(DVec2::new(i as f64 / 100.0, 0.3)))
            .collect();
        let len: f64 = pts.windows(2).map(|w| w[0].distance(w[1])).sum();
        let expected = 2.0 * (1.0 - 0.3 * b.curvature);
        assert!((len - expected).abs() < 1e-4, "{len} vs {expected}");
    }

    #[test]
    fn segments_along_a_quarter_turn_are_cut_in_16() {
        let b = Bend::new(road_axis(), 90.0);
        let line = b.subdivide(&[DVec2::new(0.0, 0.4), DVec2::new(2.0, 0.4)], false);
        assert_eq!(line.len(), 17);
        let square = [
            DVec2::new(0.0, -0.5),
            DVec2::new(2.0, -0.5),
            DVec2::new(2.0, 0.5),
            DVec2::new(0.0, 0.5),
        ];
        // Two long sides of 16 pieces, two rungs of one: 34 corners.
        assert_eq!(b.subdivide(&square, true).len(), 34);
        // A segment running past both ends is cut at them; the parts outside stay straight.
        let long = b.subdivide(&[DVec2::new(-1.0, 0.0), DVec2::new(3.0, 0.0)], false);
        assert_eq!(long.len(), 1 + 1 + 16 + 1);
        assert!(long.contains(&DVec2::ZERO) && long.contains(&DVec2::new(2.0, 0.0)));
    }

    #[test]
    fn mirrored_rings_keep_their_orientation() {
        let area = |r: &[DVec2]| -> f64 {
            (0..r.len())
                .map(|i| r[i].perp_dot(r[(i + 1) % r.len()]))
                .sum::<f64>()
        };
        let ring = vec![
            DVec2::new(0.0, 0.1),
            DVec2::new(2.0, 0.1),
            DVec2::new(2.0, 0.5),
        ];
        let proxy = Proxy {
            shape: ProxyShape::Polygon {
                outer: ring.clone(),
                holes: vec![],
            },
            fill: Rgba([0; 4]),
            binding: Binding::Skinned,
            extrude: None,
        };
        let m = mirror_geometry(&road_axis(), &[proxy]);
        let ProxyShape::Polygon { outer, .. } = &m[0].shape else {
            panic!()
        };
        assert!(area(&ring) > 0.0 && area(outer) > 0.0);
        assert!(outer.iter().all(|p| p.y < 0.0));
    }

    #[test]
    fn folding_is_on_the_inside_only() {
        let b = Bend::new(road_axis(), 300.0); // radius 0.38 m
        assert!(b.folds(DVec2::new(1.0, 0.5)).is_some());
        assert!(b.folds(DVec2::new(1.0, -0.5)).is_none());
        assert!(b.folds(DVec2::new(-1.0, 0.5)).is_none());
        assert!(
            Bend::new(road_axis(), -300.0)
                .folds(DVec2::new(1.0, -0.5))
                .is_some()
        );
    }
}
