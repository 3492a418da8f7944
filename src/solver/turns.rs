//! Counts from turns (`relax.rs`, `docs/solver.md`): a chain whose elements each turn by an
//! angle between their sites (a wedge, a curved rail) rests only with the counts whose turn
//! matches the turn between the frames its ends are held in: twelve 30-degree wedges close a
//! ring, and no other count near twelve does, whatever the ring's length. The relaxation's
//! lengths cannot see this (a ring of thirteen squeezed into twelve's circle keeps its
//! length); the turn between the chain's end sites can.

use clay_dsl::compiled::{
    AssemblyData, CompiledGrammar, Part, PartKind, STRETCH_TWO, StretchPart, StretchRule,
};
use glam::DVec2;
use std::cmp::Ordering;

use super::loops::{Step, free_loops};
use super::rounding::{chain_of, held_elements, runs};
use crate::assembly::Assembly;
use crate::fit::{RigidMotion, align, rigid_motion};

/// An element that turns by less than this (radians) between its sites is straight: its
/// chain's turn says nothing of its count.
const STRAIGHT: f64 = 1e-3;

/// The most elements a whole turn more adds to a chain in one proposal ([`from_turn`]):
/// twelve 30-degree wedges, or 64 elements of 5.6 degrees.
const WHOLE_TURN_MOST: usize = 64;

/// A proposal of [`counts_from_turns`]: counts (`(chain, first, count)`, as a
/// [`Proposal`]'s) and piece states (`(instance, state)`).
///
/// [`Proposal`]: super::report::Proposal
pub(super) type Turned = (Vec<(usize, usize, usize)>, Vec<(usize, usize)>);

/// Counts whose turns miss the held one within this (in element turns) miss alike.
const ALIKE_TURN: f64 = 1e-3;

/// Counts whose ends' distance apart at rest misses the pose's within this (in elements'
/// lengths) miss alike.
const ALIKE_CHORD: f64 = 1e-3;

/// The centre of points.
fn centre(ps: &[DVec2]) -> DVec2 {
    ps.iter().sum::<DVec2>() / ps.len().max(1) as f64
}

/// The angle `a` brought into (-pi, pi].
fn wrap(a: f64) -> f64 {
    DVec2::from_angle(a).to_angle()
}

/// The direction (radians) of a site's vertices `v`, first to last.
fn site_angle(v: &[DVec2]) -> Option<f64> {
    let d = *v.last()? - *v.first()?;
    (d.length_squared() > 0.0).then(|| d.to_angle())
}

/// The rigid motion from one element of a two-element part to the next in its `two` rest
/// state: the one taking element 0's vertices onto element 1's, vertex by piece vertex.
/// `None` with fewer than two such vertices.
fn element_step(part: &StretchPart) -> Option<RigidMotion> {
    let two = &part.states.get(STRETCH_TWO)?.positions;
    let (mut from, mut to) = (Vec::new(), Vec::new());
    for (k, v) in part.vertices.iter().enumerate() {
        if v.element != 0 {
            continue;
        }
        let twin = part
            .vertices
            .iter()
            .position(|w| w.element == 1 && w.vertex == v.vertex);
        if let (Some(j), Some(&p)) = (twin, two.get(k)) {
            from.push(p);
            to.push(*two.get(j)?);
        }
    }
    if from.len() < 2 {
        return None;
    }
    rigid_motion(&from, &to)
}

/// Whether the elements of `rule`'s chain run straight on from each other (turning by less
/// than [`STRAIGHT`]): a chain whose count its length decides, not its turn.
pub(super) fn chain_is_straight(rule: &StretchRule) -> bool {
    element_step(&rule.part).is_some_and(|s| s.rotation.to_angle().abs() < STRAIGHT)
}

/// The positions, in the part's vertex order, of element 0's `from` site and element 1's
/// `to` site of a two-element part (the chain's ends when the part is its first or last).
struct EndSites {
    from: Vec<usize>,
    to: Vec<usize>,
}

impl EndSites {
    fn of(grammar: &CompiledGrammar, rule: &StretchRule) -> Option<Self> {
        let piece = grammar.pieces.get(rule.piece)?;
        let find = |element: u8, v: usize| {
            (rule.part.vertices.iter()).position(|w| w.element == element && w.vertex == v)
        };
        let site = |s: usize, element: u8| -> Option<Vec<usize>> {
            let vs = &piece.sites.get(s)?.vertices;
            let ks: Option<Vec<usize>> = vs.iter().map(|&v| find(element, v)).collect();
            ks.filter(|ks| ks.len() >= 2)
        };
        Some(Self {
            from: site(rule.from, 0)?,
            to: site(rule.to, 1)?,
        })
    }
}

/// A chain's turn against its rest turn: the element's turn, its count, how far (radians)
/// the turn from its first site to its last in a pose is from the turn its count has at
/// rest, and the part a change of count goes to (the one furthest from its rest shape).
struct ChainTurn {
    theta: f64,
    step: RigidMotion,
    /// In the `two` state: element 0's `from` site's vertices, element 1's `to` site's.
    rest_from: Vec<DVec2>,
    rest_to: Vec<DVec2>,
    /// In the pose: the chain's first site's vertices, its last site's.
    from: Vec<DVec2>,
    to: Vec<DVec2>,
    count: usize,
    off: f64,
    first: usize,
    min: usize,
    max: Option<usize>,
}

impl ChainTurn {
    /// Chain `c`'s, from its `parts` (`(first, part)`) in `pose`.
    fn of(asm: &Assembly, c: usize, parts: &[(usize, &Part)], pose: &[DVec2]) -> Option<Self> {
        let (data, grammar) = (asm.data(), asm.grammar());
        let rule = grammar.stretch_rules.get(data.chains.get(c)?.rule)?;
        let step = element_step(&rule.part)?;
        let theta = step.rotation.to_angle();
        let n = data.chains[c].instances.len();
        let ends = EndSites::of(grammar, rule)?;
        let part = |first: usize| parts.iter().find(|p| p.0 == first).map(|p| p.1);
        let (head, tail) = (part(0)?, part(n.checked_sub(2)?)?);
        let two = &rule.part.states.get(STRETCH_TWO)?.positions;
        let rest_of = |ks: &[usize]| -> Option<Vec<DVec2>> {
            ks.iter().map(|&k| two.get(k).copied()).collect()
        };
        let posed = |p: &Part, ks: &[usize]| -> Option<Vec<DVec2>> {
            ks.iter()
                .map(|&k| pose.get(*p.vertices.get(k)?).copied())
                .collect()
        };
        let (rest_from, rest_to) = (rest_of(&ends.from)?, rest_of(&ends.to)?);
        let (from, to) = (posed(head, &ends.from)?, posed(tail, &ends.to)?);
        // the turn from the chain's first site to its last: two elements' at rest, and one
        // element's more for each further element
        let rest = site_angle(&rest_to)? - site_angle(&rest_from)?;
        let turn = site_angle(&to)? - site_angle(&from)?;
        let strain = |p: &Part| {
            (p.states.get(STRETCH_TWO))
                .map_or(0.0, |s| align(&s.positions, &p.vertices, pose).distance)
        };
        let first = (parts.iter())
            .max_by(|x, y| strain(x.1).total_cmp(&strain(y.1)))
            .map_or(0, |p| p.0);
        Some(Self {
            theta,
            step,
            rest_from,
            rest_to,
            from,
            to,
            count: n,
            off: wrap(turn - rest - (n as f64 - 2.0) * theta),
            first,
            min: rule.min.max(2),
            max: rule.max,
        })
    }

    fn turns(&self) -> bool {
        self.theta.abs() >= STRAIGHT
    }

    /// The rest positions of the `to` site of element `m - 1` (element 1's carried on).
    fn rest_last(&self, m: usize) -> Vec<DVec2> {
        let mut last = self.rest_to.clone();
        for _ in 2..m {
            last.iter_mut().for_each(|p| *p = self.step.apply(*p));
        }
        last
    }

    /// How far apart its first and last sites' centres are at rest with `m` elements.
    fn chord(&self, m: usize) -> Option<f64> {
        let d = centre(&self.rest_last(m)).distance(centre(&self.rest_from));
        d.is_finite().then_some(d)
    }

    /// How far an element carries its sites' centres at rest.
    fn element_length(&self) -> f64 {
        let last = centre(&self.rest_last(2));
        last.distance(centre(&self.rest_last(3)))
    }

    /// How far apart its first and last sites' centres are in the pose.
    fn span(&self) -> f64 {
        centre(&self.to).distance(centre(&self.from))
    }
}

/// Proposals of counts (each a list of `(chain, first, count)` as a [`Proposal`]'s) for
/// every chain of turning elements whose count does not match a turn it is held to in
/// `pose` (the relaxed pose): the count whose turn matches best, when better than the
/// chain's own by the `hysteresis` margin (paper 4.3, in elements' turns), within the rule's
/// bounds, among counts a whole turn apart the one whose ends are as far apart at rest as
/// in the pose, then the fewest (no extra loop). A chain's turn from its first site to its
/// last grows by one element's turn with each element, modulo a whole turn. The turns it
/// may be held to: its own; where it is the one turning chain of chains in series
/// (`rounding::runs`: a straight wall and an arc docked end to end), theirs all together,
/// since a straight chain rests straight; and the turn along each path between two held
/// pieces through it ([`held_paths`]). The session judges each with the lengths it then
/// asks for (`Proposal::then_lengths`), so the straight chains it moves are re-counted
/// there, not here.
///
/// [`Proposal`]: super::report::Proposal
pub(super) fn counts_from_turns(asm: &Assembly, pose: &[DVec2], hysteresis: f64) -> Vec<Turned> {
    let data = asm.data();
    let mut parts: Vec<Vec<(usize, &Part)>> = vec![Vec::new(); data.chains.len()];
    for p in &data.parts {
        if let PartKind::Stretch { chain, first } = p.kind
            && let Some(of) = parts.get_mut(chain)
        {
            of.push((first, p));
        }
    }
    let turns: Vec<Option<ChainTurn>> = (0..data.chains.len())
        .map(|c| ChainTurn::of(asm, c, &parts[c], pose))
        .collect();
    let held = held_elements(asm);
    let series = runs(asm.grammar(), data, &held);
    let mut paths = held_paths(data, &held);
    // a loop no held piece is on turns by a whole turn (a ring let go)
    paths.extend(free_loops(asm, pose, &held));
    // each path's turn off its rest: its chains' and free pieces' misfits added up
    let alongs: Vec<Option<f64>> = (paths.iter())
        .map(|path| {
            (path.iter())
                .map(|s| match *s {
                    Step::Chain(d, sign) => turns[d].as_ref().map(|d| sign * d.off),
                    Step::Piece {
                        instance,
                        enter,
                        leave,
                    } => piece_off(asm.grammar(), data, pose, (instance, enter, leave)),
                })
                .sum()
        })
        .collect();
    let mut out = Vec::new();
    for (c, t) in turns.iter().enumerate() {
        let Some(t) = t.as_ref().filter(|t| t.turns()) else {
            continue;
        };
        let run = series.iter().find(|g| g.contains(&c));
        let alone = run.is_none_or(|g| {
            g.iter()
                .filter(|&&d| turns[d].as_ref().is_none_or(ChainTurn::turns))
                .count()
                == 1
        });
        // the turns it may be held to: its own; its run's when it is the run's one turning
        // chain; each path's between held pieces through it (the whole path's misfit on it)
        let mut offs = vec![t.off];
        if let Some(g) = run.filter(|_| alone) {
            offs.push(wrap(
                g.iter()
                    .filter_map(|&d| turns[d].as_ref())
                    .map(|d| d.off)
                    .sum(),
            ));
        }
        for (path, along) in paths.iter().zip(&alongs) {
            let Some(sign) = path.iter().find_map(|s| match *s {
                Step::Chain(d, sign) if d == c => Some(sign),
                _ => None,
            }) else {
                continue;
            };
            if let Some(along) = along {
                offs.push(wrap(sign * along));
            }
        }
        for off in offs {
            if let Some(change) = from_turn(c, t, off, hysteresis).map(|x| (vec![x], vec![]))
                && !out.contains(&change)
            {
                out.push(change);
            }
        }
    }
    // the same turn between the holds split otherwise between a path's turning chains
    for (path, along) in paths.iter().zip(&alongs) {
        if let Some(along) = along {
            for turned in splits(asm, path, &turns, *along) {
                if !out.contains(&turned) {
                    out.push(turned);
                }
            }
        }
    }
    // chains in series with several turning ones (a ring of arcs between gates): what the
    // run's turn asks for, spread over them evenly
    for run in &series {
        let turning: Vec<&ChainTurn> = (run.iter())
            .filter_map(|&d| turns[d].as_ref())
            .filter(|t| t.turns())
            .collect();
        let Some(t0) = turning.first() else {
            continue;
        };
        let known = run.iter().all(|&d| turns[d].is_some());
        let alike = turning.iter().all(|t| (t.theta - t0.theta).abs() < 1e-9);
        if turning.len() < 2 || !known || !alike {
            continue;
        }
        let off = wrap(
            run.iter()
                .filter_map(|&d| turns[d].as_ref())
                .map(|d| d.off)
                .sum(),
        );
        let whole = (off / t0.theta).round();
        let miss = |j: f64| wrap(off - j * t0.theta).abs() / t0.theta.abs();
        if whole == 0.0 || miss(whole) >= (1.0 - hysteresis) * miss(0.0) {
            continue;
        }
        let (k, j) = (turning.len() as i64, whole as i64);
        let counts: Option<Vec<(usize, usize, usize)>> = (run.iter())
            .filter(|&&d| turns[d].as_ref().is_some_and(ChainTurn::turns))
            .enumerate()
            .map(|(i, &d)| {
                let t = turns[d].as_ref()?;
                let share = j.div_euclid(k) + i64::from((i as i64) < j.rem_euclid(k));
                let m = usize::try_from(t.count as i64 + share).ok()?;
                (m >= t.min && t.max.is_none_or(|x| m <= x)).then_some((d, t.first, m))
            })
            .collect();
        let changed =
            |&(d, _, m): &(usize, usize, usize)| turns[d].as_ref().map(|t| t.count) != Some(m);
        if let Some(counts) = counts.map(|c| c.into_iter().filter(changed).collect::<Vec<_>>())
            && !counts.is_empty()
        {
            out.push((counts, Vec::new()));
        }
    }
    out
}

/// Counts for the turning chains on a held `path` (its turn `along` off its rest), each one element
/// more, fewer or as it is, and its pieces' states ([`piece_takes`]), two changes or more, that
/// leave the path's turn as near its rest as any such changes do and as it is: the turn between two
/// holds fixes how much the path turns, not how its turning chains and pieces share it. One element
/// moved from an arc to another through a free hub moves the hub (a tree whose arcs of 3 and 2 rest
/// only as 2 and 3 when its far hub is led round: strain 0.03 at 3 and 2, the same turn); an arc of
/// 20-degree elements one longer with a 10-degree bend piece mirrored turns as far as one shorter
/// with the bend as it was, and only one of them closes whole (generated morph case 334: 5 and the
/// bend mirrored rested at strain 0.025 where 4 and the bend rest). At most [`SPLIT_CHAINS`]
/// turning chains, [`SPLIT_MOST`] proposals, fewest changes first; one change alone is
/// [`from_turn`]'s (a chain) or the relaxation's (a piece, `relax.rs`). The session judges each by
/// energy, with the lengths it then asks for.
fn splits(asm: &Assembly, path: &[Step], turns: &[Option<ChainTurn>], along: f64) -> Vec<Turned> {
    let on: Vec<(&ChainTurn, f64, usize)> = (path.iter())
        .filter_map(|s| match *s {
            Step::Chain(d, sign) => turns[d]
                .as_ref()
                .filter(|t| t.turns())
                .map(|t| (t, sign, d)),
            Step::Piece { .. } => None,
        })
        .collect();
    // each other state of each piece on the path: (instance, state, how much more it turns)
    let others: Vec<(usize, usize, f64)> = (path.iter())
        .filter_map(|s| match *s {
            Step::Piece {
                instance,
                enter,
                leave,
            } => Some(piece_states(asm, (instance, enter, leave))),
            Step::Chain(..) => None,
        })
        .flatten()
        .collect();
    if on.len() > SPLIT_CHAINS || others.len() > SPLIT_STATES || on.len() + others.len() < 2 {
        return Vec::new();
    }
    // the unit misses are read in: the smallest element's turn, or piece state's change
    let unit = (on.iter().map(|c| c.0.theta.abs()))
        .chain(others.iter().map(|o| o.2.abs()))
        .filter(|&x| x >= STRAIGHT)
        .fold(f64::INFINITY, f64::min);
    if !unit.is_finite() {
        return Vec::new();
    }
    // the path's misfit, in units, with each chain changed by `by` and the piece states
    // `taken` (indices into `others`)
    let miss = |(by, taken): &(Vec<i64>, Vec<usize>)| {
        let turned: f64 = (on.iter().zip(by))
            .map(|(c, &k)| c.1 * k as f64 * c.0.theta)
            .sum();
        let more: f64 = taken.iter().map(|&o| others[o].2).sum();
        wrap(along - turned - more).abs() / unit
    };
    let allowed = |by: &[i64]| {
        (on.iter().zip(by)).all(|(c, &k)| {
            let m = c.0.count as i64 + k;
            m >= c.0.min as i64 && c.0.max.is_none_or(|x| m <= x as i64)
        })
    };
    let changes = |(by, taken): &(Vec<i64>, Vec<usize>)| {
        by.iter().map(|k| k.unsigned_abs()).sum::<u64>() + taken.len() as u64
    };
    let mut all: Vec<Vec<i64>> = vec![Vec::new()];
    for _ in 0..on.len() {
        all = (all.into_iter())
            .flat_map(|v| (-1..=1).map(move |k| [v.clone(), vec![k]].concat()))
            .collect();
    }
    // the pieces' states: for each turn they can add up to, the fewest changes that do
    let takes = piece_takes(asm, &others, unit);
    let mut all: Vec<(Vec<i64>, Vec<usize>)> = (all.into_iter())
        .flat_map(|by| takes.iter().map(move |t| (by.clone(), t.clone())))
        .collect();
    // a piece's other state with one turning chain taking up the rest of the turn, however
    // many elements that is (a bend of 45 degrees handed on as 20 and two more 15-degree
    // arc elements)
    for o in 0..others.len() {
        for i in 0..on.len() {
            let t = on[i].0;
            let turn = (std::f64::consts::TAU / t.theta.abs())
                .ceil()
                .min(WHOLE_TURN_MOST as f64);
            let by = |k: i64| -> Vec<i64> {
                (0..on.len()).map(|j| if j == i { k } else { 0 }).collect()
            };
            // among the counts the chain's rule allows: the nearest fit below its `min`
            // hid the whole turn more that fits within it
            let best = (-(t.count as i64)..=turn as i64)
                .map(|k| (by(k), vec![o]))
                .filter(|x| allowed(&x.0))
                .min_by(|x, y| {
                    (miss(x), changes(x))
                        .partial_cmp(&(miss(y), changes(y)))
                        .unwrap_or(Ordering::Equal)
                });
            all.extend(best);
        }
    }
    all.retain(|x| allowed(&x.0) && changes(x) >= 2);
    all.sort();
    all.dedup();
    // alike within ALIKE_TURN: a piece's bend read from nine digits is not an exact
    // multiple of an element's turn
    let least = all.iter().map(&miss).fold(f64::INFINITY, f64::min);
    let now = miss(&(vec![0; on.len()], Vec::new()));
    all.retain(|x| miss(x) <= least.min(now) + ALIKE_TURN);
    all.sort_by_key(changes);
    (all.iter().take(SPLIT_MOST))
        .map(|(by, taken)| {
            let counts = (on.iter().zip(by))
                .filter(|(_, k)| **k != 0)
                .map(|(c, &k)| (c.2, c.0.first, (c.0.count as i64 + k) as usize))
                .collect();
            let states = taken.iter().map(|&o| (others[o].0, others[o].1));
            (counts, states.collect())
        })
        .collect()
}

/// Most other piece states on one held path [`splits`] tries taking.
const SPLIT_STATES: usize = 64;

/// The other states `others` (`(instance, state, how much more it turns)`, each piece's
/// together) the pieces of a path can take, at most one each, as indices into `others`:
/// for each turn they add up to (alike within [`ALIKE_TURN`] of `unit`) and each change in
/// how many pieces are in which state, the [`TAKES_EACH`] with the fewest changes, at most
/// [`TAKES_MOST`] in all. The same states shared otherwise among the same pieces are left
/// to the tries (a bend handed to a neighbour, `trials.rs`). A street's three 15-degree bends
/// turn as one 45-degree bend does, three changes away (issue 46: led along the 45-degree
/// bend path it rested at strain 0.03 in three `l15`s).
fn piece_takes(asm: &Assembly, others: &[(usize, usize, f64)], unit: f64) -> Vec<Vec<usize>> {
    let instances = &asm.data().instances;
    let kind = |instance: usize, state: usize| (instances.get(instance).map(|x| x.piece), state);
    // how many pieces more (or fewer) are in each state, by piece: (piece, state, more)
    let net = |taken: &[usize]| {
        let mut more: Vec<((Option<usize>, usize), i64)> = Vec::new();
        for &o in taken {
            let (instance, state, _) = others[o];
            let now = instances.get(instance).map_or(usize::MAX, |x| x.state);
            for (k, by) in [(kind(instance, state), 1), (kind(instance, now), -1)] {
                match more.iter_mut().find(|m| m.0 == k) {
                    Some(m) => m.1 += by,
                    None => more.push((k, by)),
                }
            }
        }
        more.retain(|m| m.1 != 0);
        more.sort_unstable();
        more
    };
    let key = |sum: f64| (sum / unit / ALIKE_TURN).round() as i64;
    let mut found: Vec<(f64, Vec<usize>)> = vec![(0.0, Vec::new())];
    let mut i = 0;
    while i < others.len() {
        let instance = others[i].0;
        let n = others[i..].iter().take_while(|o| o.0 == instance).count();
        let mut next = found.clone();
        for (sum, taken) in &found {
            for (o, other) in others.iter().enumerate().skip(i).take(n) {
                next.push((sum + other.2, [taken.clone(), vec![o]].concat()));
            }
        }
        // fewest changes first: each turn's and state count's first TAKES_EACH stay
        next.sort_by_key(|(_, taken)| taken.len());
        let mut each: std::collections::HashMap<_, usize> = Default::default();
        next.retain(|(sum, taken)| {
            let seen = each.entry((key(*sum), net(taken))).or_default();
            *seen += 1;
            *seen <= TAKES_EACH
        });
        next.truncate(TAKES_MOST);
        found = next;
        i += n;
    }
    (found.into_iter())
        .map(|f| f.1)
        .filter(|taken| taken.is_empty() || !net(taken).is_empty())
        .collect()
}

/// Most assignments of a path's piece states [`piece_takes`] keeps for one turn.
const TAKES_EACH: usize = 4;

/// Most assignments of a path's piece states [`piece_takes`] keeps.
const TAKES_MOST: usize = 1024;

/// Most turning chains on one held path whose shares of its turn [`splits`] tries.
const SPLIT_CHAINS: usize = 4;

/// Most proposals [`splits`] makes for one path.
const SPLIT_MOST: usize = 4;

/// The count for turning chain `c` (`t`) held to a turn `off` (radians) from its rest
/// turn, as [`counts_from_turns`] says; `None` when none matches better than its own by the
/// `hysteresis` margin.
fn from_turn(c: usize, t: &ChainTurn, off: f64, hysteresis: f64) -> Option<(usize, usize, usize)> {
    let n = t.count;
    // how far `m` elements' turn is from the one held, in element turns
    let miss = |m: usize| wrap(off - (m as f64 - n as f64) * t.theta).abs() / t.theta.abs();
    // how far `m` elements' ends are apart at rest from how far they are in the pose
    let chord = |m: usize| t.chord(m).map_or(f64::INFINITY, |x| (x - t.span()).abs());
    // up to a whole turn more than it has (and twice its count), a whole turn being at most
    // WHOLE_TURN_MOST elements: with elements that turn by thousandths of a radian it is
    // hundreds, and a misfit the relaxation spread reads as one of them (a fuzzed grammar's
    // chain of 8 was proposed 172, and judging it took seconds)
    let turn = ((std::f64::consts::TAU / t.theta.abs()).ceil() as usize).min(WHOLE_TURN_MOST);
    let hi = t.max.unwrap_or(usize::MAX).min((2 * n).max(n + turn) + 2);
    let counts: Vec<usize> = (t.min..=hi).filter(|&m| m != n).collect();
    // counts a whole turn apart miss alike: the one whose ends are as far apart at rest
    // as in the pose among them, then the fewest elements (a whole loop more closes as
    // well, and no one wants it: a stadium's arcs grown by pass 1 during a slow pull
    // went on to 12 where 4 rest, 8 of them a loop). Alike within tolerances, not to the
    // last bit: an element's turn read from a grammar's nine digits is a whole turn in 36
    // only to 1e-7, and 41 ten-degree arcs, their chord carried through 39 steps, beat 5
    // by a rounding (generated morph case 3563 was proposed 41 where 5 rest)
    let best_miss = counts
        .iter()
        .map(|&m| miss(m))
        .fold(f64::INFINITY, f64::min);
    let near: Vec<usize> = (counts.iter().copied())
        .filter(|&m| miss(m) <= best_miss + ALIKE_TURN)
        .collect();
    let best_chord = near.iter().map(|&m| chord(m)).fold(f64::INFINITY, f64::min);
    let alike = ALIKE_CHORD * t.element_length();
    let best = (near.into_iter())
        .filter(|&m| chord(m) <= best_chord + alike)
        .min();
    // better than its own by the hysteresis margin, and not alike: a ring a hand moved by
    // centimetres misses by 1e-7 of a turn, and a whole turn more by less
    let better = |m: usize| miss(m) + ALIKE_TURN < (1.0 - hysteresis) * miss(n);
    let m = best.filter(|&m| better(m) && miss(m) < 0.5)?;
    Some((c, t.first, m))
}

/// The steps of the path between each two pieces the handles hold (of stable ids `held`,
/// chain elements aside), through the docks. The turns along a path add up to the turn
/// between its ends' holds, whatever free pieces lie between (a tree's hubs): what its
/// turning chains' counts and its pieces' states must match together (a path of pieces
/// alone too: a street of bendable segments held at both ends). The fewest instances' path
/// where several join the same two.
fn held_paths(data: &AssemblyData, held: &[u64]) -> Vec<Vec<Step>> {
    let chain_of = chain_of(data);
    // each instance's docked neighbours: (neighbour, own site, neighbour's site)
    let mut next = vec![Vec::new(); data.instances.len()];
    for d in &data.docks {
        if d.a.instance < next.len() && d.b.instance < next.len() {
            next[d.a.instance].push((d.b.instance, d.a.site, d.b.site));
            next[d.b.instance].push((d.a.instance, d.b.site, d.a.site));
        }
    }
    let ends: Vec<usize> = (data.instances.iter().enumerate())
        .filter(|(i, x)| held.contains(&x.id) && chain_of[*i].is_none())
        .map(|(i, _)| i)
        .collect();
    let mut paths = Vec::new();
    for (k, &from) in ends.iter().enumerate() {
        // breadth first from `from`: each instance's predecessor and the site it was
        // entered at
        let mut before = vec![None; data.instances.len()];
        before[from] = Some((from, usize::MAX));
        let mut queue = std::collections::VecDeque::from([from]);
        while let Some(i) = queue.pop_front() {
            for &(j, _, site) in &next[i] {
                if before[j].is_none() {
                    before[j] = Some((i, site));
                    queue.push_back(j);
                }
            }
        }
        for &to in &ends[k + 1..] {
            let mut walk = vec![(to, usize::MAX)];
            while let Some(last) = walk.last_mut().filter(|w| w.0 != from) {
                let Some((j, site)) = before[last.0] else {
                    break;
                };
                last.1 = site;
                walk.push((j, usize::MAX));
            }
            if walk.last().map(|w| w.0) != Some(from) {
                continue;
            }
            walk.reverse();
            // walk[x] = (instance, the site it was entered at); it leaves at the site
            // the next one was entered from
            let mut path: Vec<Step> = Vec::new();
            for (x, &(i, enter)) in walk.iter().enumerate().take(walk.len() - 1).skip(1) {
                match chain_of[i] {
                    Some(c) if matches!(path.last(), Some(Step::Chain(d, _)) if *d == c) => {}
                    Some(c) => {
                        let first = data.chains[c].instances.first() == Some(&i);
                        path.push(Step::Chain(c, if first { 1.0 } else { -1.0 }));
                    }
                    None => {
                        let after = walk[x + 1];
                        let leave = (next[i].iter())
                            .find(|n| n.0 == after.0 && n.2 == after.1)
                            .map(|n| n.1);
                        if let Some(leave) = leave {
                            path.push(Step::Piece {
                                instance: i,
                                enter,
                                leave,
                            });
                        }
                    }
                }
            }
            if !path.is_empty() {
                paths.push(path);
            }
        }
    }
    paths
}

/// Each other rest state of piece `instance`: `(instance, state, how much more it turns
/// from site `enter` to site `leave` than in its state now)` (radians).
fn piece_states(
    asm: &Assembly,
    (instance, enter, leave): (usize, usize, usize),
) -> Vec<(usize, usize, f64)> {
    let grammar = asm.grammar();
    let Some(x) = asm.data().instances.get(instance) else {
        return Vec::new();
    };
    let Some(piece) = grammar.pieces.get(x.piece) else {
        return Vec::new();
    };
    let turn = |state: usize| -> Option<f64> {
        let rest = &piece.states.get(state)?.positions;
        let angle = |site: usize| {
            let vs = &piece.sites.get(site)?.vertices;
            site_angle(&[*rest.get(*vs.first()?)?, *rest.get(*vs.last()?)?])
        };
        Some(angle(leave)? - angle(enter)?)
    };
    let Some(now) = turn(x.state) else {
        return Vec::new();
    };
    (0..piece.states.len())
        .filter(|&s| s != x.state)
        .filter_map(|s| Some((instance, s, wrap(turn(s)? - now))))
        .collect()
}

/// How far (radians) free piece `instance`'s turn from site `enter` to site `leave` is from
/// its rest state's in `pose`.
fn piece_off(
    grammar: &CompiledGrammar,
    data: &AssemblyData,
    pose: &[DVec2],
    (instance, enter, leave): (usize, usize, usize),
) -> Option<f64> {
    let x = data.instances.get(instance)?;
    let piece = grammar.pieces.get(x.piece)?;
    let rest = &piece.states.get(x.state)?.positions;
    let angles = |site: usize| -> Option<(f64, f64)> {
        let vs = &piece.sites.get(site)?.vertices;
        let at = |v: usize| Some((*rest.get(v)?, *pose.get(*x.vertices.get(v)?)?));
        let (a, b) = (at(*vs.first()?)?, at(*vs.last()?)?);
        Some((site_angle(&[a.0, b.0])?, site_angle(&[a.1, b.1])?))
    };
    let (e, l) = (angles(enter)?, angles(leave)?);
    Some(wrap((l.1 - e.1) - (l.0 - e.0)))
}

#[cfg(test)]
mod tests {
    use super::{counts_from_turns, wrap};
    use std::f64::consts::PI;

    #[test]
    fn a_chain_is_proposed_at_most_a_bounded_turn_more() {
        // the junction's stretch part with its `two` state bent (a fuzz find): its elements
        // turn by thousandths of a radian, and a whole turn more is hundreds of elements
        let json =
            include_str!("../../tests/fixtures/fuzz_finds/compiled/turns_of_a_bent_two_state.json");
        let grammar: clay_dsl::CompiledGrammar = serde_json::from_str(json).unwrap();
        let grammar = std::sync::Arc::new(grammar);
        let mut asm = crate::assembly::Assembly::new(grammar.clone());
        // the instance furthest east grabbed and dragged by (1, 0.5) over three frames
        let east = (0..asm.data().instances.len())
            .max_by(|&a, &b| {
                let x = |i| asm.instance_centroid(i).map_or(f64::NEG_INFINITY, |c| c.x);
                x(a).total_cmp(&x(b))
            })
            .unwrap();
        let grab = asm
            .hold_instance(east, crate::assembly::HandleKind::Grab)
            .unwrap();
        let mut solver =
            crate::solver::Solver::new(crate::solver::SolverConfig::from_params(&grammar.solver));
        for k in 1..=3 {
            let by = glam::DVec2::new(1.0, 0.5) * (k as f64 / 3.0);
            asm.move_handle(grab, by, 0.0);
            solver.frame(&mut asm).unwrap();
        }
        let pose = asm.data().positions.clone();
        let proposals = counts_from_turns(&asm, &pose, 0.15);
        for (chain, _, count) in proposals.into_iter().flat_map(|p| p.0) {
            let n = asm.data().chains[chain].instances.len();
            let most = (2 * n).max(n + super::WHOLE_TURN_MOST) + 2;
            assert!(count <= most, "chain {chain} of {n} proposed {count}");
        }
    }

    #[test]
    fn wrap_is_the_turn_to_the_nearest_whole_turn() {
        // callers read |wrap|: how far an angle is from a whole turn, either way
        assert!((wrap(3.0 * PI).abs() - PI).abs() < 1e-12);
        assert!((wrap(-PI).abs() - PI).abs() < 1e-12);
        assert!((wrap(0.25) - 0.25).abs() < 1e-12);
        assert!((wrap(2.0 * PI - 0.25) + 0.25).abs() < 1e-12);
        assert!((wrap(-7.0 * PI + 0.5) - (PI + 0.5 - 2.0 * PI)).abs() < 1e-12);
    }
}
