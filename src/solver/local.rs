//! The local step (paper 4.1-4.3): for each part and each of its rest states, the optimal 2D
//! rotation onto the current pose and the shape distance, the choice of the active rest state
//! with hysteresis, and the per-edge rotations `R_xy` averaged over the parts touching an edge.
//! The free functions are the plain reference; [`RestCache`](super::rest_cache::RestCache)
//! (`rest_cache.rs`) gives the same results, bit for bit, from rest data flattened once per
//! assembly generation (what the solver runs).

use clay_dsl::compiled::Part;
use glam::DVec2;

use crate::fit::{Alignment, align, rotation_of};

/// What the local step knows of a stretch part besides its rest states (paper 5.1): the
/// direction its chain ran in when the frame started, and which of its states the stretch
/// rule can honour now.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StretchContext {
    /// The part's rotation in the pose the frame started from (the displayed one): the
    /// direction along which its length is measured. The pass-1 pose may fold a squeezed
    /// part onto itself, and the best rotation of a folded part turns it round, so a squeeze
    /// would read as a stretch.
    pub reference: DVec2,
    /// Bit `j` set: state `j` may become active. A state the rule cannot apply (`one` at the
    /// chain's `min` or between two held elements, `three` at its `max`) is unavailable
    /// rather than chosen: a part left in it would hold a shape its chain never gets.
    pub allowed: u8,
}

impl StretchContext {
    fn allows(&self, state: usize) -> bool {
        state < 8 && self.allowed & (1 << state) != 0
    }
}

/// How a switching local step decides (paper 4.3, 5.1).
#[derive(Clone, Copy, Debug)]
pub struct Switching<'a> {
    /// A part switches to a nearer state only when it is closer by this fraction.
    pub hysteresis: f64,
    /// Per part, in part order: the stretch parts' contexts (`None` for other parts; an
    /// empty slice decides every part by its distances alone).
    pub stretch: &'a [Option<StretchContext>],
    /// The parts around every vertex: with it, a piece part's rest state is judged by the
    /// vertices it shares with other parts ([`boundary_of`]); without, by all its vertices.
    pub shared: Option<&'a VertexParts>,
}

impl<'a> Switching<'a> {
    /// Every part by its distances alone, with `hysteresis`.
    #[cfg(test)]
    pub fn plain(hysteresis: f64) -> Self {
        Self {
            hysteresis,
            stretch: &[],
            shared: None,
        }
    }

    pub fn context(&self, pi: usize, part: &Part) -> Option<StretchContext> {
        let stretch = matches!(part.kind, clay_dsl::compiled::PartKind::Stretch { .. })
            && part.states.len() == 3;
        if stretch {
            self.stretch.get(pi).copied().flatten()
        } else {
            None
        }
    }
}

/// A switching local step's choice for one part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Chosen {
    pub state: usize,
    /// The rotation of that state onto the pose.
    pub rotation: DVec2,
    /// For a stretch part, how many elements its two span in the pose: at least 3 in
    /// `three`, 2 in `two`, 1 or fewer in `one` (a part squeezed past one element's length,
    /// folded onto itself, spans fewer than none); 0 for other parts.
    pub claim: i32,
}

/// The most elements a stretch part may claim or give up (far beyond any model).
pub const MAX_CLAIM: i32 = 1 << 20;

/// Picks the active state of part `pi` (`part`) for the current positions: the nearest rest
/// state, but only when it is closer than `(1 - hysteresis)` times the active one (paper
/// 4.3); a stretch part with a context decides by [`decide_stretch`]. Returns the (possibly
/// new) active state, the rotation of that state onto the pose and the part's claim.
pub fn choose_state(pi: usize, part: &Part, positions: &[DVec2], how: Switching) -> Chosen {
    let hysteresis = how.hysteresis;
    let active = part.active.min(part.states.len().saturating_sub(1));
    let Some(current) = part.states.get(active) else {
        return Chosen {
            state: 0,
            rotation: DVec2::X,
            claim: 0,
        };
    };
    let ctx = how.context(pi, part);
    if let Some(ctx) = ctx
        && let Some(sums) = state_sums(part, positions)
    {
        return decide_stretch(sums, active, hysteresis, ctx);
    }
    let here = align(&current.positions, &part.vertices, positions);
    if part.states.len() < 2 {
        return Chosen {
            state: active,
            rotation: here.rotation,
            claim: 0,
        };
    }
    let boundary = how.shared.and_then(|vp| boundary_of(part, vp));
    let turn = boundary
        .as_ref()
        .and_then(|b| b.pose_turn(|k| positions[part.vertices[k]]));
    let judge = |j: usize| judged(part, positions, boundary.as_ref(), turn, j);
    let mut best = (active, judge(active));
    let judged_here = best.1;
    for j in 0..part.states.len() {
        // a stretch part takes only the states its rule can honour now
        if j == active || ctx.is_some_and(|c| !c.allows(j)) {
            continue;
        }
        let d = judge(j);
        if d < best.1 {
            best = (j, d);
        }
    }
    let state = switched(active, judged_here, best, hysteresis);
    let rotation = if state == active {
        here.rotation
    } else {
        align(&part.states[state].positions, &part.vertices, positions).rotation
    };
    Chosen {
        state,
        rotation,
        claim: 0,
    }
}

/// How far rest state `j` of `part` is from the pose: on the `boundary` vertices
/// ([`boundary_of`], [`Boundary::distance_at`]) when there are such, else its shape distance
/// over all of the part's vertices.
fn judged(
    part: &Part,
    positions: &[DVec2],
    boundary: Option<&Boundary>,
    turn: Option<DVec2>,
    j: usize,
) -> f64 {
    let rest = &part.states[j].positions;
    let at = |k: usize| positions[part.vertices[k]];
    match boundary {
        Some(b) if turn.is_some() => b.distance_at(j, &[], turn, at),
        Some(b) => b.distance_at(j, &b.points(|k| rest[k]), None, at),
        None => align(rest, &part.vertices, positions).distance,
    }
}

/// The vertices of a piece part with alternative rest states that it shares with other
/// parts ([`boundary_of`]): where it meets its neighbours, judged on their shape, or on the
/// turn between its two docking sites ([`SiteTurns`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Boundary {
    /// Local indices of the shared vertices.
    local: Vec<usize>,
    /// Two docking sites whose turn differs between every two states: the states are judged
    /// by that turn alone ([`SiteTurns`]).
    turns: Option<SiteTurns>,
}

/// The turn between a piece part's two docking sites, by which its states are judged when
/// they all differ in it (by [`TURNS_APART`] at least): a bendable piece's `bend` states and
/// their mirrors. Each site's rotation is its least-squares rotation from the part's first
/// state onto the pose (or onto another state); the turn is the second site's rotation less
/// the first's, so it is measured from the first state's turn.
///
/// Why: judged on shape, a piece whose states differ in turn also reads a squeeze or a
/// stretch between its sites as nearer a state whose sites are nearer or further apart. A
/// deep piece (3.6 m long, 1 m deep) squeezed in a strained model took its 75-degree state at
/// a turn of 1.9 degrees between its sites, and a thin fence corner pushed gently took its
/// quarter turn. Paper 4.3 asks that small changes of the input give small changes of the
/// output; the turn is what a bend state is, whatever the piece's proportions.
#[derive(Clone, Debug, PartialEq)]
struct SiteTurns {
    /// Per site: the indices into [`Boundary::local`] of its vertices.
    sites: [Vec<usize>; 2],
    /// Per site: the first state's positions of its vertices.
    first: [Vec<DVec2>; 2],
    /// Per state: its turn from the first state's, as a unit complex number.
    of_state: Vec<DVec2>,
}

/// How far apart (radians) every two states' turns between the sites must be for a part to
/// be judged by its turn: one degree; closer states differ in something else.
pub const TURNS_APART: f64 = std::f64::consts::PI / 180.0;

impl SiteTurns {
    /// The turns of `part`'s states between the two `groups` (indices into `local`) of its
    /// shared vertices; `None` when a site has fewer than two vertices, a state gives a site
    /// no rotation, or two states turn alike.
    fn new(part: &Part, local: &[usize], groups: [Vec<usize>; 2]) -> Option<Self> {
        let at = |j: usize, g: usize| -> Option<Vec<DVec2>> {
            (groups[g].iter())
                .map(|&i| part.states[j].positions.get(local[i]).copied())
                .collect()
        };
        if groups.iter().any(|g| g.len() < 2) {
            return None;
        }
        let first = [at(0, 0)?, at(0, 1)?];
        let of_state = (0..part.states.len())
            .map(|j| turn_between(&first, [&at(j, 0)?, &at(j, 1)?]))
            .collect::<Option<Vec<DVec2>>>()?;
        let apart = (0..of_state.len())
            .all(|a| (0..a).all(|b| angle_between(of_state[a], of_state[b]).abs() >= TURNS_APART));
        apart.then_some(Self {
            sites: groups,
            first,
            of_state,
        })
    }

    /// The pose's turn between the sites (`at` by local vertex index), from the first
    /// state's; `None` when a site has collapsed to a point. As [`turn_between`], without
    /// gathering the points (it runs for every such part in every local step).
    fn of_pose(&self, local: &[usize], at: impl Fn(usize) -> DVec2) -> Option<DVec2> {
        let rotation = |g: usize| {
            let (first, site) = (&self.first[g], &self.sites[g]);
            let q = |k: usize| at(local[site[k]]);
            let inv = 1.0 / first.len() as f64;
            let pc = first.iter().copied().sum::<DVec2>() * inv;
            let qc = (0..site.len()).map(q).sum::<DVec2>() * inv;
            let (mut dot, mut cross) = (0.0, 0.0);
            for (k, &p) in first.iter().enumerate() {
                let (a, b) = (p - pc, q(k) - qc);
                dot += a.dot(b);
                cross += a.perp_dot(b);
            }
            DVec2::new(dot, cross).try_normalize()
        };
        let (a, b) = (rotation(0)?, rotation(1)?);
        DVec2::new(a.dot(b), a.perp_dot(b)).try_normalize()
    }
}

/// The second site's rotation from `first[1]` onto `to[1]` less the first site's, as a unit
/// complex number.
fn turn_between(first: &[Vec<DVec2>; 2], to: [&[DVec2]; 2]) -> Option<DVec2> {
    let a = crate::fit::rigid_rotation(&first[0], to[0])?;
    let b = crate::fit::rigid_rotation(&first[1], to[1])?;
    DVec2::new(a.dot(b), a.perp_dot(b)).try_normalize()
}

/// The angle (radians, in [-pi, pi]) from unit complex number `a` to `b`.
fn angle_between(a: DVec2, b: DVec2) -> f64 {
    a.perp_dot(b).atan2(a.dot(b))
}

impl Boundary {
    /// Groups `local` (indices into `part.vertices`) by the parts sharing each vertex (a
    /// docking site each); with two, the turns between them ([`SiteTurns`]).
    fn new(part: &Part, local: Vec<usize>, shared: &VertexParts) -> Self {
        let mut keys: Vec<&[usize]> = Vec::new();
        let group: Vec<usize> = (local.iter())
            .map(|&k| {
                let key = shared.of(part.vertices[k]);
                keys.iter().position(|&g| g == key).unwrap_or_else(|| {
                    keys.push(key);
                    keys.len() - 1
                })
            })
            .collect();
        let turns = (keys.len() == 2)
            .then(|| {
                let of = |g: usize| (0..local.len()).filter(|&i| group[i] == g).collect();
                SiteTurns::new(part, &local, [of(0), of(1)])
            })
            .flatten();
        Self { local, turns }
    }

    /// Local indices of the shared vertices.
    pub fn local(&self) -> &[usize] {
        &self.local
    }

    /// The boundary's points of `at` (by local vertex index).
    pub fn points(&self, at: impl Fn(usize) -> DVec2) -> Vec<DVec2> {
        self.local.iter().map(|&k| at(k)).collect()
    }

    /// The pose's turn between the sites when the part is judged by its turn and the pose's
    /// sites have one ([`SiteTurns`]), once for all states.
    pub fn pose_turn(&self, at: impl Fn(usize) -> DVec2) -> Option<DVec2> {
        self.turns.as_ref()?.of_pose(&self.local, at)
    }

    /// How far state `j` (`rest`: its [`Boundary::points`]) is from the pose `at` gives: the
    /// squared difference (radians) of their turns between the sites when the part is judged
    /// by its turn and the pose's sites have one (`turn`, [`Boundary::pose_turn`]; `rest` is
    /// not read then), else the shape distance of the points.
    pub fn distance_at(
        &self,
        j: usize,
        rest: &[DVec2],
        turn: Option<DVec2>,
        at: impl Fn(usize) -> DVec2,
    ) -> f64 {
        if let Some(turn) = turn
            && let Some(&state) = self.turns.as_ref().and_then(|t| t.of_state.get(j))
        {
            return angle_between(state, turn).powi(2);
        }
        crate::fit::align_points(rest, &self.points(at)).distance
    }

    /// The turns (degrees) between the sites, from the first state's, of the pose `at` gives
    /// and of each state, when the part is judged by its turn ([`SiteTurns`]).
    pub fn turns(&self, at: impl Fn(usize) -> DVec2) -> Option<(f64, Vec<f64>)> {
        let t = self.turns.as_ref()?;
        let pose = t.of_pose(&self.local, at)?;
        let degrees = |u: DVec2| angle_between(DVec2::X, u).to_degrees();
        Some((
            degrees(pose),
            t.of_state.iter().map(|&u| degrees(u)).collect(),
        ))
    }
}

/// The vertices of a piece part with alternative rest states that it shares with other parts,
/// when there are at least two and fewer than all, or all when the part is judged by the turn
/// between its sites ([`SiteTurns`]) (paper 5.1, replacement: "the shape of the boundary
/// vertices determines which piece to insert"), as a [`Boundary`]. The others belong
/// to the part alone and take whichever state it takes, so they decide nothing: judged with
/// them, a segment whose ends are where its bent state puts them reads as no nearer that
/// state than its straight one, its middle still where the straight state's elasticity holds
/// it.
pub fn boundary_of(part: &Part, shared: &VertexParts) -> Option<Boundary> {
    if !matches!(part.kind, clay_dsl::compiled::PartKind::Piece { .. }) || part.states.len() < 2 {
        return None;
    }
    let ks: Vec<usize> = (0..part.vertices.len())
        .filter(|&k| shared.of(part.vertices[k]).len() >= 2)
        .collect();
    if ks.len() < 2 {
        return None;
    }
    // the states must differ there: a part docked by one site has that site's shape in
    // every state, and its distances would all be rounding
    let at = |j: usize| -> Option<Vec<DVec2>> {
        ks.iter()
            .map(|&k| part.states[j].positions.get(k).copied())
            .collect()
    };
    let first = at(0)?;
    let scale: f64 = {
        let c = first.iter().copied().sum::<DVec2>() / first.len() as f64;
        first.iter().map(|p| (*p - c).length_squared()).sum()
    };
    let differ = (1..part.states.len()).any(|j| {
        at(j).is_some_and(|other| {
            let indices: Vec<usize> = (0..other.len()).collect();
            align(&first, &indices, &other).distance > 1e-9 * scale
        })
    });
    if !differ {
        return None;
    }
    let every = ks.len() == part.vertices.len();
    let b = Boundary::new(part, ks, shared);
    // every vertex shared: judged on its shape, unless by its turn
    (!every || b.turns.is_some()).then_some(b)
}

/// A stretch part's sums over its centred pose for its three states (as [`align`] forms
/// them): `(dot, cross, pp)` per state and the pose's squared norm. `None` when a state has
/// fewer positions than the part has vertices.
fn state_sums(part: &Part, positions: &[DVec2]) -> Option<StateSums> {
    let m = part.vertices.len();
    if m == 0 || part.states.iter().any(|s| s.positions.len() < m) {
        return None;
    }
    let inv = 1.0 / m as f64;
    let pose_centre = part.vertices.iter().map(|&v| positions[v]).sum::<DVec2>() * inv;
    let mut sums = StateSums::default();
    for (j, state) in part.states.iter().take(3).enumerate() {
        let rest = &state.positions[..m];
        let rest_centre = rest.iter().copied().sum::<DVec2>() * inv;
        let (mut dot, mut cross, mut pp, mut qq) = (0.0, 0.0, 0.0, 0.0);
        for (k, &v) in part.vertices.iter().enumerate() {
            let p = rest[k] - rest_centre;
            let q = positions[v] - pose_centre;
            dot += p.dot(q);
            cross += p.perp_dot(q);
            pp += p.length_squared();
            qq += q.length_squared();
        }
        sums.dot[j] = dot;
        sums.cross[j] = cross;
        sums.pp[j] = pp;
        sums.qq = qq;
    }
    let ends = StretchEnds::find(
        &part.states[0].positions[..m],
        &part.states[2].positions[..m],
    )?;
    sums.span = ends.span(|k| positions[part.vertices[k]]);
    sums.element = ends.element;
    sums.axis = ends.axis;
    Some(sums)
}

/// The sums a stretch part's decision reads (see [`state_sums`]), and its span: where its
/// far end (the second element's `to` site) is from its near end (the first element's `from`
/// site) in the pose, `span`, against `ends.element`, one element's length at rest.
#[derive(Clone, Copy, Debug, Default)]
pub struct StateSums {
    pub dot: [f64; 3],
    pub cross: [f64; 3],
    pub pp: [f64; 3],
    pub qq: f64,
    pub span: DVec2,
    pub element: f64,
    /// The chain's direction in the part's rest frame (unit).
    pub axis: DVec2,
}

/// A stretch part measured in a pose
/// ([`RestCache::measure_stretch`](super::rest_cache::RestCache::measure_stretch)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PartMeasure {
    /// Each element's length, in elements at rest.
    pub lengths: [f64; 2],
    /// The first element's `from` site's centre and the second's `to` site's.
    pub near: DVec2,
    pub far: DVec2,
    /// One element's length at rest.
    pub element: f64,
}

/// A stretch part's ends, found from its rest states: its `one`, `two` and `three` states
/// differ only along the axis, by the vertex's distance from the near end, so the vertices
/// that do not move between `one` and `three` are the near end (the first element's `from`
/// site) and those that move most are the far end (the second element's `to` site).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StretchEnds {
    pub near: Vec<usize>,
    /// The first element's `to` site (the second's `from`): half way in `three - one`.
    pub middle: Vec<usize>,
    pub far: Vec<usize>,
    /// The chain's direction in the part's rest frame (unit), and one element's length.
    pub axis: DVec2,
    pub element: f64,
}

impl StretchEnds {
    /// From the `one` and `three` rest positions (one per vertex of the part).
    pub fn find(one: &[DVec2], three: &[DVec2]) -> Option<Self> {
        let moved: Vec<DVec2> = one.iter().zip(three).map(|(&a, &b)| b - a).collect();
        let longest = moved.iter().map(|d| d.length()).fold(0.0, f64::max);
        if !(longest > 0.0 && longest.is_finite()) {
            return None;
        }
        let tolerance = 1e-9 * longest;
        let near: Vec<usize> = (0..moved.len())
            .filter(|&k| moved[k].length() <= tolerance)
            .collect();
        let far: Vec<usize> = (0..moved.len())
            .filter(|&k| moved[k].length() >= longest - tolerance)
            .collect();
        let middle: Vec<usize> = (0..moved.len())
            .filter(|&k| (moved[k].length() - longest / 2.0).abs() <= tolerance)
            .collect();
        // `three - one` moves the far end by two elements' length (3/2 - 1/2 of the two)
        let axis = moved[far[0]] / longest;
        (!near.is_empty() && !middle.is_empty()).then_some(Self {
            near,
            middle,
            far,
            axis,
            element: longest / 2.0,
        })
    }

    /// The far end's centre less the near end's, in `pose` (the part's vertices' positions).
    pub fn span(&self, pose: impl Fn(usize) -> DVec2) -> DVec2 {
        let centre = |ks: &[usize]| ks.iter().map(|&k| pose(k)).sum::<DVec2>() / ks.len() as f64;
        centre(&self.far) - centre(&self.near)
    }

    /// The spans of the part's two elements (from their `from` site's centre to their `to`
    /// site's), in `pose`.
    pub fn element_spans(&self, pose: impl Fn(usize) -> DVec2) -> [DVec2; 2] {
        let centre = |ks: &[usize]| ks.iter().map(|&k| pose(k)).sum::<DVec2>() / ks.len() as f64;
        let (near, middle, far) = (centre(&self.near), centre(&self.middle), centre(&self.far));
        [middle - near, far - middle]
    }
}

/// A stretch part's state (paper 5.1, the stretch rule's `one`, `two`, `three`). Its three
/// rest states are its two elements scaled along the chain's axis by 1/2, 1 and 3/2, so the
/// rest shape of its two elements stretched to span `c` elements is the same affine family at
/// scale `c / 2`, and every sum the shape distance needs is an affine (the rest norm: a
/// quadratic) function of the scale, known from the three states' sums.
///
/// The part is measured in the frame of its rotation when the frame began
/// ([`StretchContext::reference`]), not in its best rotation: pass 1 may fold a squeezed part
/// onto itself, and the best rotation of a folded part turns it round, so a squeeze would
/// read as a stretch. Its length `c` in elements is its span, from the near end to the far
/// end along the chain's direction in that frame (the sparse norm gathers a stretch into one
/// of the two elements, so the scale that fits all its vertices best would mislead). The state the length calls for is the candidate: `three` from 2.5 elements on
/// (claiming the nearest count, however many: a part stretched far beyond three fits the
/// three-element shape no better, by the hysteresis's margin, than two), `one` up to 1.5,
/// else `two`. The candidate replaces the active state when its shape distance (for a claim
/// of `c` elements, the distance to the `c`-element shape) is below `(1 - hysteresis)` times
/// the active state's (paper 4.3); at once when the part is no longer than `one` (beyond
/// the states' range both distances grow alike, and the margin would never be met) or when
/// the active state has become unavailable.
pub fn decide_stretch(
    sums: StateSums,
    active: usize,
    hysteresis: f64,
    ctx: StretchContext,
) -> Chosen {
    use clay_dsl::compiled::{STRETCH_ONE as ONE, STRETCH_THREE as THREE, STRETCH_TWO as TWO};
    let view = StretchView::of(&sums, ctx);
    let StretchView {
        distances,
        length,
        elements,
        candidate,
        candidate_distance,
    } = view;
    let beyond_one = candidate == ONE && length <= 1.0;
    let switch = candidate != active
        && (!ctx.allows(active)
            || beyond_one
            || candidate_distance < (1.0 - hysteresis) * distances[active]);
    let state = if switch { candidate } else { active };
    let count = elements.max(1);
    let claim = match state {
        ONE if candidate == ONE => elements.min(1),
        ONE => 1,
        TWO => 2,
        _ if candidate == THREE => count.max(3),
        _ => 3,
    };
    let (dot, cross) = (sums.dot[state], sums.cross[state]);
    let len = (dot * dot + cross * cross).sqrt();
    Chosen {
        state,
        rotation: rotation_of(dot, cross, len),
        claim,
    }
}

/// What a stretch part's decision ([`decide_stretch`]) sees of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StretchView {
    /// The squared distances to `one`, `two` and `three`, turned by the reference.
    pub distances: [f64; 3],
    /// Its span in elements along the chain's direction, and that rounded (however far).
    pub length: f64,
    pub elements: i32,
    /// The state its length calls for (`two` when that one is unavailable), and the distance
    /// to its shape (for `three`, to the shape of `elements` elements).
    pub candidate: usize,
    pub candidate_distance: f64,
}

impl StretchView {
    pub fn of(sums: &StateSums, ctx: StretchContext) -> Self {
        use clay_dsl::compiled::{STRETCH_ONE as ONE, STRETCH_THREE as THREE, STRETCH_TWO as TWO};
        let StateSums {
            dot, cross, pp, qq, ..
        } = *sums;
        let r = ctx.reference;
        // the squared distance to a rest shape with these sums, turned by the reference
        let distance =
            |dot: f64, cross: f64, pp: f64| (pp + qq - 2.0 * (r.x * dot + r.y * cross)).max(0.0);
        let distances: [f64; 3] = std::array::from_fn(|j| distance(dot[j], cross[j], pp[j]));
        // the span along the chain's direction, in elements
        let length = sums.span.dot(r.rotate(sums.axis)) / sums.element;
        let length = if length.is_finite() { length } else { 2.0 };
        let elements = length
            .round()
            .clamp(-f64::from(MAX_CLAIM), f64::from(MAX_CLAIM)) as i32;
        let count = elements.max(1);
        let mut candidate = match count {
            1 => ONE,
            2 => TWO,
            _ => THREE,
        };
        if !ctx.allows(candidate) {
            candidate = TWO;
        }
        let candidate_distance = if candidate == THREE && count > 3 {
            // the `count`-element shape: t = count - 2 steps of `three - two` from `two`
            let t = f64::from(count - 2);
            let d = dot[TWO] + t * (dot[THREE] - dot[TWO]);
            let c = cross[TWO] + t * (cross[THREE] - cross[TWO]);
            let linear = (pp[THREE] - pp[ONE]) / 4.0;
            let quadratic = (pp[ONE] + pp[THREE]) / 2.0 - pp[TWO];
            distance(d, c, pp[TWO] + 2.0 * t * linear + t * t * quadratic)
        } else {
            distances[candidate]
        };
        Self {
            distances,
            length,
            elements,
            candidate,
            candidate_distance,
        }
    }
}

/// What the local step sees of a part when it chooses its state ([`choose_state`]): the
/// distances it compares, per rest state, and which states may become active. For the
/// inspector, which must say what the solver does.
#[derive(Clone, Debug, PartialEq)]
pub struct Judgement {
    /// Per rest state: the squared shape distance the choice compares (a piece part's over
    /// its shared vertices, a stretch part's in its chain's frame).
    pub distances: Vec<f64>,
    /// Per rest state: whether it may become active.
    pub available: Vec<bool>,
    /// For a stretch part: the state its length calls for, and its length in elements.
    pub candidate: Option<(usize, f64)>,
    /// For a piece part judged by the turn between its sites ([`Boundary::distance_at`]): that
    /// turn in the pose and each state's, in degrees from the first state's.
    pub turns: Option<(f64, Vec<f64>)>,
}

/// The [`Judgement`] of part `pi` (`part`) at `positions`, as [`choose_state`] makes it.
pub fn judge(pi: usize, part: &Part, positions: &[DVec2], how: Switching) -> Judgement {
    let n = part.states.len();
    if let Some(ctx) = how.context(pi, part)
        && let Some(sums) = state_sums(part, positions)
    {
        let view = StretchView::of(&sums, ctx);
        return Judgement {
            distances: view.distances.to_vec(),
            available: (0..n).map(|j| ctx.allows(j)).collect(),
            candidate: Some((view.candidate, view.length)),
            turns: None,
        };
    }
    let boundary = how.shared.and_then(|vp| boundary_of(part, vp));
    let turn = boundary
        .as_ref()
        .and_then(|b| b.pose_turn(|k| positions[part.vertices[k]]));
    let distances = (0..n)
        .map(|j| judged(part, positions, boundary.as_ref(), turn, j))
        .collect();
    let turns = boundary.and_then(|b| b.turns(|k| positions[part.vertices[k]]));
    Judgement {
        distances,
        available: vec![true; n],
        candidate: None,
        turns,
    }
}

/// Paper 4.3: the nearest state `best` replaces the active one only when it is closer than
/// `(1 - hysteresis)` times the active state's distance `here`. Returns the state and its
/// rotation onto the pose.
pub fn with_hysteresis(
    active: usize,
    here: Alignment,
    best: (usize, Alignment),
    hysteresis: f64,
) -> (usize, DVec2) {
    if switched(active, here.distance, (best.0, best.1.distance), hysteresis) == active {
        (active, here.rotation)
    } else {
        (best.0, best.1.rotation)
    }
}

/// Paper 4.3 on distances: `best.0` when it is not `active` and its distance `best.1` is
/// below `(1 - hysteresis)` times the active state's `here`, else `active`.
pub fn switched(active: usize, here: f64, best: (usize, f64), hysteresis: f64) -> usize {
    if best.0 != active && best.1 < (1.0 - hysteresis) * here {
        best.0
    } else {
        active
    }
}

/// Rotation of the active state of `part` onto the pose, states fixed.
pub fn part_rotation(part: &Part, positions: &[DVec2]) -> DVec2 {
    match part.states.get(part.active) {
        Some(s) => align(&s.positions, &part.vertices, positions).rotation,
        None => DVec2::X,
    }
}

/// For every vertex, the parts containing it (compressed rows; built once per generation).
#[derive(Clone, Debug, Default)]
pub struct VertexParts {
    start: Vec<usize>,
    parts: Vec<usize>,
}

impl VertexParts {
    pub fn build(parts: &[Part], vertex_count: usize) -> Self {
        let mut count = vec![0usize; vertex_count + 1];
        for part in parts {
            for &v in &part.vertices {
                count[v + 1] += 1;
            }
        }
        for i in 0..vertex_count {
            count[i + 1] += count[i];
        }
        let mut fill = count.clone();
        let mut list = vec![0; count[vertex_count]];
        for (pi, part) in parts.iter().enumerate() {
            for &v in &part.vertices {
                list[fill[v]] = pi;
                fill[v] += 1;
            }
        }
        Self {
            start: count,
            parts: list,
        }
    }

    pub fn of(&self, v: usize) -> &[usize] {
        &self.parts[self.start[v]..self.start[v + 1]]
    }
}

/// Sum of the rotations of the parts containing `v` that lie within the cone `cos_cone` of
/// `own`; [`edge_rotation`] is the normalised sum of this for both ends of an edge.
pub fn vertex_rotation_sum(
    vertex_parts: &VertexParts,
    rotations: &[DVec2],
    v: usize,
    own: DVec2,
    cos_cone: f64,
) -> DVec2 {
    let mut s = DVec2::ZERO;
    for &j in vertex_parts.of(v) {
        let r = rotations[j];
        if r.dot(own) >= cos_cone {
            s += r;
        }
    }
    s
}

/// Normalises a sum of rotations, falling back to `own` when it (nearly) vanishes.
#[inline]
pub fn normalised_or(s: DVec2, own: DVec2) -> DVec2 {
    let len = s.length();
    // divided before the test (the quotient is dropped when unused): the compiler then
    // divides both components in one instruction, and the division dominates the local step
    let unit = s / len;
    if len > 1e-9 && len.is_finite() {
        unit
    } else {
        own
    }
}

/// `R_xy` for an edge of part `own_part`: the average of the rotations of the parts containing
/// `x` or `y`, as a normalised sum of unit complex numbers (never an average of angles).
///
/// Only parts whose rotation lies within the cone `cos_cone` of the part's own rotation take
/// part: every part's rest states live in its own piece frame, so two parts meeting at a
/// corner (a wall turning 90 degrees at a tower) have rotations 90 degrees apart even at rest,
/// and averaging them would leave a rest assembly with non-zero energy. Parts containing both
/// ends count twice. Falls back to the part's own rotation when the average vanishes.
pub fn edge_rotation(
    vertex_parts: &VertexParts,
    rotations: &[DVec2],
    x: usize,
    y: usize,
    own_part: usize,
    cos_cone: f64,
) -> DVec2 {
    let own = rotations[own_part];
    if cos_cone >= 1.0 {
        return own;
    }
    let s = vertex_rotation_sum(vertex_parts, rotations, x, own, cos_cone)
        + vertex_rotation_sum(vertex_parts, rotations, y, own, cos_cone);
    normalised_or(s, own)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn align_recovers_a_rotation_and_zero_distance() {
        let rest = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(0.0, 2.0),
        ];
        let rot = DVec2::from_angle(0.7);
        let pos: Vec<DVec2> = rest
            .iter()
            .map(|&p| rot.rotate(p) + DVec2::new(3.0, -1.0))
            .collect();
        let a = align(&rest, &[0, 1, 2], &pos);
        assert!((a.rotation - rot).length() < 1e-12);
        assert!(a.distance < 1e-12);
    }

    #[test]
    fn coincident_vertices_give_identity_not_nan() {
        let rest = [DVec2::ZERO; 3];
        let pos = [DVec2::new(1.0, 1.0); 3];
        let a = align(&rest, &[0, 1, 2], &pos);
        assert_eq!(a.rotation, DVec2::X);
        assert!(a.distance.is_finite());
    }

    fn two_parts(rotations: &[DVec2]) -> (Vec<Part>, VertexParts) {
        let part = |v: Vec<usize>| Part {
            kind: clay_dsl::compiled::PartKind::Piece { instance: 0 },
            vertices: v,
            edges: vec![[0, 1]],
            states: vec![],
            active: 0,
        };
        let parts = vec![part(vec![0, 1]), part(vec![1, 2])];
        let vp = VertexParts::build(&parts, 3);
        assert_eq!(rotations.len(), 2);
        (parts, vp)
    }

    #[test]
    fn edge_rotation_averages_nearby_rotations_as_unit_complex_numbers() {
        let rotations = [DVec2::from_angle(0.1), DVec2::from_angle(0.3)];
        let (_, vp) = two_parts(&rotations);
        let r = edge_rotation(&vp, &rotations, 0, 1, 0, 0.5);
        // part 0 counts twice (it holds both ends), part 1 once
        let expected = (2.0 * rotations[0] + rotations[1]).normalize();
        assert!((r - expected).length() < 1e-12);
    }

    #[test]
    fn rotations_outside_the_cone_are_left_out() {
        let rotations = [DVec2::X, DVec2::Y];
        let (_, vp) = two_parts(&rotations);
        assert_eq!(edge_rotation(&vp, &rotations, 0, 1, 0, 0.9), DVec2::X);
        // with the cone wide open, opposite rotations may cancel: fall back to our own
        let opposite = [DVec2::X, -DVec2::X];
        assert_eq!(edge_rotation(&vp, &opposite, 1, 1, 0, -1.0), DVec2::X);
    }
}
