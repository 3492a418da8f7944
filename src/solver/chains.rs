//! The stretch chains as the frame sees them (paper 5.1): each chain's length in elements
//! where pass 1 starts ([`ChainLength`]) and its chord at rest, each stretch part's context
//! for the switching local steps (the direction it is measured along, the states its chain's
//! rule can honour now), and the claims pass 1 leaves, sized by the chains' lengths.
//!
//! A file of its own because the chains are a job of their own, read at two steps of the
//! frame (pass 1's start and the claims after it): an `impl Solver` block over the state of
//! `state.rs`, imported from that sibling rather than from `mod.rs`, so no child imports its
//! parent.

use clay_dsl::compiled::PartKind;
use glam::DVec2;

use super::growth::ChainLength;
use super::report::FrameReport;
use super::state::Solver;
use super::{layout, local, turns};
use crate::assembly::Assembly;

impl Solver {
    /// The claims of the stretch parts pass 1 left in `three` or `one`
    /// ([`FrameReport::claims`]). With a sub-L1 norm they are sized by their chains' lengths
    /// where pass 1 started (`work.chain_lengths`): the part's own claim says where the chain
    /// grows or shrinks, the chain's length (its elements' lengths summed along its
    /// direction) how many elements it gains or loses. The sparse pass gathers a fast
    /// gesture's change of length into one part only as far as its iterations got, and a part
    /// claiming too few would leave the rest to the displayed pose: a chain squeezed in one
    /// frame to a third of its length then buckles before the rules catch up. With p >= 1
    /// nothing gathers: a part claims one element (the paper's rule).
    pub(super) fn collect_claims(&self, asm: &Assembly, report: &mut FrameReport) {
        use clay_dsl::compiled::{STRETCH_ONE, STRETCH_THREE};
        let parts = &asm.data().parts;
        let claims = &self.work.pass1_claims;
        let standing: Vec<(usize, usize, i32)> = (parts.iter().enumerate())
            .filter_map(|(pi, part)| {
                let PartKind::Stretch { chain, .. } = part.kind else {
                    return None;
                };
                let claim = claims.get(pi).copied();
                match part.active {
                    STRETCH_THREE => Some((pi, chain, claim.unwrap_or(3).max(3))),
                    STRETCH_ONE => Some((pi, chain, claim.unwrap_or(1).min(1))),
                    _ => None,
                }
            })
            .collect();
        if standing.is_empty() {
            return;
        }
        let lengths = &self.work.chain_lengths;
        // only a sub-L1 norm gathers: with p >= 1 every part holds a share of the chain's
        // change of length, and a part claims one element at a time (paper 5.2)
        let gathers = self.config.norm < 1.0;
        for (pi, chain, claim) in standing {
            let count = asm
                .data()
                .chains
                .get(chain)
                .map_or(0, |c| c.instances.len()) as f64;
            let length = lengths.get(chain).copied().flatten().filter(|_| gathers);
            let limit = f64::from(local::MAX_CLAIM);
            let claim = match length {
                // a chain grows by what its ends are apart beyond its elements, too: a slack
                // (buckled) chain pulled straightens before it stretches
                Some(l) if claim >= 3 && l.path.round() - count >= 1.0 => {
                    let grow = (l.path.round() - count).min((l.chord.round() - count).max(1.0));
                    2 + grow.min(limit) as i32
                }
                Some(l) if claim <= 1 && l.path.round() - count <= -1.0 => {
                    2 + (l.path.round() - count).max(-limit) as i32
                }
                _ if claim >= 3 => 3,
                _ => 1,
            };
            report.claims.push((pi, claim));
        }
    }

    /// Per chain, at `pose` ([`ChainLength`]): every element's span from its `from` site to
    /// its `to` site along its part's direction (`work.kept_rotations`), summed, and the
    /// straight distance between the chain's ends. `None` for a chain some part of which
    /// cannot be measured.
    fn chain_lengths(&self, asm: &Assembly, pose: &[DVec2]) -> Vec<Option<ChainLength>> {
        let data = asm.data();
        let mut lengths = vec![Some(ChainLength::default()); data.chains.len()];
        let w = &self.work;
        for (pi, part) in data.parts.iter().enumerate() {
            let PartKind::Stretch { chain, first } = part.kind else {
                continue;
            };
            let Some(slot) = lengths.get_mut(chain) else {
                continue;
            };
            let count = data.chains[chain].instances.len();
            let measured = match (&w.rest, w.kept_rotations.get(pi)) {
                (Some(cache), Some(&r)) => cache.measure_stretch(pi, part, pose, r),
                _ => None,
            };
            let (Some(length), Some(m)) = (slot.as_mut(), measured) else {
                *slot = None;
                continue;
            };
            // each element counted once: as its part's first, and the last as the second
            length.path += m.lengths[0];
            if first == 0 {
                length.near = m.near;
            }
            if first + 2 == count {
                length.path += m.lengths[1];
                length.chord = (m.far - length.near).length() / m.element;
                length.far = m.far;
                length.element = m.element;
            }
        }
        lengths
    }

    /// Every stretch part's context for this frame ([`local::StretchContext`]): its rotation
    /// at the displayed pose `warm` (`work.kept_rotations`, from [`Solver::start_at`] or the
    /// last frame), and the states the stretch rule can honour: `three` below the rule's
    /// `max`, `one` above its `min` unless both elements are held (a shrink would remove one).
    /// A chain claims elements only in the direction its length has moved: `three` only
    /// while it is longer than its elements at rest, `one` only while it is shorter, judged
    /// by its length in `start` (pass 1's first pose: the displayed one with the handles' new
    /// step; [`Solver::chain_lengths`], kept in `work.chain_lengths` to size the claims). The
    /// sparse pass gathers the change into a few parts, and a chain squeezed below its `min`
    /// folds, where a part beside a fold may span more than two elements though the chain as a
    /// whole is short.
    pub(super) fn stretch_contexts(&mut self, asm: &Assembly, start: &[DVec2]) {
        use clay_dsl::compiled::{STRETCH_ONE, STRETCH_THREE, STRETCH_TWO};
        let data = asm.data();
        let grammar = asm.grammar();
        self.work.stretch.clear();
        if !data
            .parts
            .iter()
            .any(|p| matches!(p.kind, PartKind::Stretch { .. }))
        {
            return;
        }
        let lengths = self.chain_lengths(asm, start);
        let rest_chords = self.rest_chords(asm, start, &lengths);
        let reversal = self.config.reversal;
        // per stretch rule: whether its chain runs straight (else an arc, counted by its turn)
        let straight: Vec<bool> = (grammar.stretch_rules.iter())
            .map(turns::chain_is_straight)
            .collect();
        let w = &mut self.work;
        let held_ids: Vec<u64> = asm
            .handles()
            .iter()
            .filter_map(|h| h.held.as_ref().map(|x| x.id))
            .collect();
        let held = |instance: usize| {
            data.instances
                .get(instance)
                .is_some_and(|i| held_ids.contains(&i.id))
        };
        // per chain: `None` when its ends are further apart than at rest by half an element
        // (taut), else whether what holds it stretches it half an element beyond its count
        let slack: Vec<Option<bool>> = (0..data.chains.len())
            .map(|chain| {
                let l = lengths.get(chain).copied().flatten()?;
                let rest = rest_chords.get(chain).copied().flatten()?;
                (l.chord < rest + 0.5).then(|| {
                    let c = &data.chains[chain];
                    let centres = c.instances.iter().filter(|&&i| held(i)).map(|&i| {
                        let vs = &data.instances[i].vertices;
                        vs.iter().map(|&v| start[v]).sum::<DVec2>() / vs.len().max(1) as f64
                    });
                    l.taut(centres) >= c.instances.len() as f64 + 0.5
                })
            })
            .collect();
        for (pi, part) in data.parts.iter().enumerate() {
            let PartKind::Stretch { chain, first } = part.kind else {
                w.stretch.push(None);
                continue;
            };
            let (Some(c), Some(&reference)) = (data.chains.get(chain), w.kept_rotations.get(pi))
            else {
                w.stretch.push(None);
                continue;
            };
            let Some(rule) = grammar.stretch_rules.get(c.rule) else {
                w.stretch.push(None);
                continue;
            };
            let count = c.instances.len();
            let both_held = [first, first + 1]
                .iter()
                .all(|&k| c.instances.get(k).is_some_and(|&i| held(i)));
            let length = (lengths.get(chain).copied().flatten()).map_or(count as f64, |l| l.path);
            // a change that reverses the chain's last one waits for `reversal` elements
            let shrink_below = count as f64 - if c.trend > 0 { reversal } else { 0.0 };
            // Against the chain's chord at rest (in elements): ends no further apart than at
            // rest (a chain pulled straight after a buckle, a squeeze let go of, a wave a
            // rewrite left) leave no room for an element, however far its path wanders, unless
            // something holds it out of line ([`ChainLength::taut`]); and then it grows only
            // once its elements span a whole element more than it has.
            let slack = slack.get(chain).copied().flatten();
            let (slack, held_out) = (slack.is_some(), slack == Some(true));
            let wait = match (c.trend < 0, slack) {
                (true, _) => reversal,
                (false, true) => 1.0,
                (false, false) => 0.0,
            };
            let grow_above = count as f64 + wait;
            let mut allowed = 1 << STRETCH_TWO;
            if !straight.get(c.rule).copied().unwrap_or(true) {
                // a chain of turning elements (an arc) is counted by its turn, in the
                // relaxation (`turns.rs`), not by its length: pulled straighter, its elements
                // stretch, and one inserted turns the arc further where the holds keep its
                // turn (a ring of two hubs pulled out over 240 frames curled an arc a whole
                // turn more, 4 elements to 12, at rest; over 30, it kept 4)
                w.stretch
                    .push(Some(local::StretchContext { reference, allowed }));
                continue;
            }
            if count > rule.min.max(1) && !both_held && length <= shrink_below {
                allowed |= 1 << STRETCH_ONE;
            }
            if rule.max.is_none_or(|max| count < max)
                && length >= grow_above
                && (!slack || held_out)
            {
                allowed |= 1 << STRETCH_THREE;
            }
            w.stretch
                .push(Some(local::StretchContext { reference, allowed }));
        }
        w.chain_lengths = lengths;
    }

    /// Per chain, its chord in the rest layout ([`layout::rest_layout`], in elements) where a
    /// stretch could be in question (its elements span at least its count) while its ends are
    /// not half an element further apart than a straight chain's (no chord at rest is longer):
    /// `None` for the others, which are taut.
    fn rest_chords(
        &self,
        asm: &Assembly,
        pose: &[DVec2],
        lengths: &[Option<ChainLength>],
    ) -> Vec<Option<f64>> {
        let chains = &asm.data().chains;
        let asked = |c: usize| {
            let count = chains[c].instances.len() as f64;
            lengths[c].is_some_and(|l| l.path >= count && l.chord < count + 0.5)
        };
        if !(0..chains.len().min(lengths.len())).any(asked) {
            return vec![None; chains.len()];
        }
        let w = &self.work;
        let laid = layout::rest_layout(
            &asm.data().parts,
            &w.vertex_parts,
            &self.components,
            pose,
            &[],
            &[],
        );
        let at_rest = self.chain_lengths(asm, &laid);
        (0..chains.len())
            .map(|c| {
                let asked = c < lengths.len() && asked(c);
                asked.then(|| at_rest.get(c).copied().flatten().map(|l| l.chord))?
            })
            .collect()
    }
}
