//! A sculpting session: the solver, the rules, the grab and what the session has done so far.
//! [`Session::frame`] is the one definition of a sculpting frame (a solver frame, then the
//! rules, paper 5.1) and of what counts as a rule event; `clayc run` (through [`replay`] and
//! [`Session::step`]), `clayc bench` and the editor all sculpt through it.
//!
//! The assembly is passed in rather than owned: the editor solves a spare copy of its model
//! on another thread while it draws the one on screen, and swaps them when the frame is done.
//!
//! Architecture Invariant: nothing outside this module runs the rules after a solver frame
//! (checked by `cli/tests/session.rs`: `clayc run`'s counts equal the session's events).

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use clay_dsl::compiled::PartKind;
use glam::DVec2;

pub mod file;
mod gesture;
mod settings;

pub use gesture::{Grab, pin, pin_at, pin_of, toggle_pin, unpin};
pub use settings::{SETTING_NAMES, configure};
// Only the tests set one setting by name (`clay::testing::apply_setting`).
#[cfg(any(test, feature = "testing"))]
pub use settings::apply_setting;

use crate::assembly::{Assembly, HandleId};
use crate::figure::rests_better;
use crate::rules::cut::CUT_REACH;
use crate::rules::{RuleEvent, RuleKind, Rules, replace};
use crate::script::{Motion, Script, Selector, Step};
use crate::solver::{FrameReport, Solver, SolverConfig, SolverError, Stop};
use crate::summary::{Summary, summarize};

/// What one sculpting frame did.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub report: FrameReport,
    /// The rules that fired after it, in order: one `replace` per instance whose rest state
    /// changed in the frame, then stretches and shrinks, then at most one merge.
    pub events: Vec<RuleEvent>,
}

/// Why a part is in the rest state it is in (the editor's inspector shows this): what the
/// solver's state choice compares.
#[derive(Clone, Debug, PartialEq)]
pub struct PartReport {
    pub part: usize,
    /// The active state's index in `states`.
    pub active: usize,
    /// Every rest state's name with the distance the state choice compares to the current
    /// pose: the squared shape-space distance (a piece part's over the vertices it shares
    /// with other parts, a stretch part's in its chain's frame), or for a piece judged by the
    /// turn between its sites (`turns`), the squared difference of the turns in radians.
    pub states: Vec<(String, f64)>,
    /// For a piece judged by the turn between its two docking sites: that turn in the pose
    /// and each state's, in degrees from the first state's.
    pub turns: Option<(f64, Vec<f64>)>,
    /// Per rest state: whether it may become active now (a stretch part's `one` at its
    /// chain's `min`, say, may not).
    pub available: Vec<bool>,
    /// For a stretch part: the state its length calls for, and its length in elements.
    pub candidate: Option<(usize, f64)>,
    pub hysteresis: f64,
    /// Another state becomes active once its distance drops below this (paper 4.3's
    /// hysteresis: `(1 - hysteresis)` times the active state's distance).
    pub switch_below: f64,
    /// Whether the part rests in its active state: its distance to it is within a millionth
    /// of the part's size squared (a part may also hold still under strain, held by handles
    /// or its neighbours).
    pub at_rest: bool,
}

/// A sculpting session over an assembly.
#[derive(Debug)]
pub struct Session {
    solver: Solver,
    /// `None`: a solver-only session (tests, benchmarks of the solver alone). Replacement
    /// still happens (it is the solver's state choice shown on the instances).
    rules: Option<Rules>,
    /// The grab `drag`, `rotate` and `release` act on.
    grab: Option<Grab>,
    rules_fired: BTreeMap<RuleKind, usize>,
    /// Wall time of every frame so far (solver and rules), in milliseconds.
    frame_ms: Vec<f64>,
    /// Remarks about steps and requests that did nothing, in order.
    notes: Vec<String>,
    last_report: Option<FrameReport>,
    /// Where the next [`Session::frame`]'s passes stop: a script's `budget` step replays a
    /// frame an editor's time budget stopped ([`Stop::After`]); never, else.
    next_stop: Stop,
}

impl Session {
    /// A session with the grammar's rules.
    pub fn new(config: SolverConfig) -> Self {
        Self::with(config, Some(Rules::new()))
    }

    /// A session without stretch, shrink, merge and cut rules.
    pub fn without_rules(config: SolverConfig) -> Self {
        Self::with(config, None)
    }

    fn with(config: SolverConfig, rules: Option<Rules>) -> Self {
        Self {
            solver: Solver::new(config),
            rules,
            grab: None,
            rules_fired: RuleKind::ALL.iter().map(|&k| (k, 0)).collect(),
            frame_ms: Vec::new(),
            notes: Vec::new(),
            last_report: None,
            next_stop: Stop::Never,
        }
    }

    pub fn config(&self) -> SolverConfig {
        self.solver.config
    }

    /// New solver settings, from the next frame on.
    pub fn set_config(&mut self, config: SolverConfig) {
        self.solver.config = config;
    }

    /// A fresh solver (after the model was replaced by one of another topology).
    pub fn reset_solver(&mut self) {
        self.solver = Solver::new(self.solver.config);
    }

    pub fn solver(&self) -> &Solver {
        &self.solver
    }

    /// The rules, for tests that drive them directly between frames (feature `testing`).
    #[cfg(feature = "testing")]
    pub fn rules_mut(&mut self) -> Option<&mut Rules> {
        self.rules.as_mut()
    }

    /// Rules fired so far, per kind (every kind present).
    pub fn rules_fired(&self) -> &BTreeMap<RuleKind, usize> {
        &self.rules_fired
    }

    pub fn frame_ms(&self) -> &[f64] {
        &self.frame_ms
    }

    /// Why requests did nothing (a grab that found no instance, a cut with nothing near).
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    pub fn last_report(&self) -> Option<&FrameReport> {
        self.last_report.as_ref()
    }

    /// Every rule event so far, in order (empty without rules).
    pub fn rule_log(&self) -> &[RuleEvent] {
        self.rules.as_ref().map_or(&[], |r| &r.log)
    }

    /// Forgets the rule log (a long live session keeps its own, bounded one).
    pub fn clear_rule_log(&mut self) {
        if let Some(r) = &mut self.rules {
            r.log.clear();
        }
    }

    /// The grabbed handle.
    pub fn grabbed(&self) -> Option<HandleId> {
        self.grab.map(|g| g.handle())
    }

    /// One sculpting frame: a solver frame, then the rules (its passes stopped where a
    /// script's `budget` step just before it says, if one did).
    pub fn frame(&mut self, asm: &mut Assembly) -> Result<Frame, SolverError> {
        let stop = std::mem::take(&mut self.next_stop);
        self.run_frame(asm, stop)
    }

    /// One sculpting frame whose solver part stops within `budget` (it continues next frame;
    /// see [`Solver::frame_budgeted`]).
    pub fn frame_within(
        &mut self,
        asm: &mut Assembly,
        budget: Duration,
    ) -> Result<Frame, SolverError> {
        self.run_frame(asm, Stop::within(budget))
    }

    fn run_frame(&mut self, asm: &mut Assembly, stop: Stop) -> Result<Frame, SolverError> {
        let start = Instant::now();
        let mut events = Vec::new();
        // Paper 5.2: pass 1 decides the topology, the rules that change it run, and pass 2
        // solves the new structure for display; merges act on the displayed pose after it.
        let rules = &mut self.rules;
        let report = self
            .solver
            .frame_with(asm, stop, &mut |asm, report, pass1| {
                events = match rules.as_mut() {
                    Some(rules) => rules.after_pass1(asm, report, pass1),
                    None => {
                        let grammar = asm.grammar_arc().clone();
                        replace::replacement_events(
                            &grammar,
                            asm.data_mut(),
                            &report.switches,
                            pass1,
                        )
                    }
                };
            })?;
        if let Some(rules) = &mut self.rules {
            events.extend(rules.after_pass2(asm));
        }
        let proposals = self.solver.take_proposals(asm);
        if !proposals.is_empty() {
            events.extend(self.try_proposals(asm, report.energy, &proposals));
        }
        for e in &events {
            *self.rules_fired.entry(e.kind).or_default() += 1;
        }
        self.frame_ms.push(start.elapsed().as_secs_f64() * 1e3);
        self.last_report = Some(report.clone());
        Ok(Frame { report, events })
    }

    /// Tries what the solver's relaxation proposed (`relax.rs`: a held model that stopped
    /// strained, `docs/solver.md`), each alternative on a copy of `asm`: the rules
    /// restructure it, it settles by least squares with its states fixed, and the one with
    /// the lowest energy (of those at rest, the fewest elements and states changed:
    /// [`changes`]) replaces `asm` when that is below `(1 - hysteresis)` times the energy
    /// of `asm` as it is, settled the same way (or `energy`, the frame's, if lower: paper 4.2,
    /// 4.3: the structure changes where a rest state fits better, judged by energy).
    /// Every alternative is tried, whatever the frame's budget: what a frame does must not
    /// depend on the clock but through where its passes stopped ([`Stop`]), or a sculpt
    /// would not replay. Returns the events kept.
    fn try_proposals(
        &mut self,
        asm: &mut Assembly,
        energy: f64,
        proposals: &[crate::solver::Proposal],
    ) -> Vec<RuleEvent> {
        let Some(rules) = &mut self.rules else {
            return Vec::new();
        };
        let config = self.solver.config;
        let settle = SolverConfig {
            irls_iterations: 0,
            l2_iterations: SETTLE_ITERATIONS,
            ..config
        };
        // the model as it is, settled as the alternatives are: what they must beat
        let Some((current, _, _)) = settled(asm.clone(), settle) else {
            return Vec::new();
        };
        let energy = current.min(energy);
        let solver = &self.solver;
        // two at rest are alike: the fewer changes win (their energies differ by rounding
        // alone, and which is lower changed with a far chain added to the model)
        let rank = |e: f64, trial: &Assembly| (!solver.strained(e)).then(|| changes(asm, trial));
        let mut best: Option<(f64, Option<usize>, Assembly, Vec<RuleEvent>)> = None;
        let mut keep = |(e, trial, events): (f64, Assembly, Vec<RuleEvent>)| {
            let r = rank(e, &trial);
            let better = best.as_ref().is_none_or(|b| match (r, b.1) {
                (Some(x), Some(y)) => (x, e) < (y, b.0),
                _ => e < b.0,
            });
            if better {
                best = Some((e, r, trial, events));
            }
        };
        for proposal in proposals {
            let Some((after, trial, events, mut solver, proposal)) =
                restructured_standing(rules, asm, proposal, settle)
            else {
                continue;
            };
            if proposal.then_lengths && !asm.data().chains.is_empty() {
                // the counts a turn asks for, with the lengths they then ask for
                let parts = &asm.data().parts;
                let kept: Vec<usize> = (proposal.states.iter())
                    .filter_map(|&(part, _)| match parts[part].kind {
                        PartKind::Piece { instance } => Some(instance),
                        PartKind::Stretch { .. } => None,
                    })
                    .collect();
                for then in solver.relaxed_after(&trial, &kept) {
                    if let Some((after, trial, more, _)) =
                        restructured(rules, &trial, &then, settle)
                    {
                        keep((after, trial, [events.clone(), more].concat()));
                    }
                }
            }
            keep((after, trial, events));
        }
        let Some((after, _, trial, mut events)) = best else {
            return Vec::new();
        };
        let better = after < (1.0 - config.hysteresis) * energy;
        if !better {
            return Vec::new();
        }
        for e in &mut events {
            e.detail = format!("{}: {}", e.detail, rests_better(energy, after));
        }
        *asm = trial;
        rules.record(asm, events)
    }

    /// Grabs `instance` ([`Grab::instance`]: its pin, if any, gives way and comes back where
    /// it is dropped), letting go of the previous grab. `None` if it has no vertices.
    pub fn grab(&mut self, asm: &mut Assembly, instance: usize) -> Option<HandleId> {
        self.release(asm);
        self.grab = Grab::instance(asm, instance);
        self.grabbed()
    }

    /// Moves the grab's target ([`Grab::move_to`]). Returns whether anything changed.
    pub fn move_grab(&mut self, asm: &mut Assembly, translation: DVec2, angle: f64) -> bool {
        self.grab
            .is_some_and(|g| g.move_to(asm, translation, angle))
    }

    /// Lets go of the grab ([`Grab::release`]). Returns whether there was one.
    pub fn release(&mut self, asm: &mut Assembly) -> bool {
        self.grab.take().is_some_and(|g| g.release(asm))
    }

    /// Cuts the connection nearest `point` (paper 5.1's cut rule).
    pub fn cut(&mut self, asm: &mut Assembly, point: DVec2) -> Result<RuleEvent, String> {
        let Some(rules) = &mut self.rules else {
            let why = "this session runs without rules".to_string();
            self.notes.push(why.clone());
            return Err(why);
        };
        match rules.cut(asm, point) {
            Ok(e) => {
                *self.rules_fired.entry(e.kind).or_default() += 1;
                Ok(e)
            }
            Err(why) => {
                self.notes.push(why.clone());
                Err(why)
            }
        }
    }

    /// The connection (dock index) a cut at `point` would cut, if one is within reach.
    pub fn cut_target(asm: &Assembly, point: DVec2) -> Option<usize> {
        let grammar = asm.grammar();
        let reach = CUT_REACH.max(2.0 * grammar.solver.merge_distance);
        crate::rules::cut::nearest_dock(grammar, asm.data(), point)
            .filter(|(_, d)| *d <= reach)
            .map(|(i, _)| i)
    }

    /// Where each connection (dock) is: the centre of its docked site (NaN if it has none).
    pub fn dock_centres(asm: &Assembly) -> Vec<DVec2> {
        let (grammar, data) = (asm.grammar(), &asm.data());
        data.docks
            .iter()
            .map(|d| crate::rules::site_centre(grammar, data, d.a).unwrap_or(DVec2::NAN))
            .collect()
    }

    /// Whether the model rests after the last frame: its energy is within a millionth of the
    /// model's size squared (the claims suites' rest). A model may also hold still under
    /// strain: held by handles, or in states its chains cannot leave.
    pub fn at_rest(&self, asm: &Assembly) -> bool {
        let size = crate::solver::bbox_diagonal(&asm.data().positions);
        self.last_report()
            .is_some_and(|r| r.energy <= 1e-6 * size * size)
    }

    /// Why `part` is in the state it is in, under the solver's hysteresis.
    pub fn inspect(&self, asm: &Assembly, part: usize) -> Option<PartReport> {
        let data = &asm.data();
        let p = data.parts.get(part)?;
        let judged = self.solver.judge(asm, part)?;
        let states: Vec<(String, f64)> = (p.states.iter())
            .zip(&judged.distances)
            .map(|(s, &d)| (s.name.clone(), d))
            .collect();
        let active = p.active.min(states.len().saturating_sub(1));
        let d_active = states.get(active).map_or(0.0, |s| s.1);
        let hysteresis = self.solver.config.hysteresis;
        // at rest: within a millionth of the part's size squared (the claims suite's rest)
        let size = crate::solver::bbox_diagonal(
            &p.vertices
                .iter()
                .map(|&v| data.positions[v])
                .collect::<Vec<_>>(),
        );
        // judged by its turn: at rest within a thousandth of a radian
        let rest_within = if judged.turns.is_some() {
            1e-6
        } else {
            1e-6 * size * size
        };
        Some(PartReport {
            part,
            active,
            hysteresis,
            switch_below: (1.0 - hysteresis) * d_active,
            available: judged.available,
            candidate: judged.candidate,
            at_rest: d_active <= rest_within,
            states,
            turns: judged.turns,
        })
    }

    /// The summary of the session so far.
    pub fn summary(&self, asm: &Assembly) -> Summary {
        summarize(
            asm,
            &self.frame_ms,
            &self.rules_fired,
            self.last_report.as_ref(),
            &self.solver.config,
        )
    }
}

/// A copy of `asm` restructured by the rules as `proposal` says (laid out from its pose)
/// and settled by a solver of config `settle`: its energy, the copy, the rules' events and
/// the solver (which has run a frame on the copy). `None` when the rules change nothing or
/// the settling fails.
fn restructured(
    rules: &mut Rules,
    asm: &Assembly,
    proposal: &crate::solver::Proposal,
    settle: SolverConfig,
) -> Option<(f64, Assembly, Vec<RuleEvent>, Solver)> {
    if proposal.pose.len() != asm.data().positions.len() {
        return None;
    }
    let mut trial = asm.clone();
    trial.positions_mut().copy_from_slice(&proposal.pose);
    let events = rules.restructure(&mut trial, proposal);
    if events.is_empty() {
        return None;
    }
    let (energy, trial, solver) = settled(trial, settle)?;
    Some((energy, trial, events, solver))
}

/// [`restructured`], and when the settled model would switch a piece the proposal switched
/// again (`Solver::switched_again`: paper 4.3 in its pose), the proposal without those
/// pieces' states instead (the proposal tried is returned). A relaxation reads a piece's
/// state in the relaxed pose, where least squares spread the turn; settled with it, the
/// model may not bend that way, and the next frame's pass 1 switched the piece back
/// (generated states case 1111: a bend to -10 degrees with its sites turned 0.0, twice).
fn restructured_standing(
    rules: &mut Rules,
    asm: &Assembly,
    proposal: &crate::solver::Proposal,
    settle: SolverConfig,
) -> Option<(
    f64,
    Assembly,
    Vec<RuleEvent>,
    Solver,
    crate::solver::Proposal,
)> {
    let (after, trial, events, solver) = restructured(rules, asm, proposal, settle)?;
    let again = solver.switched_again(&trial, asm);
    if again.is_empty() {
        return Some((after, trial, events, solver, proposal.clone()));
    }
    let data = asm.data();
    let mut standing = proposal.clone();
    standing
        .states
        .retain(|&(part, _)| match data.parts.get(part).map(|p| &p.kind) {
            Some(PartKind::Piece { instance }) => {
                (data.instances.get(*instance)).is_none_or(|x| !again.contains(&x.id))
            }
            _ => true,
        });
    let (after, trial, events, solver) = restructured(rules, asm, &standing, settle)?;
    Some((after, trial, events, solver, standing))
}

/// `asm` settled by a solver of config `settle` (states fixed): its energy, the settled
/// copy and the solver (which has run a frame on it). A model still strained is settled
/// once more from its rest layout, as a frame's trials would next frame, and that is kept
/// when it rests: the rules lay an inserted element out along its chain, and an arc's
/// element so laid can fold the chain into a strain least squares does not leave (generated
/// morph case 825: 0.011 where the counts rest, 2e-9 from the rest layout). Only at rest: a
/// strained layout is no rest configuration found, and from it a chain curled a whole turn
/// rested lower than the fold its proposal settled to.
fn settled(mut asm: Assembly, settle: SolverConfig) -> Option<(f64, Assembly, Solver)> {
    let mut solver = Solver::new(settle);
    let energy = solver.frame(&mut asm).ok()?.energy;
    if solver.strained(energy)
        && let Some(laid) = solver.rest_layout_of(&asm)
    {
        let mut unfolded = asm.clone();
        unfolded.positions_mut().copy_from_slice(&laid);
        let mut again = Solver::new(settle);
        if let Ok(report) = again.frame(&mut unfolded)
            && !again.strained(report.energy)
        {
            return Some((report.energy, unfolded, again));
        }
    }
    Some((energy, asm, solver))
}

/// How far `b`'s structure is from `a`'s: the elements each chain gained or lost and the
/// piece instances (by stable id) in another state.
fn changes(a: &Assembly, b: &Assembly) -> usize {
    let (a, b) = (a.data(), b.data());
    let elements: usize = (a.chains.iter().zip(&b.chains))
        .map(|(x, y)| x.instances.len().abs_diff(y.instances.len()))
        .sum();
    let states: std::collections::HashMap<u64, usize> =
        a.instances.iter().map(|i| (i.id, i.state)).collect();
    let switched = (b.instances.iter())
        .filter(|i| states.get(&i.id).is_some_and(|&s| s != i.state))
        .count();
    elements + switched
}

/// Least-squares iterations that settle a restructured model before it is judged
/// ([`Session::try_proposals`]).
const SETTLE_ITERATIONS: usize = 200;

/// A frame failed to solve during replay.
#[derive(Clone, Debug, PartialEq)]
pub struct ReplayError {
    pub step: Option<usize>,
    pub error: SolverError,
}

impl std::fmt::Display for ReplayError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.step {
            Some(i) => write!(f, "step {i}: {}", self.error),
            None => write!(f, "{}", self.error),
        }
    }
}

impl std::error::Error for ReplayError {}

/// Replays a whole script on `asm` and summarises the result.
pub fn replay(
    asm: &mut Assembly,
    script: &Script,
    session: &mut Session,
) -> Result<Summary, ReplayError> {
    for (i, s) in script.steps.iter().enumerate() {
        session.step(asm, i, s).map_err(|error| ReplayError {
            step: Some(i),
            error,
        })?;
    }
    Ok(session.summary(asm))
}

/// Script steps (`clayc run`): each one a call of the session's own operations.
impl Session {
    /// Runs one script step (its index is only used in notes).
    pub fn step(
        &mut self,
        asm: &mut Assembly,
        index: usize,
        step: &Step,
    ) -> Result<(), SolverError> {
        match *step {
            Step::Grab(sel) | Step::Pin(sel) => {
                let Some(instance) = select(asm, sel) else {
                    let why = if asm.data().instances.is_empty() {
                        "the model is empty"
                    } else {
                        "no instance is a finite distance away"
                    };
                    self.notes
                        .push(format!("step {index}: nothing to select ({why})"));
                    return Ok(());
                };
                if let Step::Grab(_) = step {
                    self.grab(asm, instance);
                } else {
                    pin(asm, instance);
                }
            }
            Step::Unpin(sel) => {
                let unpinned = select(asm, sel).is_some_and(|i| unpin(asm, i));
                if !unpinned {
                    self.notes.push(format!(
                        "step {index}: unpin found no pinned instance there"
                    ));
                }
            }
            Step::Drag { motion, frames } => {
                if self.grab.is_none() {
                    self.notes.push(format!(
                        "step {index}: drag without a grabbed part only holds"
                    ));
                }
                let offset = match (motion, self.grabbed().and_then(|id| asm.handle(id))) {
                    (Motion::By(d), _) => d,
                    (Motion::To(p), Some(h)) => p - h.target_centre(),
                    (Motion::To(_), None) => DVec2::ZERO,
                };
                self.move_handle(asm, offset, 0.0, frames)?;
            }
            Step::Rotate { degrees, frames } => {
                if self.grab.is_none() {
                    self.notes.push(format!(
                        "step {index}: rotate without a grabbed part only holds"
                    ));
                }
                self.move_handle(asm, DVec2::ZERO, degrees.to_radians(), frames)?;
            }
            Step::Release => {
                if !self.release(asm) {
                    self.notes
                        .push(format!("step {index}: release without a grabbed part"));
                }
            }
            Step::Hold { frames } => {
                for _ in 0..frames {
                    self.frame(asm)?;
                }
            }
            Step::Budget { pass1, pass2 } => {
                self.next_stop = Stop::After {
                    pass1: pass1 as usize,
                    pass2: pass2 as usize,
                };
            }
            Step::Cut { at } => {
                if let Err(why) = self.cut(asm, at) {
                    let last = self.notes.len() - 1;
                    self.notes[last] = format!(
                        "step {index}: cut at [{}, {}] does nothing: {why}",
                        at.x, at.y
                    );
                }
            }
        }
        Ok(())
    }

    /// Moves the grab by `offset` and turns it by `angle` over `frames` frames.
    fn move_handle(
        &mut self,
        asm: &mut Assembly,
        offset: DVec2,
        angle: f64,
        frames: u64,
    ) -> Result<(), SolverError> {
        let Some(h) = self.grabbed().and_then(|id| asm.handle(id)) else {
            self.grab = None;
            return (0..frames).try_for_each(|_| self.frame(asm).map(drop));
        };
        let (t0, a0) = (h.translation, h.angle);
        if frames == 0 {
            self.move_grab(asm, t0 + offset, a0 + angle);
            return Ok(());
        }
        for k in 1..=frames {
            let s = k as f64 / frames as f64;
            // The handle may vanish when rules drop its vertices; the drag then just holds.
            self.move_grab(asm, t0 + offset * s, a0 + angle * s);
            self.frame(asm)?;
        }
        Ok(())
    }
}

/// The instance a selector picks (see [`Selector`]).
fn select(asm: &Assembly, sel: Selector) -> Option<usize> {
    match sel {
        Selector::At(p) => asm.instance_nearest(p),
        Selector::Extreme(dir) => asm.instance_extreme(dir),
    }
}
