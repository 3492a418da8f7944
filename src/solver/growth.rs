//! One claim per chain per frame (paper 5.1): of a stretch chain's parts, at most one enters
//! `three` and at most one enters `one` in a frame. A part in `three` says "these two elements
//! span this many elements' length" (its claim); the stretch rule then inserts the difference,
//! and the shrink rule removes it for a part in `one`.
//!
//! When a chain is stretched evenly (least squares, p = 2), every part reaches the switching
//! stretch together and all would enter `three` at once: each then claims room on both sides,
//! the chain has room for far fewer, and the solve squeezes the parts still in `two` to keep
//! the claimed ones at rest. The rule would insert for every claim, and the chain would end
//! overfull and buckle (41 bricks in a 40 m wall pulled to 5x). So in a frame only the part
//! with the largest claim (the farthest from two elements; among equal claims, the one that
//! fits its state best) keeps its switch: the rest of the chain waits for the rewrite and the
//! solve after it, which is when the chain's length is known again. A claim made earlier in
//! the frame gives way to a larger one later (pass 1 gathers the deformation as it iterates:
//! the first part to pass the threshold is seldom where the whole of it ends up). Parts that
//! entered the state in earlier frames keep it (with the rules off, a chain may hold many
//! parts in `three`).
//!
//! A claim is sized by its chain's length ([`ChainLength`]: the chain measured in elements
//! at rest), which lives here, beside the rule it sizes, rather than in the solver's
//! `chains.rs` that measures it: the solver's state keeps the lengths between its steps,
//! and the state imports no job of the frame.

use std::collections::BTreeMap;

use clay_dsl::compiled::{Part, PartKind, STRETCH_ONE, STRETCH_THREE};
use glam::DVec2;

use super::report::{Judged, StateSwitch};

/// Keeps, for every chain and each of `three` and `one`, only the best of the parts that
/// entered that state during the frame and are still in it (see the module doc): `claims` and
/// `residuals` are this local step's, per part. The switches of this step
/// (`switches[from..]`) that lose are undone and leave the list; an earlier switch of the frame
/// that loses is undone by a switch back, appended. Returns whether any was undone (their
/// rotations and targets are then stale: the caller evaluates again keeping the states).
pub fn one_per_chain(
    parts: &mut [Part],
    switches: &mut Vec<StateSwitch>,
    from: usize,
    residuals: &[f64],
    claims: &[i32],
) -> bool {
    let claim = |parts: &[Part], s: &StateSwitch| match parts[s.part].kind {
        PartKind::Stretch { chain, .. }
            if (s.to == STRETCH_THREE || s.to == STRETCH_ONE) && parts[s.part].active == s.to =>
        {
            Some((chain, s.to))
        }
        _ => None,
    };
    if !switches[from..].iter().any(|s| claim(parts, s).is_some()) {
        return false;
    }
    // (chain, state) -> the standing claim: the most elements claimed (the farthest from
    // two), then the smaller residual, then the lower part index (deterministic)
    let rank = |part: usize| {
        let change = claims.get(part).map_or(1, |&c| (i64::from(c) - 2).abs());
        let r = residuals.get(part).copied().unwrap_or(f64::INFINITY);
        (-change, r, part)
    };
    let mut best: BTreeMap<(usize, usize), (i64, f64, usize)> = BTreeMap::new();
    for s in switches.iter() {
        let Some(key) = claim(parts, s) else { continue };
        let r = rank(s.part);
        let slot = best.entry(key).or_insert(r);
        if r.0 < slot.0 || (r.0 == slot.0 && (r.1 < slot.1 || (r.1 == slot.1 && r.2 < slot.2))) {
            *slot = r;
        }
    }
    let loses =
        |parts: &[Part], s: &StateSwitch| claim(parts, s).is_some_and(|key| best[&key].2 != s.part);
    // earlier switches that lose are switched back (in the order of their first switch);
    // a part that also switched in this step is undone with this step's switches below
    let mut back = Vec::new();
    let now: Vec<usize> = switches[from..].iter().map(|s| s.part).collect();
    for s in &switches[..from] {
        if loses(parts, s)
            && !now.contains(&s.part)
            && !back.iter().any(|b: &StateSwitch| b.part == s.part)
        {
            back.push(StateSwitch {
                part: s.part,
                from: s.to,
                to: s.from,
                judged: Judged::Shape,
            });
        }
    }
    // this step's switches that lose never happened
    let before = switches.len();
    let mut k = 0;
    let mut undone = Vec::new();
    switches.retain(|s| {
        k += 1;
        if k <= from || !loses(parts, s) {
            return true;
        }
        undone.push((s.part, s.from));
        false
    });
    for (part, state) in undone {
        parts[part].active = state;
    }
    for b in &back {
        parts[b.part].active = b.to;
    }
    let changed = switches.len() != before || !back.is_empty();
    switches.extend(back);
    changed
}

/// A stretch chain measured in a pose, in elements at rest
/// ([`Solver::chain_lengths`](super::state::Solver::chain_lengths)).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct ChainLength {
    /// Along the chain: its elements' lengths summed.
    pub(super) path: f64,
    /// Straight from its first element's `from` site to its last element's `to` site.
    pub(super) chord: f64,
    /// Where the chain starts (its first element's `from` site's centre).
    pub(super) near: DVec2,
    /// Where the chain ends (its last element's `to` site's centre).
    pub(super) far: DVec2,
    /// An element's length at rest (the unit of `path` and `chord`).
    pub(super) element: f64,
}

impl ChainLength {
    /// The shortest the chain could be through what holds it, in elements: the polyline
    /// from its near end through the centres of its held elements (`held`, in chain order,
    /// positions in the measured pose) to its far end; its chord when none is held. A chain
    /// no longer than this at rest needs no element more, however its path wanders.
    pub(super) fn taut(&self, held: impl IntoIterator<Item = DVec2>) -> f64 {
        let mut at = self.near;
        let mut length = 0.0;
        for p in held {
            length += (p - at).length();
            at = p;
        }
        length += (self.far - at).length();
        length / self.element.max(1e-12)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clay_dsl::compiled::STRETCH_TWO;

    fn chain_parts(n: usize) -> Vec<Part> {
        (0..n)
            .map(|first| Part {
                kind: PartKind::Stretch { chain: 0, first },
                vertices: Vec::new(),
                edges: Vec::new(),
                states: Vec::new(),
                active: STRETCH_TWO,
            })
            .collect()
    }

    fn switch_all(parts: &mut [Part], to: usize) -> Vec<StateSwitch> {
        parts
            .iter_mut()
            .enumerate()
            .map(|(part, p)| {
                p.active = to;
                StateSwitch {
                    part,
                    from: STRETCH_TWO,
                    to,
                    judged: Judged::Shape,
                }
            })
            .collect()
    }

    fn active(parts: &[Part]) -> Vec<usize> {
        parts.iter().map(|p| p.active).collect()
    }

    #[test]
    fn only_the_best_fitting_part_of_an_evenly_claiming_chain_grows() {
        let mut parts = chain_parts(4);
        let mut switches = switch_all(&mut parts, STRETCH_THREE);
        let residuals = [0.3, 0.1, 0.2, 0.1];
        assert!(one_per_chain(
            &mut parts,
            &mut switches,
            0,
            &residuals,
            &[3; 4]
        ));
        assert_eq!(
            active(&parts),
            [STRETCH_TWO, STRETCH_THREE, STRETCH_TWO, STRETCH_TWO]
        );
        assert_eq!(switches.len(), 1);
        assert_eq!(switches[0].part, 1);
    }

    #[test]
    fn the_largest_claim_stands() {
        let mut parts = chain_parts(3);
        let mut switches = switch_all(&mut parts, STRETCH_THREE);
        // part 2 claims 7 elements: it stands although it fits its state worst
        let residuals = [0.1, 0.1, 5.0];
        assert!(one_per_chain(
            &mut parts,
            &mut switches,
            0,
            &residuals,
            &[3, 4, 7]
        ));
        assert_eq!(active(&parts), [STRETCH_TWO, STRETCH_TWO, STRETCH_THREE]);
    }

    #[test]
    fn an_earlier_claim_gives_way_to_a_larger_one_and_chains_are_apart() {
        let mut parts = chain_parts(3);
        parts[2].kind = PartKind::Stretch { chain: 1, first: 0 };
        for p in &mut parts {
            p.active = STRETCH_THREE;
        }
        let switch = |part| StateSwitch {
            part,
            from: STRETCH_TWO,
            to: STRETCH_THREE,
            judged: Judged::Shape,
        };
        // part 0 switched in an earlier iteration of the frame and now claims 3; part 1
        // claims 5 in this step: part 0 switches back
        let mut switches = vec![switch(0), switch(1), switch(2)];
        assert!(one_per_chain(
            &mut parts,
            &mut switches,
            1,
            &[0.0; 3],
            &[3, 5, 3]
        ));
        assert_eq!(active(&parts), [STRETCH_TWO, STRETCH_THREE, STRETCH_THREE]);
        let left: Vec<(usize, usize)> = switches.iter().map(|s| (s.part, s.to)).collect();
        assert_eq!(
            left,
            [
                (0, STRETCH_THREE),
                (1, STRETCH_THREE),
                (2, STRETCH_THREE),
                (0, STRETCH_TWO)
            ]
        );
    }

    #[test]
    fn an_earlier_claim_as_large_holds_the_chain() {
        let mut parts = chain_parts(2);
        for p in &mut parts {
            p.active = STRETCH_THREE;
        }
        let switch = |part| StateSwitch {
            part,
            from: STRETCH_TWO,
            to: STRETCH_THREE,
            judged: Judged::Shape,
        };
        let mut switches = vec![switch(0), switch(1)];
        assert!(one_per_chain(
            &mut parts,
            &mut switches,
            1,
            &[0.0, 0.0],
            &[3, 3]
        ));
        assert_eq!(active(&parts), [STRETCH_THREE, STRETCH_TWO]);
        assert_eq!(switches.len(), 1);
    }

    #[test]
    fn parts_grown_in_earlier_frames_do_not_hold_the_chain() {
        let mut parts = chain_parts(3);
        parts[0].active = STRETCH_THREE;
        parts[2].active = STRETCH_THREE;
        let mut switches = vec![StateSwitch {
            part: 2,
            from: STRETCH_TWO,
            to: STRETCH_THREE,
            judged: Judged::Shape,
        }];
        assert!(!one_per_chain(
            &mut parts,
            &mut switches,
            0,
            &[0.0, 0.0, 0.1],
            &[3; 3]
        ));
        assert_eq!(parts[2].active, STRETCH_THREE);
    }

    #[test]
    fn a_chain_may_grow_at_one_end_and_shrink_at_the_other() {
        let mut parts = chain_parts(2);
        parts[0].active = STRETCH_ONE;
        parts[1].active = STRETCH_THREE;
        let mut switches = vec![
            StateSwitch {
                part: 0,
                from: STRETCH_TWO,
                to: STRETCH_ONE,
                judged: Judged::Shape,
            },
            StateSwitch {
                part: 1,
                from: STRETCH_TWO,
                to: STRETCH_THREE,
                judged: Judged::Shape,
            },
        ];
        assert!(!one_per_chain(
            &mut parts,
            &mut switches,
            0,
            &[0.1, 0.1],
            &[1, 3]
        ));
        assert_eq!(switches.len(), 2);
    }
}
