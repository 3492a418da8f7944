//! The local step's rest data flattened once per assembly generation ([`RestCache`]): the
//! same results as the reference functions of [`super::local`], bit for bit, computed from
//! contiguous arrays (what the solver runs). Apart from `local.rs` because the reference is
//! the definition and this is its fast copy: the two are read, and tested against each other,
//! side by side.

use clay_dsl::compiled::Part;
use glam::DVec2;

use super::local::{
    self as local, Chosen, PartMeasure, StateSums, StretchEnds, Switching, VertexParts,
    boundary_of, choose_state, decide_stretch, normalised_or, part_rotation, switched,
    with_hysteresis,
};
use crate::fit::{distance_of, finish, rotation_of};

/// Where one part's data starts in the flat arrays of [`RestCache`]; part `i`'s data ends
/// where part `i + 1`'s starts (there is one span more than parts).
#[derive(Clone, Copy, Debug, Default)]
struct Span {
    /// Into `vertices` (one slot per vertex of the part).
    vertex: u32,
    /// Into `neighbours`.
    neighbour: u32,
    /// Into `edge_ends` (the solver's edge order).
    edge: u32,
    /// Into `shapes`.
    shape: u32,
}

/// The rest data of a part that does not depend on where the part is: its edges between
/// local vertices and its states' centred positions and rest edges. Parts with the same
/// data (the instances of one piece, the elements of one chain) share one shape, so the
/// local step streams each part's vertices and neighbours but reads the rest data of a few
/// shapes that stay in cache.
#[derive(Clone, Copy, Debug)]
struct Shape {
    /// Vertex, edge and rest-state counts.
    m: u32,
    edges: u32,
    states: u32,
    /// Into `rest`: state `j`'s centred positions at `rest + j * m`, or [`SHORT`] when a
    /// state has fewer positions than the part has vertices ([`align`](crate::fit::align)
    /// then centres the pose over a prefix of the vertices, so the part takes the reference
    /// path).
    rest: u32,
    /// Into `pp` (one per state).
    pp: u32,
    /// Into `rest_edges`: state `j`'s rest edge vectors `x0 - y0` at `rest_edges + j * edges`.
    rest_edges: u32,
    /// Into `edge_local`.
    edge_local: u32,
}

const SHORT: u32 = u32::MAX;

/// The rest data of every part, flattened once per assembly generation, so the local step
/// reads contiguous arrays instead of chasing each part's and each state's own allocations,
/// gathers and centres the pose once per part instead of once per rest state, and does not
/// recompute the rest centres and norms (they only change with the generation). Parts with
/// bit-identical rest data share it ([`Shape`]).
///
/// Every result equals the reference functions' ([`choose_state`], [`part_rotation`],
/// [`edge_rotation`](super::local::edge_rotation)) bit for bit: the same numbers are summed
/// in the same order, only computed less often. The active states are read from the parts at
/// every call, since the local step switches them; everything else must not change without a
/// generation bump.
#[derive(Clone, Debug, Default)]
pub struct RestCache {
    spans: Vec<Span>,
    shapes: Vec<Shape>,
    /// Per shape: a stretch part's ends ([`StretchEnds`]), `None` for other shapes.
    ends: Vec<Option<StretchEnds>>,
    /// Per part: its index into `boundaries` ([`SHORT`]: none; see [`boundary_of`]).
    boundary_at: Vec<u32>,
    boundaries: Vec<Boundary>,
    vertices: Vec<u32>,
    rest: Vec<DVec2>,
    /// Per shape and state: the squared norm of its centred positions.
    pp: Vec<f64>,
    rest_edges: Vec<DVec2>,
    edge_local: Vec<[u32; 2]>,
    /// Zero rest edges, as many as the largest part has edges: the targets of a part without
    /// its active state (as in the reference).
    zeros: Vec<DVec2>,
    /// Per part-edge, its ends' global vertices (the solver's `EdgeSlot::x`, `y`, compact).
    edge_ends: Vec<[u32; 2]>,
    /// Per part, `[k, j]` for every part `j` containing the part's vertex `k`: vertex by
    /// vertex, each vertex's parts in the order of [`VertexParts::of`] (so the sums run in
    /// the reference's order), one flat list per part so its loop has one trip count.
    neighbours: Vec<[u32; 2]>,
    /// Scratch sized for the largest part: its centred pose, and its vertices' rotation sums.
    pose: Vec<DVec2>,
    sums: Vec<DVec2>,
    /// Per part: the active state the last rotation step ([`RestCache::choose_state`] or
    /// [`RestCache::part_rotation`]) left it in, and how many parts that step has noted
    /// since the last [`RestCache::edge_targets`]: when all have, the edge targets need not
    /// read the parts again.
    active: Vec<usize>,
    noted: usize,
}

/// The vertices a piece part shares with other parts ([`boundary_of`]), with every state's
/// positions of them as the judgement takes them ([`local::Boundary::points`]).
#[derive(Clone, Debug)]
struct Boundary {
    judged: local::Boundary,
    /// State `j`'s points at `j * judged.local().len()`.
    rest: Vec<DVec2>,
}

impl Boundary {
    fn new(part: &Part, judged: local::Boundary) -> Self {
        let rest = (part.states.iter())
            .flat_map(|state| judged.points(|k| state.positions[k]))
            .collect();
        Self { judged, rest }
    }

    /// How many states the boundary has points of.
    fn states(&self) -> usize {
        self.rest.len() / self.judged.local().len().max(1)
    }
}

/// Converts an index into the cache's compact form (`None` when it does not fit).
fn compact(i: usize) -> Option<u32> {
    u32::try_from(i).ok().filter(|&i| i != SHORT)
}

impl RestCache {
    /// Flattens `parts`; `None` when an index would not fit the compact `u32` arrays (the
    /// solver then uses the reference functions).
    pub fn build(parts: &[Part], vertex_parts: &VertexParts) -> Option<Self> {
        let mut c = Self::default();
        // the shape of each distinct rest data, keyed by its bits
        let mut shape_of: std::collections::HashMap<Vec<u64>, u32> = Default::default();
        let mut key = Vec::new();
        let mut last = (Vec::new(), SHORT);
        let (mut most, mut most_edges) = (0, 0);
        for part in parts {
            let m = part.vertices.len();
            most = most.max(m);
            most_edges = most_edges.max(part.edges.len());
            key.clear();
            key.extend([m, part.edges.len(), part.states.len()].map(|k| k as u64));
            key.extend(part.edges.iter().flatten().map(|&k| k as u64));
            for state in &part.states {
                key.push(state.positions.len() as u64);
                key.extend(
                    state
                        .positions
                        .iter()
                        .flat_map(|p| [p.x, p.y].map(f64::to_bits)),
                );
            }
            // consecutive parts are mostly instances of one piece: compare with the last
            // part's key before hashing
            let shape = if key == last.0 {
                last.1
            } else {
                let shape = match shape_of.get(key.as_slice()) {
                    Some(&s) => s,
                    None => {
                        let s = c.push_shape(part)?;
                        shape_of.insert(key.clone(), s);
                        s
                    }
                };
                last.0.clone_from(&key);
                last.1 = shape;
                shape
            };
            c.spans.push(Span {
                vertex: compact(c.vertices.len())?,
                neighbour: compact(c.neighbours.len())?,
                edge: compact(c.edge_ends.len())?,
                shape,
            });
            for (k, &v) in part.vertices.iter().enumerate() {
                c.vertices.push(compact(v)?);
                for &j in vertex_parts.of(v) {
                    c.neighbours.push([compact(k)?, compact(j)?]);
                }
            }
            for e in &part.edges {
                let end = |k: usize| part.vertices.get(k).copied().and_then(compact);
                c.edge_ends.push([end(e[0])?, end(e[1])?]);
            }
            let dense = part
                .states
                .iter()
                .all(|st| st.positions.len() >= part.vertices.len());
            match boundary_of(part, vertex_parts).filter(|_| dense) {
                Some(judged) => {
                    c.boundary_at.push(compact(c.boundaries.len())?);
                    c.boundaries.push(Boundary::new(part, judged));
                }
                None => c.boundary_at.push(SHORT),
            }
        }
        c.spans.push(Span {
            vertex: compact(c.vertices.len())?,
            neighbour: compact(c.neighbours.len())?,
            edge: compact(c.edge_ends.len())?,
            shape: SHORT,
        });
        c.active = vec![0; parts.len()];
        c.zeros = vec![DVec2::ZERO; most_edges];
        c.pose = vec![DVec2::ZERO; most];
        c.sums = vec![DVec2::ZERO; most];
        Some(c)
    }

    /// Appends `part`'s rest data as a new shape; returns its index.
    fn push_shape(&mut self, part: &Part) -> Option<u32> {
        let m = part.vertices.len();
        let dense = m > 0 && part.states.iter().all(|s| s.positions.len() >= m);
        let shape = Shape {
            m: compact(m)?,
            edges: compact(part.edges.len())?,
            states: compact(part.states.len())?,
            rest: if dense {
                compact(self.rest.len())?
            } else {
                SHORT
            },
            pp: compact(self.pp.len())?,
            rest_edges: compact(self.rest_edges.len())?,
            edge_local: compact(self.edge_local.len())?,
        };
        for e in &part.edges {
            self.edge_local.push([compact(e[0])?, compact(e[1])?]);
        }
        for state in &part.states {
            let rest = &state.positions;
            let mut pp = 0.0;
            if dense {
                // the same expressions, in the same order, as `align`
                let inv = 1.0 / m as f64;
                let centre = rest[..m].iter().copied().sum::<DVec2>() * inv;
                for &r in &rest[..m] {
                    let p = r - centre;
                    pp += p.length_squared();
                    self.rest.push(p);
                }
            }
            self.pp.push(pp);
            for e in &part.edges {
                self.rest_edges
                    .push(match (rest.get(e[0]), rest.get(e[1])) {
                        (Some(&a), Some(&b)) => a - b,
                        _ => DVec2::ZERO,
                    });
            }
        }
        let index = compact(self.shapes.len())?;
        self.shapes.push(shape);
        let stretch = matches!(part.kind, clay_dsl::compiled::PartKind::Stretch { .. })
            && part.states.len() == 3
            && dense;
        self.ends.push(
            stretch
                .then(|| {
                    StretchEnds::find(
                        &part.states[0].positions[..m],
                        &part.states[2].positions[..m],
                    )
                })
                .flatten(),
        );
        Some(index)
    }

    /// A stretch part at `positions` ([`PartMeasure`]), its lengths measured along its
    /// chain's direction turned by `reference`; `None` for other parts.
    pub fn measure_stretch(
        &self,
        pi: usize,
        part: &Part,
        positions: &[DVec2],
        reference: DVec2,
    ) -> Option<PartMeasure> {
        let (s, _) = self.dense_span(pi, part)?;
        let ends = self.ends[s.shape as usize].as_ref()?;
        let verts = &self.vertices[s.vertex as usize..];
        let at = |k: usize| positions[verts[k] as usize];
        let centre = |ks: &[usize]| ks.iter().map(|&k| at(k)).sum::<DVec2>() / ks.len() as f64;
        let axis = reference.rotate(ends.axis);
        let spans = ends.element_spans(at);
        Some(PartMeasure {
            lengths: spans.map(|d| d.dot(axis) / ends.element),
            near: centre(&ends.near),
            far: centre(&ends.far),
            element: ends.element,
        })
    }

    /// Number of parts the cache was built for.
    pub fn parts(&self) -> usize {
        self.spans.len().saturating_sub(1)
    }

    /// Number of distinct rest data ([`Shape`]s) among the parts (tests check the sharing).
    #[cfg(test)]
    pub fn shapes(&self) -> usize {
        self.shapes.len()
    }

    /// Number of part-edges the cache was built for.
    pub fn edges(&self) -> usize {
        self.edge_ends.len()
    }

    /// The elastic energy `sum |t - (f_x - f_y)|^2` of `targets` (one per part-edge, in the
    /// solver's order) at `positions`, summed in edge order as the solver's `terms`; `None`
    /// when `targets` is not one per cached edge. (The solver sums these in
    /// `chunks::evaluate`; this is the reference its tests compare with.)
    #[cfg(test)]
    pub fn elastic(&self, targets: &[DVec2], positions: &[DVec2]) -> Option<f64> {
        if targets.len() != self.edge_ends.len() {
            return None;
        }
        let mut elastic = 0.0;
        for (&[x, y], &t) in self.edge_ends.iter().zip(targets) {
            elastic += (t - (positions[x as usize] - positions[y as usize])).length_squared();
        }
        Some(elastic)
    }

    /// Part `pi`'s span and shape, when `part` still has the vertex and state counts the
    /// cache was built with and dense rest data (else the reference path).
    fn dense_span(&self, pi: usize, part: &Part) -> Option<(Span, Shape)> {
        let s = *self.spans.get(pi)?;
        let shape = *self.shapes.get(s.shape as usize)?;
        let fits = shape.rest != SHORT
            && shape.m as usize == part.vertices.len()
            && shape.states as usize == part.states.len();
        fits.then_some((s, shape))
    }

    /// Gathers and centres the pose of the part with span `s` into `self.pose[..m]`;
    /// returns its squared norm. The same expressions, in the same order, as
    /// [`align`](crate::fit::align).
    fn gather_pose(&self, s: Span, m: usize, positions: &[DVec2], pose: &mut [DVec2]) -> f64 {
        let verts = &self.vertices[s.vertex as usize..][..m];
        let inv = 1.0 / m as f64;
        let centre = verts.iter().map(|&v| positions[v as usize]).sum::<DVec2>() * inv;
        let mut qq = 0.0;
        for (q, &v) in pose[..m].iter_mut().zip(verts) {
            *q = positions[v as usize] - centre;
            qq += q.length_squared();
        }
        qq
    }

    /// [`choose_state`] for part `pi` (which is `part`), from the cached rest data.
    pub fn choose_state(
        &mut self,
        pi: usize,
        part: &Part,
        positions: &[DVec2],
        how: Switching,
    ) -> Chosen {
        let mut pose = std::mem::take(&mut self.pose);
        let chosen = self.choose_with(pi, part, positions, how, &mut pose);
        self.pose = pose;
        // the caller makes `chosen.state` the part's active state
        self.note(pi, chosen.state);
        chosen
    }

    /// Records part `pi`'s active state; `noted` counts the parts noted in order from 0.
    fn note(&mut self, pi: usize, active: usize) {
        if pi == 0 {
            self.noted = 0;
        }
        if let Some(a) = self.active.get_mut(pi) {
            *a = active;
        }
        self.noted = if pi == self.noted { pi + 1 } else { usize::MAX };
    }

    /// [`choose_state`] for part `pi` (which is `part`), with `pose` as scratch (at least as
    /// long as the largest part).
    pub fn choose_with(
        &self,
        pi: usize,
        part: &Part,
        positions: &[DVec2],
        how: Switching,
        pose: &mut [DVec2],
    ) -> Chosen {
        let Some((s, shape)) = self.dense_span(pi, part) else {
            return choose_state(pi, part, positions, how);
        };
        let count = shape.states as usize;
        if count == 0 {
            return choose_state(pi, part, positions, how);
        }
        let hysteresis = how.hysteresis;
        let m = part.vertices.len();
        let active = part.active.min(count - 1);
        let qq = self.gather_pose(s, m, positions, pose);
        let pose = &pose[..m];
        let rest = &self.rest[shape.rest as usize..][..count * m];
        let pp = &self.pp[shape.pp as usize..][..count];
        let ctx = how.context(pi, part);
        if ctx.is_some() && self.ends[s.shape as usize].is_none() {
            // a stretch part that does not stretch straight (an arc's): the states its rule
            // can honour, judged by shape
            return choose_state(pi, part, positions, how);
        }
        if let Some(ctx) = ctx
            && let Some(ends) = &self.ends[s.shape as usize]
        {
            let mut sums = StateSums {
                qq,
                span: ends.span(|k| pose[k]),
                element: ends.element,
                axis: ends.axis,
                ..StateSums::default()
            };
            for j in 0..3 {
                (sums.dot[j], sums.cross[j]) = products(&rest[j * m..][..m], pose);
                sums.pp[j] = pp[j];
            }
            return decide_stretch(sums, active, hysteresis, ctx);
        }
        if how.shared.is_some()
            && let Some(b) = self
                .boundary_at
                .get(pi)
                .and_then(|&i| self.boundaries.get(i as usize))
            && b.states() == count
        {
            return self
                .decide_on_boundary(b, s, pose, positions, rest, pp, qq, active, hysteresis);
        }
        // One pass over the pose for all states (each state's sums still run in vertex
        // order), then the reference's comparisons on the distances.
        let (state, rotation) = match count {
            1 => decide::<1>(pose, rest, pp, qq, active, hysteresis),
            2 => decide::<2>(pose, rest, pp, qq, active, hysteresis),
            3 => decide::<3>(pose, rest, pp, qq, active, hysteresis),
            4 => decide::<4>(pose, rest, pp, qq, active, hysteresis),
            _ => {
                let align_state = |j: usize| {
                    let (dot, cross) = products(&rest[j * m..][..m], pose);
                    finish(dot, cross, pp[j], qq)
                };
                let here = align_state(active);
                let mut best = (active, here);
                for j in (0..count).filter(|&j| j != active) {
                    let a = align_state(j);
                    if a.distance < best.1.distance {
                        best = (j, a);
                    }
                }
                with_hysteresis(active, here, best, hysteresis)
            }
        };
        Chosen {
            state,
            rotation,
            claim: 0,
        }
    }

    /// [`choose_state`]'s decision for a part judged on its boundary `b` (see
    /// [`boundary_of`]): the states' distances over the boundary vertices, the chosen
    /// state's rotation over all of them (`pose`, `rest`, `pp`, `qq`: the whole part's, as
    /// [`RestCache::choose_with`] gathered them).
    #[allow(clippy::too_many_arguments)]
    fn decide_on_boundary(
        &self,
        b: &Boundary,
        s: Span,
        pose: &[DVec2],
        positions: &[DVec2],
        rest: &[DVec2],
        pp: &[f64],
        qq: f64,
        active: usize,
        hysteresis: f64,
    ) -> Chosen {
        let verts = &self.vertices[s.vertex as usize..];
        let n = b.judged.local().len();
        let at = |k: usize| positions[verts[k] as usize];
        let turn = b.judged.pose_turn(at);
        let judge = |j: usize| b.judged.distance_at(j, &b.rest[j * n..][..n], turn, at);
        let here = judge(active);
        let mut best = (active, here);
        for j in (0..b.states()).filter(|&j| j != active) {
            let d = judge(j);
            if d < best.1 {
                best = (j, d);
            }
        }
        let state = switched(active, here, best, hysteresis);
        let m = pose.len();
        let (dot, cross) = products(&rest[state * m..][..m], pose);
        Chosen {
            state,
            rotation: finish(dot, cross, pp[state], qq).rotation,
            claim: 0,
        }
    }

    /// [`RestCache::part_rotation`] for every part, in order, into `out`.
    pub fn part_rotations(&mut self, parts: &[Part], positions: &[DVec2], out: &mut Vec<DVec2>) {
        out.clear();
        for (pi, part) in parts.iter().enumerate() {
            let r = self.part_rotation(pi, part, positions);
            out.push(r);
        }
    }

    /// [`part_rotation`] for part `pi` (which is `part`), from the cached rest data.
    #[inline]
    pub fn part_rotation(&mut self, pi: usize, part: &Part, positions: &[DVec2]) -> DVec2 {
        self.note(pi, part.active);
        self.rotation_of(pi, part, positions)
    }

    /// [`part_rotation`] for part `pi` (which is `part`), from the cached rest data.
    #[inline]
    pub fn rotation_of(&self, pi: usize, part: &Part, positions: &[DVec2]) -> DVec2 {
        let Some((s, shape)) = self.dense_span(pi, part) else {
            return part_rotation(part, positions);
        };
        if part.active >= shape.states as usize {
            return part_rotation(part, positions);
        }
        let m = part.vertices.len();
        let verts = &self.vertices[s.vertex as usize..][..m];
        let rest = &self.rest[shape.rest as usize + part.active * m..][..m];
        // the same expressions, in the same order, as `align`, without storing the pose
        let inv = 1.0 / m as f64;
        let centre = verts.iter().map(|&v| positions[v as usize]).sum::<DVec2>() * inv;
        let (mut dot, mut cross, mut qq) = (0.0, 0.0, 0.0);
        for (p, &v) in rest.iter().zip(verts) {
            let q = positions[v as usize] - centre;
            dot += p.dot(q);
            cross += p.perp_dot(q);
            qq += q.length_squared();
        }
        finish(dot, cross, self.pp[shape.pp as usize + part.active], qq).rotation
    }

    /// `R_xy (x0 - y0)` for every part-edge, in the solver's edge order, into `targets`: the
    /// same as [`edge_rotation`](super::local::edge_rotation) per edge with the active
    /// state's rest edge, but each part sums its vertices' neighbour rotations once instead
    /// of once per edge end.
    ///
    /// Reads the parts' active states from the last rotation step when it noted every part
    /// (and the caller has not switched states since), else from `parts`.
    pub fn edge_targets(
        &mut self,
        parts: &[Part],
        rotations: &[DVec2],
        cos_cone: f64,
        targets: &mut Vec<DVec2>,
    ) {
        let count = parts.len().min(self.parts());
        if self.noted != parts.len() || count != parts.len() {
            for (a, part) in self.active.iter_mut().zip(parts) {
                *a = part.active;
            }
        }
        self.noted = 0;
        // every target is written below: no clearing pass over them
        targets.resize(self.spans[count].edge as usize, DVec2::ZERO);
        for pi in 0..count {
            self.part_edge_targets(pi, self.active[pi], rotations, cos_cone, targets);
        }
    }

    /// The targets of part `pi`'s edges, with its active state `active`, into `targets`.
    #[inline]
    fn part_edge_targets(
        &mut self,
        pi: usize,
        active: usize,
        rotations: &[DVec2],
        cos_cone: f64,
        targets: &mut [DVec2],
    ) {
        let mut sums = std::mem::take(&mut self.sums);
        let first = self.spans[pi].edge as usize;
        let out = &mut targets[first..][..self.part_edges(pi)];
        self.targets_with(
            pi,
            active,
            rotations[pi],
            rotations,
            cos_cone,
            out,
            &mut sums,
        );
        self.sums = sums;
    }

    /// Number of edges of part `pi`.
    #[inline]
    pub fn part_edges(&self, pi: usize) -> usize {
        self.shapes[self.spans[pi].shape as usize].edges as usize
    }

    /// Where part `pi`'s edges start in the solver's edge order.
    #[inline]
    pub fn first_edge(&self, pi: usize) -> usize {
        self.spans[pi].edge as usize
    }

    /// The targets of part `pi`'s edges (`out`, [`RestCache::part_edges`] long), with its
    /// active state `active` and rotation `own`; `rotations` (every part's) is read only
    /// within a cone (`cos_cone < 1`), and `sums` is scratch as long as the largest part.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn targets_with(
        &self,
        pi: usize,
        active: usize,
        own: DVec2,
        rotations: &[DVec2],
        cos_cone: f64,
        out: &mut [DVec2],
        sums: &mut [DVec2],
    ) {
        let (s, next) = (self.spans[pi], self.spans[pi + 1]);
        let shape = self.shapes[s.shape as usize];
        let count = shape.edges as usize;
        let edges = &self.edge_local[shape.edge_local as usize..][..count];
        // a part without its active state gets zero rest edges, as in the reference
        let rest = if active < shape.states as usize {
            &self.rest_edges[shape.rest_edges as usize + active * count..][..count]
        } else {
            &self.zeros[..count]
        };
        if cos_cone >= 1.0 {
            for (t, &d) in out.iter_mut().zip(rest) {
                *t = own.rotate(d);
            }
            return;
        }
        let m = shape.m as usize;
        let neighbours = &self.neighbours[s.neighbour as usize..next.neighbour as usize];
        // small parts sum on the stack: a fixed-size zeroing is a few stores, where the
        // slice's would be a call to memset per part
        let mut small = [DVec2::ZERO; 8];
        let sums = if m <= small.len() {
            &mut small[..m]
        } else {
            let sums = &mut sums[..m];
            sums.fill(DVec2::ZERO);
            sums
        };
        part_targets(sums, neighbours, rotations, own, cos_cone, edges, rest, out);
    }

    /// The squared residuals `|t - (f_x - f_y)|^2` of part `pi`'s edges (`targets`, its
    /// targets) at `positions`, each added to `elastic` in edge order; returns their sum
    /// (the part's stacked residual, squared).
    #[inline]
    pub fn residual_of(
        &self,
        pi: usize,
        targets: &[DVec2],
        positions: &[DVec2],
        elastic: &mut f64,
    ) -> f64 {
        let (s, next) = (self.spans[pi], self.spans[pi + 1]);
        let ends = &self.edge_ends[s.edge as usize..next.edge as usize];
        ends.iter()
            .zip(targets)
            .map(|(&[x, y], &t)| {
                let r2 = (t - (positions[x as usize] - positions[y as usize])).length_squared();
                *elastic += r2;
                r2
            })
            .sum()
    }

    /// Scratch lengths a caller of the `&self` steps needs: the largest part's vertex count.
    pub fn largest_part(&self) -> usize {
        self.pose.len()
    }
}

/// The edge targets of one part: `sums` (zeroed, one per vertex of the part) gathers the
/// rotations of the parts around each vertex within the cone of `own`, then every edge gets
/// the normalised sum of its ends' sums applied to its rest edge.
#[allow(clippy::too_many_arguments)]
#[inline]
fn part_targets(
    sums: &mut [DVec2],
    neighbours: &[[u32; 2]],
    rotations: &[DVec2],
    own: DVec2,
    cos_cone: f64,
    edges: &[[u32; 2]],
    rest: &[DVec2],
    out: &mut [DVec2],
) {
    // sums start at +0 and gain terms in the order of `vertex_rotation_sum`
    for &[k, j] in neighbours {
        let r = rotations[j as usize];
        if r.dot(own) >= cos_cone {
            sums[k as usize] += r;
        }
    }
    for ((t, e), &d) in out.iter_mut().zip(edges).zip(rest) {
        *t = normalised_or(sums[e[0] as usize] + sums[e[1] as usize], own).rotate(d);
    }
}

/// Sums of dot and cross products of centred rest positions with the centred pose, in vertex
/// order as in [`align`](crate::fit::align).
fn products(rest: &[DVec2], pose: &[DVec2]) -> (f64, f64) {
    let (mut dot, mut cross) = (0.0, 0.0);
    for (p, q) in rest.iter().zip(pose) {
        dot += p.dot(*q);
        cross += p.perp_dot(*q);
    }
    (dot, cross)
}

/// [`choose_state`]'s decision for a part with `N` dense states (`rest` holds state `j` at
/// `j * m`): the states' sums run side by side over the pose, each in vertex order, and only
/// the chosen state's rotation is computed.
#[inline]
fn decide<const N: usize>(
    pose: &[DVec2],
    rest: &[DVec2],
    pp: &[f64],
    qq: f64,
    active: usize,
    hysteresis: f64,
) -> (usize, DVec2) {
    let m = pose.len();
    let (mut dot, mut cross) = ([0.0; N], [0.0; N]);
    for (k, q) in pose.iter().enumerate() {
        for j in 0..N {
            let p = rest[j * m + k];
            dot[j] += p.dot(*q);
            cross[j] += p.perp_dot(*q);
        }
    }
    let len: [f64; N] = std::array::from_fn(|j| (dot[j] * dot[j] + cross[j] * cross[j]).sqrt());
    let distance: [f64; N] = std::array::from_fn(|j| distance_of(pp[j], qq, len[j]));
    let mut best = active;
    for j in (0..N).filter(|&j| j != active) {
        if distance[j] < distance[best] {
            best = j;
        }
    }
    let chosen = if best != active && distance[best] < (1.0 - hysteresis) * distance[active] {
        best
    } else {
        active
    };
    (chosen, rotation_of(dot[chosen], cross[chosen], len[chosen]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::local::edge_rotation;

    #[test]
    fn parts_with_the_same_rest_data_share_one_shape() {
        let square = vec![(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
        let mut bent = square.clone();
        bent[2].0 = 1.5;
        let parts = vec![
            arbitrary_part(vec![0, 1, 2, 3], vec![square.clone(), bent.clone()], 0),
            arbitrary_part(vec![4, 5, 6, 7], vec![square.clone(), bent.clone()], 1),
            // the same states in another order are other rest data
            arbitrary_part(vec![8, 9, 10, 11], vec![bent, square], 0),
        ];
        let vp = VertexParts::build(&parts, 12);
        let cache = RestCache::build(&parts, &vp).unwrap();
        assert_eq!(cache.parts(), 3);
        assert_eq!(cache.shapes(), 2);
    }

    /// A part over `vertices` (indices into `n` positions) with `states` rest states; states
    /// may be short (fewer positions than vertices) to exercise the reference fallback.
    fn arbitrary_part(vertices: Vec<usize>, states: Vec<Vec<(f64, f64)>>, active: usize) -> Part {
        let m = vertices.len();
        let edges = (0..m)
            .flat_map(|a| (a + 1..m).map(move |b| [a, b]))
            .filter(|e| (e[0] * 7 + e[1]) % 3 != 0)
            .collect();
        Part {
            kind: clay_dsl::compiled::PartKind::Piece { instance: 0 },
            vertices,
            edges,
            states: states
                .into_iter()
                .map(|p| clay_dsl::compiled::PartState {
                    name: String::new(),
                    positions: p.into_iter().map(|(x, y)| DVec2::new(x, y)).collect(),
                })
                .collect(),
            active,
        }
    }

    fn same(a: DVec2, b: DVec2) -> bool {
        a.x.to_bits() == b.x.to_bits() && a.y.to_bits() == b.y.to_bits()
    }

    fn assembly() -> impl proptest::strategy::Strategy<Value = (Vec<Part>, Vec<DVec2>, f64, f64)> {
        use proptest::prelude::*;
        let n = 12usize;
        let coordinate = -3.0..3.0f64;
        let part = (
            proptest::collection::vec(0..n, 0..11),
            proptest::collection::vec(
                proptest::collection::vec((coordinate.clone(), coordinate.clone()), 0..11),
                0..6,
            ),
            0..7usize,
            any::<bool>(),
        )
            .prop_map(|(vertices, mut states, active, full)| {
                // mostly states with one position per vertex, as grammars make them
                if full {
                    for s in &mut states {
                        s.resize(vertices.len(), (0.5, -0.25));
                    }
                }
                arbitrary_part(vertices, states, active)
            });
        (
            proptest::collection::vec(part, 1..8),
            proptest::collection::vec((coordinate.clone(), coordinate), n),
            0.0..0.5f64,
            0.0..200.0f64,
            proptest::collection::vec(any::<bool>(), 8),
        )
            .prop_map(move |(mut parts, positions, hysteresis, cone, twins)| {
                // some parts get a twin elsewhere with the same rest data (as the instances
                // of one piece have), so the cache's shared shapes are exercised
                for (i, &twin) in twins.iter().enumerate().take(parts.len()) {
                    if twin {
                        let mut copy = parts[i].clone();
                        for v in &mut copy.vertices {
                            *v = (*v + 5) % n;
                        }
                        copy.active = (copy.active + i) % 7;
                        parts.push(copy);
                    }
                }
                let positions = positions
                    .into_iter()
                    .map(|(x, y)| DVec2::new(x, y))
                    .collect();
                (parts, positions, hysteresis, cone)
            })
    }

    proptest::proptest! {
        /// The cached local step chooses the same states and gives bit-identical rotations,
        /// edge targets and energy as the straightforward `align`-based functions.
        #[test]
        fn rest_cache_matches_the_reference((parts, positions, hysteresis, cone) in assembly()) {
            let vp = VertexParts::build(&parts, positions.len());
            let mut cache = RestCache::build(&parts, &vp).unwrap();
            let cos_cone = if cone >= 180.0 { -1.0 } else { cone.to_radians().cos() };
            let mut parts = parts;
            // the switching step, then the states-fixed step, as the solver runs them
            let mut rotations = Vec::new();
            for (pi, part) in parts.iter_mut().enumerate() {
                let how = Switching::plain(hysteresis);
                let want = choose_state(pi, part, &positions, how);
                let got = cache.choose_state(pi, part, &positions, how);
                proptest::prop_assert_eq!(want.state, got.state);
                proptest::prop_assert!(same(want.rotation, got.rotation), "{:?} vs {:?}", want.rotation, got.rotation);
                part.active = got.state;
                rotations.push(got.rotation);
            }
            for round in 0..2 {
                let mut targets = Vec::new();
                cache.edge_targets(&parts, &rotations, cos_cone, &mut targets);
                let mut want = Vec::new();
                for (pi, part) in parts.iter().enumerate() {
                    let rest = part.states.get(part.active).map(|s| s.positions.as_slice());
                    for e in &part.edges {
                        let d0 = match rest.map(|r| (r.get(e[0]), r.get(e[1]))) {
                            Some((Some(&a), Some(&b))) => a - b,
                            _ => DVec2::ZERO,
                        };
                        let (x, y) = (part.vertices[e[0]], part.vertices[e[1]]);
                        let r = edge_rotation(&vp, &rotations, x, y, pi, cos_cone);
                        want.push(r.rotate(d0));
                    }
                }
                proptest::prop_assert_eq!(want.len(), targets.len());
                for (w, t) in want.iter().zip(&targets) {
                    proptest::prop_assert!(same(*w, *t), "round {}: {:?} vs {:?}", round, w, t);
                }
                let mut elastic = 0.0;
                for (part, t) in parts.iter().flat_map(|p| p.edges.iter().map(move |e| (p, e))).zip(&want) {
                    let (x, y) = (part.0.vertices[part.1[0]], part.0.vertices[part.1[1]]);
                    elastic += (*t - (positions[x] - positions[y])).length_squared();
                }
                let got = cache.elastic(&targets, &positions).unwrap();
                proptest::prop_assert_eq!(elastic.to_bits(), got.to_bits());
                // states fixed: rotations of the active states
                rotations.clear();
                for (pi, part) in parts.iter().enumerate() {
                    let want = part_rotation(part, &positions);
                    let got = cache.part_rotation(pi, part, &positions);
                    proptest::prop_assert!(same(want, got), "{:?} vs {:?}", want, got);
                    rotations.push(got);
                }
            }
        }
    }
}
