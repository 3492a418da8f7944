//! The smart-clay rules (paper 5.1): replacement, stretch/shrink, merge and cut, as pure
//! rewrites of `(&CompiledGrammar, &mut AssemblyData)` that each yield a [`RuleEvent`], and
//! [`Rules`], which runs them on a live [`Assembly`] after every solver frame.
//!
//! Every rewrite is a transaction: it either leaves an `AssemblyData` that passes
//! [`AssemblyData::check`](clay_dsl::compiled::AssemblyData::check) (with parts rebuilt from the grammar, untouched parts keeping their
//! active state, and untouched instances keeping their ids) or restores the data and returns
//! an error. Per-frame cost of finding rule applications is linear in the number of parts and
//! free sites; a rewrite itself costs O(instances + docks + vertices) and happens rarely.
//!
//! This file holds [`Rules`] and the order in which one frame's rules run. Each rule has its
//! file (`replace.rs`, `stretch.rs`, `merge.rs`, `cut.rs`; `proximity.rs` finds sites within
//! reach); what they share is in `rewrite.rs` (the events, [`Rewrite`], the transaction and
//! `finish` every rewrite leaves through) and `sites.rs` (where a site is and which way it
//! faces). The rule files import those siblings, never this file.

pub mod cut;
pub mod merge;
pub(crate) mod proximity;
pub mod replace;
mod rewrite;
mod sites;
pub mod stretch;

pub use rewrite::{Rewrite, RuleEvent, RuleKind};
pub use sites::site_centre;
// Only the tests read a site's outward direction (`clay::testing::site_out`).
#[cfg(any(test, feature = "testing"))]
pub use sites::site_out;

use std::collections::HashSet;

use clay_dsl::compiled::CompiledGrammar;
use glam::DVec2;

use crate::assembly::Assembly;
use crate::solver::{FrameReport, Judged, Proposal, StateSwitch};

/// Runs the rules on a live assembly after each solver frame, and the cut operation.
#[derive(Clone, Debug, Default)]
pub struct Rules {
    /// Frames seen so far (stamped on events).
    pub frame: u64,
    /// Every event so far, in order.
    pub log: Vec<RuleEvent>,
    /// Pairs of instances (stable ids, smaller first) a cut separated: they do not weld
    /// again until their sites have moved beyond the merge distance (paper 5.1: a
    /// connection is fixed until cut, and a cut is the user's explicit wish to part them).
    parted: Vec<(u64, u64)>,
}

fn unordered(a: u64, b: u64) -> (u64, u64) {
    (a.min(b), a.max(b))
}

/// Most rewrites of one chain that one relaxation proposal makes (each at most
/// `stretch::MAX_GROWTH` elements): a chain grows or shrinks to its proposed count in one stop
/// unless the proposal is more than about a thousand elements away.
const MAX_REWRITES_PER_PROPOSAL: usize = 16;

impl Rules {
    pub fn new() -> Self {
        Self::default()
    }

    /// Applies the rules after one solver frame ([`Rules::after_pass1`] with the frame's
    /// pass-1 pose `pass1`, then [`Rules::after_pass2`]): for tests that drive the rules
    /// around a frame of their own (feature `testing`).
    #[cfg(feature = "testing")]
    pub fn after_frame(
        &mut self,
        asm: &mut Assembly,
        report: &FrameReport,
        pass1: &[DVec2],
    ) -> Vec<RuleEvent> {
        let mut events = self.after_pass1(asm, report, pass1);
        events.extend(self.after_pass2(asm));
        events
    }

    /// The rules that decide the frame's topology, between the solver's passes (paper 5.2:
    /// pass 2 runs on the topology pass 1 determined): replacement events for the piece parts
    /// that switched state, and at most one stretch or shrink per chain (parts left in
    /// `three`/`one`, by their claims). Counts the frame. Bumps the assembly's generation if
    /// the structure changed, and carries rotations and handles across the renumbering.
    ///
    /// `pass1` is the frame's pass-1 pose (one position per vertex, or empty): a chain that
    /// stretches is laid out in it first. There the sparse norm has gathered the chain's
    /// stretch into the rewritten part and left the other elements at rest, so the elements
    /// the rule lays into that part's span come out at rest too; in the displayed pose, where
    /// least squares spreads the stretch over the whole chain, a part claiming many elements
    /// would have them squeezed into two elements' length. A chain that shrinks stays in the
    /// displayed pose: the sparse norm gathers a squeeze by folding the part onto itself, and
    /// the elements beyond the fold lie back over those before it.
    pub fn after_pass1(
        &mut self,
        asm: &mut Assembly,
        report: &FrameReport,
        pass1: &[DVec2],
    ) -> Vec<RuleEvent> {
        self.frame += 1;
        let grammar = asm.grammar_arc().clone();
        let mut events =
            replace::replacement_events(&grammar, asm.data_mut(), &report.switches, pass1);
        let mut rewrites = Vec::new();
        let held: HashSet<u64> = asm
            .handles()
            .iter()
            .filter_map(|h| h.held.as_ref().map(|x| x.id))
            .collect();
        let candidates = stretch::candidates(&grammar, asm.data());
        if pass1.len() == asm.data().positions.len() {
            let data = asm.data();
            let mut laid = Vec::new();
            let grows =
                |part: usize| data.parts.get(part).map(|p| p.active) == Some(stretch::THREE);
            for &(_, (chain, _)) in candidates.iter().filter(|c| grows(c.0)) {
                for &i in data.chains.get(chain).map_or(&[][..], |c| &c.instances) {
                    laid.extend(data.instances[i].vertices.iter().copied());
                }
            }
            let positions = asm.positions_mut();
            for v in laid {
                if pass1[v].is_finite() {
                    positions[v] = pass1[v];
                }
            }
        }
        for (part, at) in candidates {
            // Earlier rewrites in this loop never renumber chains, and elements only within
            // their own chain, so (chain, first) is still valid here; `part` indexes the
            // parts the frame ran on.
            let elements = report
                .claims
                .iter()
                .find(|c| c.0 == part)
                .map(|c| i64::from(c.1));
            let elements = elements.unwrap_or_else(|| {
                let active = asm.data().parts.get(part).map(|p| p.active);
                if active == Some(stretch::ONE) { 1 } else { 3 }
            });
            if let Ok(r) = stretch::rewrite_part(&grammar, asm.data_mut(), at, elements, &held) {
                self.carry(asm, &r);
                rewrites.push(r.event);
            }
        }
        events.extend(rewrites);
        self.stamp(&grammar, asm, events)
    }

    /// The rules that act on the displayed pose, after the solver's frame: at most one merge.
    pub fn after_pass2(&mut self, asm: &mut Assembly) -> Vec<RuleEvent> {
        let grammar = asm.grammar_arc().clone();
        let mut events = Vec::new();
        // a cut pair parts once no merge rule finds its sides within reach
        self.parted.retain(|&pair| {
            merge::find_in_reach(&grammar, asm.data(), |m, t| unordered(m, t) == pair).is_some()
        });
        let parted = &self.parted;
        if let Some(found) = merge::find_where(&grammar, asm.data(), |m, t| {
            !parted.contains(&unordered(m, t))
        }) && let Ok(r) = merge::apply(&grammar, asm.data_mut(), &found)
        {
            self.carry(asm, &r);
            events.push(r.event);
        }
        self.stamp(&grammar, asm, events)
    }

    /// Applies what the solver's relaxation proposed (a held model that stopped strained,
    /// `docs/solver.md`): the piece parts' states (replacement), then each chain's count (a
    /// stretch, at most doubling the chain a rewrite, or a shrink at the proposed part), laid
    /// out from `asm`'s positions. The events are not logged: the session keeps the result
    /// only if the model rests better with it ([`Rules::record`]).
    pub(crate) fn restructure(&self, asm: &mut Assembly, proposal: &Proposal) -> Vec<RuleEvent> {
        let grammar = asm.grammar_arc().clone();
        let held: HashSet<u64> = asm
            .handles()
            .iter()
            .filter_map(|h| h.held.as_ref().map(|x| x.id))
            .collect();
        let parts = &mut asm.data_mut().parts;
        let switches: Vec<StateSwitch> = (proposal.states.iter())
            .filter_map(|&(part, to)| {
                let p = parts.get_mut(part)?;
                let from = std::mem::replace(&mut p.active, to);
                // judged by energy, whose figures the session adds once it has them
                // (`Session::try_proposals`): not by shape, so no shape figure
                Some(StateSwitch {
                    part,
                    from,
                    to,
                    judged: Judged::Proposal,
                })
            })
            .collect();
        let mut events = replace::replacement_events(&grammar, asm.data_mut(), &switches, &[]);
        // rewrites until each chain has its count, at most `MAX_REWRITES_PER_PROPOSAL` per
        // chain (a stretch inserts at most `stretch::MAX_GROWTH`): a proposal made far from
        // the model's size cannot run away; the rest of such a change waits for the next stop
        for &(chain, first, count) in &proposal.counts {
            for _ in 0..MAX_REWRITES_PER_PROPOSAL {
                let Some(n) = asm.data().chains.get(chain).map(|c| c.instances.len()) else {
                    break;
                };
                let r = if count > n {
                    stretch::stretch(&grammar, asm.data_mut(), chain, first, 2 + count - n)
                } else if count < n {
                    let elements = 2 - (n - count) as i64;
                    stretch::shrink(&grammar, asm.data_mut(), chain, first, elements, &held)
                } else {
                    break;
                };
                let Ok(r) = r else { break };
                self.carry(asm, &r);
                events.push(r.event);
            }
        }
        events
    }

    /// Counts the frame's `events` made outside [`Rules::after_pass1`] and
    /// [`Rules::after_pass2`] ([`Rules::restructure`]'s, kept): stamped and logged.
    pub(crate) fn record(&mut self, asm: &Assembly, events: Vec<RuleEvent>) -> Vec<RuleEvent> {
        let grammar = asm.grammar_arc().clone();
        self.stamp(&grammar, asm, events)
    }

    /// Stamps `events` with the frame and logs them.
    fn stamp(
        &mut self,
        grammar: &CompiledGrammar,
        asm: &Assembly,
        mut events: Vec<RuleEvent>,
    ) -> Vec<RuleEvent> {
        for e in &mut events {
            e.frame = self.frame;
        }
        debug_assert!(
            asm.data().check(grammar).is_ok(),
            "{:?}",
            asm.data().check(grammar)
        );
        self.log.extend(events.iter().cloned());
        events
    }

    /// Cuts the dock nearest `point` (the cut rule's `cut_at`).
    pub fn cut(&mut self, asm: &mut Assembly, point: DVec2) -> Result<RuleEvent, String> {
        let grammar = asm.grammar_arc().clone();
        let r = cut::cut_at(&grammar, asm.data_mut(), point)?;
        // every pair among the instances on the cut's sides (its new instance included)
        let ids = &r.event.instances;
        for (k, &a) in ids.iter().enumerate() {
            for &b in &ids[k + 1..] {
                self.parted.push(unordered(a, b));
            }
        }
        self.carry(asm, &r);
        let mut e = r.event;
        e.frame = self.frame;
        self.log.push(e.clone());
        Ok(e)
    }

    /// Carries per-part rotations and handle vertices across a rewrite and bumps the
    /// assembly's generation.
    fn carry(&self, asm: &mut Assembly, r: &Rewrite) {
        let old_rot = asm.rotations().to_vec();
        for h in asm.handles_mut().iter_mut() {
            let mut vertices = Vec::with_capacity(h.vertices.len());
            let mut anchor = Vec::with_capacity(h.anchor.len());
            for (k, &v) in h.vertices.iter().enumerate() {
                if let Some(Some(nv)) = r.vertex_map.get(v) {
                    vertices.push(*nv);
                    anchor.push(h.anchor[k]);
                }
            }
            h.vertices = vertices;
            h.anchor = anchor;
        }
        asm.topology_changed();
        let rot = asm.rotations_mut();
        for (old, new) in r.part_map.iter().enumerate() {
            if let (Some(new), Some(&q)) = (new, old_rot.get(old))
                && let Some(slot) = rot.get_mut(*new)
            {
                *slot = q;
            }
        }
    }
}
