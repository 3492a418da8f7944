//! One growth per chain per frame (paper 5.1): of a stretch chain's parts, at most one
//! switches into `three` and at most one into `one` in a frame. A part in `three` says "these
//! two elements hold a third element's length"; the stretch rule then inserts one element per
//! chain per frame.
//! When a chain is stretched evenly (least squares, p = 2), every part reaches the switching
//! stretch together and all would enter `three` at once: each then claims an extra half
//! element on both sides, the chain has room for far fewer, and the solve squeezes the parts
//! still in `two` to keep the claimed ones at rest. The rule then inserts one element for
//! every claimed pair, and the chain ends overfull and buckles (41 bricks in a 40 m wall
//! pulled to 5x). So in a frame a switch into `three` (`one`) is kept only for the part that
//! fits that state best: the rest of the chain waits for the rewrite and the solve after it,
//! which is when the chain's length is known again. Parts that entered the state in earlier
//! frames keep it (with the rules off, a chain may hold many parts in `three`).

use std::collections::BTreeMap;

use clay_dsl::compiled::{Part, PartKind, STRETCH_ONE, STRETCH_THREE};

use super::StateSwitch;

/// Undoes the switches in `switches[from..]` (this local step's; `switches[..from]` are the
/// frame's earlier ones) that would let a chain claim a second element in one frame (see the
/// module doc): among a chain's new switches into `three` (or `one`), the part with the
/// smallest squared stacked residual in it (`residuals`, per part) keeps its switch, unless
/// an earlier step of the frame already switched a part of the chain into that state. The
/// reverted parts get their previous state back and their entries leave `switches`. Returns
/// whether any was reverted (their rotations and targets are then stale: the caller
/// evaluates again keeping the states).
pub fn one_per_chain(
    parts: &mut [Part],
    switches: &mut Vec<StateSwitch>,
    from: usize,
    residuals: &[f64],
) -> bool {
    let growth = |state: usize| state == STRETCH_THREE || state == STRETCH_ONE;
    let chain_of = |part: &Part| match part.kind {
        PartKind::Stretch { chain, .. } => Some(chain),
        PartKind::Piece { .. } => None,
    };
    let claim = |s: &StateSwitch| {
        chain_of(&parts[s.part])
            .filter(|_| growth(s.to))
            .map(|chain| (chain, s.to))
    };
    if !switches[from..].iter().any(|s| claim(s).is_some()) {
        return false;
    }
    // (chain, state) -> the part whose claim stands (`None`: claimed earlier this frame);
    // ties go to the lower part index, so the choice is deterministic
    let mut keep: BTreeMap<(usize, usize), Option<(f64, usize)>> = BTreeMap::new();
    for s in &switches[..from] {
        if let Some(key) = claim(s) {
            keep.insert(key, None);
        }
    }
    for s in &switches[from..] {
        let Some(key) = claim(s) else { continue };
        let r = residuals.get(s.part).copied().unwrap_or(f64::INFINITY);
        let slot = keep.entry(key).or_insert(Some((r, s.part)));
        if let Some(best) = slot
            && r < best.0
        {
            *best = (r, s.part);
        }
    }
    let stands: Vec<bool> = switches[from..]
        .iter()
        .map(|s| claim(s).is_none_or(|key| keep[&key].is_some_and(|(_, p)| p == s.part)))
        .collect();
    let before = switches.len();
    let mut stands = stands.into_iter();
    let mut k = 0;
    switches.retain(|s| {
        k += 1;
        if k <= from || stands.next() == Some(true) {
            return true;
        }
        parts[s.part].active = s.from;
        false
    });
    switches.len() != before
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
                }
            })
            .collect()
    }

    #[test]
    fn only_the_best_fitting_part_of_a_chain_grows() {
        let mut parts = chain_parts(4);
        let mut switches = switch_all(&mut parts, STRETCH_THREE);
        assert!(one_per_chain(
            &mut parts,
            &mut switches,
            0,
            &[0.3, 0.1, 0.2, 0.1]
        ));
        let active: Vec<usize> = parts.iter().map(|p| p.active).collect();
        assert_eq!(
            active,
            [STRETCH_TWO, STRETCH_THREE, STRETCH_TWO, STRETCH_TWO]
        );
        assert_eq!(switches.len(), 1);
        assert_eq!(switches[0].part, 1);
    }

    #[test]
    fn a_claim_earlier_in_the_frame_holds_the_chain_and_chains_are_apart() {
        let mut parts = chain_parts(3);
        parts[2].kind = PartKind::Stretch { chain: 1, first: 0 };
        for p in &mut parts {
            p.active = STRETCH_THREE;
        }
        let switch = |part| StateSwitch {
            part,
            from: STRETCH_TWO,
            to: STRETCH_THREE,
        };
        // part 0 switched in an earlier iteration of the frame
        let mut switches = vec![switch(0), switch(1), switch(2)];
        assert!(one_per_chain(
            &mut parts,
            &mut switches,
            1,
            &[0.5, 0.0, 0.0]
        ));
        let active: Vec<usize> = parts.iter().map(|p| p.active).collect();
        assert_eq!(active, [STRETCH_THREE, STRETCH_TWO, STRETCH_THREE]);
        let left: Vec<usize> = switches.iter().map(|s| s.part).collect();
        assert_eq!(left, [0, 2]);
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
        }];
        assert!(!one_per_chain(
            &mut parts,
            &mut switches,
            0,
            &[0.0, 0.0, 0.1]
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
            },
            StateSwitch {
                part: 1,
                from: STRETCH_TWO,
                to: STRETCH_THREE,
            },
        ];
        assert!(!one_per_chain(&mut parts, &mut switches, 0, &[0.1, 0.1]));
        assert_eq!(switches.len(), 2);
    }
}
