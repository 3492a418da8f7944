//! The sculpt: the live assembly, its solver, the user's grab and pins, and the undo history of
//! whole gestures. Everything the canvas and panels change goes through [`Command`]s applied
//! here, so it is tested without a window.

use std::sync::Arc;
use std::time::{Duration, Instant};

use clay::assembly::{Assembly, HandleKind};
use clay::session::{Grab, Session};
use clay::solver::{FrameReport, SolverConfig, SolverError};
use clay_dsl::compiled::{AssemblyData, CompiledGrammar, PartKind};
use glam::DVec2;

use crate::session::{Pin, Settings};

mod worker;
use worker::Worker;

/// What the user asks of the model. The UI emits these; [`Sculpt::apply`] applies them after
/// the frame.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// Start a gesture on `part`, pressed at world point `at`: the instance of the part nearest
    /// `at` becomes the handle (in a stretch chain a part spans two elements; the user grabs the
    /// brick under the cursor, not the pair, as `clayc run` does).
    Grab {
        part: usize,
        at: DVec2,
    },
    /// Move the grabbed part: its target is its start pose moved by `translation` and turned by
    /// `angle` radians about its centre.
    MoveGrab {
        translation: DVec2,
        angle: f64,
    },
    /// End the gesture.
    Release,
    /// Pin the instance of `part` nearest `at`, or unpin it if pinned.
    TogglePin {
        part: usize,
        at: DVec2,
    },
    /// Cut the connection nearest `point` (world coordinates).
    Cut {
        point: DVec2,
    },
    Undo,
    Redo,
    /// Back to the grammar's initial model (undoable).
    Reset,
    /// New solver and rule settings, applied live.
    Settings(Settings),
}

pub use crate::session::LogEntry;

/// The model as it was before a gesture.
#[derive(Clone, Debug)]
struct Snapshot {
    grammar: Arc<CompiledGrammar>,
    data: AssemblyData,
    pins: Vec<Pin>,
    /// The rule log as it was: undoing a gesture takes back what its rules logged too.
    log: Vec<LogEntry>,
}

/// Why a part is in the state it is in: the session's report
/// ([`clay::session::PartReport`]) with the names the inspector shows.
#[derive(Clone, Debug, PartialEq)]
pub struct PartReport {
    /// `tower`, or `wall` for a stretch part.
    pub piece: String,
    /// "`t1`", or "`wall[3]` and `wall[4]`" for a stretch part.
    pub covers: String,
    pub pinned: bool,
    /// What the solver's state choice compares, from the session.
    pub why: clay::session::PartReport,
}

/// Most log entries kept; older ones are dropped.
const LOG_LIMIT: usize = 500;
/// Largest vertex move in a frame, relative to the model's size, for which the model counts
/// as at rest.
/// Most gestures kept for undo.
const UNDO_LIMIT: usize = 200;

/// The live sculpt.
pub struct Sculpt {
    assembly: Assembly,
    /// The solver and the rules (what a frame is).
    session: Session,
    settings: Settings,
    grab: Option<Grab>,
    undo: Vec<Snapshot>,
    redo: Vec<Snapshot>,
    /// Changed since the last save or open.
    pub dirty: bool,
    /// Whether the solver still has work: a moved handle, or a frame that did not converge.
    unsettled: bool,
    /// Solver frames run so far.
    frame: u64,
    /// Bumped whenever `data` may have changed, so views re-pose only then.
    revision: u64,
    /// Bumped by every undo step taken, undone or redone.
    history: u64,
    last_report: Option<FrameReport>,
    /// Solver frames run in the last UI frame.
    pub frames_last_step: usize,
    error: Option<String>,
    log: Vec<LogEntry>,
    /// The sequence number of the next log entry (entries keep their order across undo).
    next_seq: u64,
    /// The thread of the background solver frames ([`Sculpt::step_in_background`]), started
    /// at the first; busy while a frame runs there.
    worker: Option<Worker<Request, Job>>,
    /// The model the last background frame started from, reused for the next one.
    spare: Option<Assembly>,
    /// The grab moved while a background frame ran (its result is then not a fixed point).
    moved_while_solving: bool,
    /// A model no longer needed, freed by the next background frame's thread.
    stale: Option<Assembly>,
}

/// A background solver frame to run: the model, solver and rules to work on, within `budget`.
struct Request {
    model: Assembly,
    session: Session,
    budget: Duration,
    /// A model no longer needed, freed on the worker's thread.
    stale: Option<Assembly>,
}

/// One background solver frame, as the worker's thread runs it.
fn run_request(request: Request) -> Job {
    let Request {
        mut model,
        mut session,
        budget,
        stale,
    } = request;
    // freeing a whole model costs milliseconds at 10k parts: not on the UI thread
    drop(stale);
    let generation = model.generation();
    let outcome = solve_frame(&mut model, &mut session, budget);
    // After a rewrite the model shown now can no longer be brought up to date in place for
    // the next frame: copy the result here, off the UI thread.
    let spare = (model.generation() != generation).then(|| model.clone());
    Job {
        model,
        spare,
        session,
        outcome,
    }
}

/// What a background solver frame hands back: the model, solver and rules it worked on.
struct Job {
    model: Assembly,
    /// A copy of `model`, made when a rule rewrote it (the next frame starts from it).
    spare: Option<Assembly>,
    session: Session,
    outcome: FrameOutcome,
}

/// What one solver frame and the rules after it did.
struct FrameOutcome {
    report: Result<FrameReport, SolverError>,
    /// Log lines of the frame (state switches of stretch parts, rule events), in order.
    notes: Vec<(String, Option<DVec2>)>,
    /// A rule rewrote the model.
    rewrote: bool,
    /// The frame panicked: the model it worked on may be half rewritten.
    panicked: bool,
}

/// One sculpting frame within `budget` (the session's: a solver frame, then the rules), on
/// whichever thread, with its log lines in the grammar's names.
///
/// A panic in the solver or the rules is caught: the outcome says so, and the caller keeps
/// the last good model (the editor never exits on a model it was given).
fn solve_frame(assembly: &mut Assembly, session: &mut Session, budget: Duration) -> FrameOutcome {
    let solved = crate::guard::catching(|| session.frame_within(assembly, budget));
    let failed = |e: SolverError, panicked: bool| FrameOutcome {
        report: Err(e),
        notes: Vec::new(),
        rewrote: false,
        panicked,
    };
    let frame = match solved {
        Ok(Ok(frame)) => frame,
        Ok(Err(e)) => return failed(e, false),
        Err(why) => {
            let e = SolverError(format!(
                "internal error: the solver stopped ({why}); the model before this gesture \
                 is restored"
            ));
            return failed(e, true);
        }
    };
    // The editor keeps its own bounded log.
    session.clear_rule_log();
    // Any event, a replacement too, means the model may move on: not settled yet.
    let rewrote = !frame.events.is_empty();
    let notes = frame
        .events
        .iter()
        .map(|e| {
            (
                format!("{} at ({:.1}, {:.1})", e.detail, e.at.x, e.at.y),
                Some(e.at),
            )
        })
        .collect();
    FrameOutcome {
        report: Ok(frame.report),
        notes,
        rewrote,
        panicked: false,
    }
}

impl Sculpt {
    /// The grammar's initial model.
    pub fn new(grammar: Arc<CompiledGrammar>) -> Self {
        let settings = Settings {
            hysteresis: grammar.solver.hysteresis,
            norm: grammar.solver.norm,
            merge_distance: grammar.solver.merge_distance,
        };
        let assembly = Assembly::new(grammar);
        let mut sculpt = Self {
            session: Session::new(SolverConfig::default()),
            assembly,
            settings,
            grab: None,
            undo: Vec::new(),
            redo: Vec::new(),
            dirty: false,
            unsettled: true,
            frame: 0,
            revision: 0,
            last_report: None,
            frames_last_step: 0,
            error: None,
            history: 0,
            log: Vec::new(),
            next_seq: 0,
            worker: None,
            spare: None,
            moved_while_solving: false,
            stale: None,
        };
        sculpt.configure_solver();
        sculpt
    }

    /// A saved sculpt over `grammar`. Fails, in words, when the data does not fit the grammar.
    pub fn from_saved(
        grammar: Arc<CompiledGrammar>,
        data: AssemblyData,
        pins: Vec<Pin>,
        settings: Option<Settings>,
        log: Vec<LogEntry>,
    ) -> Result<Self, String> {
        data.check(&grammar)
            .map_err(|e| format!("the session does not fit the grammar: {e}"))?;
        let mut sculpt = Self::new(grammar.clone());
        if let Some(s) = settings {
            sculpt.settings = s;
            sculpt.configure_solver();
        }
        sculpt.restore(Snapshot {
            grammar,
            data,
            pins,
            log,
        });
        sculpt
            .assembly
            .validate()
            .map_err(|e| format!("the session does not fit the grammar: {}", e.join("; ")))?;
        Ok(sculpt)
    }

    pub fn assembly(&self) -> &Assembly {
        &self.assembly
    }

    pub fn data(&self) -> &AssemblyData {
        self.assembly.data()
    }

    pub fn grammar(&self) -> &Arc<CompiledGrammar> {
        self.assembly.grammar_arc()
    }

    pub fn settings(&self) -> Settings {
        self.settings
    }

    pub fn last_report(&self) -> Option<&FrameReport> {
        self.last_report.as_ref()
    }

    /// Solver frames run so far.
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// Changes with every undo step taken, undone or redone.
    pub fn history(&self) -> u64 {
        self.history
    }

    /// Changes whenever the assembly data may have changed.
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// The last solver failure, if the model is stuck.
    pub fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }

    pub fn log(&self) -> &[LogEntry] {
        &self.log
    }

    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// The part being dragged, if any.
    pub fn grabbed(&self) -> Option<usize> {
        self.grab.and_then(|g| g.part())
    }

    /// The grabbed handle's current target centre and angle.
    pub fn grab_target(&self) -> Option<(DVec2, f64)> {
        self.grab?.target(&self.assembly)
    }

    /// Whether the solver has work left; the app keeps repainting while it has.
    pub fn needs_work(&self) -> bool {
        (self.unsettled || self.solving_in_background()) && self.error.is_none()
    }

    /// Whether the model rests: the solver has nothing left to do and the last frame's energy
    /// is within a millionth of the model's size squared (the claims suite's rest). A model
    /// may also hold still under strain: held by handles, or a state its chain cannot leave.
    pub fn at_rest(&self) -> bool {
        !self.needs_work() && self.session.at_rest(&self.assembly)
    }

    /// The pins, with where they hold their vertices.
    pub fn pins(&self) -> Vec<Pin> {
        let mut pins: Vec<Pin> = self
            .assembly
            .handles()
            .iter()
            .filter(|h| h.kind() == HandleKind::Pin)
            .map(|h| Pin {
                vertices: h.vertices().to_vec(),
                at: (0..h.vertices().len()).map(|k| h.target(k)).collect(),
            })
            .collect();
        if let Some(g) = &self.grab
            && g.was_pinned()
            && let Some(h) = self.assembly.handle(g.handle())
        {
            pins.push(Pin {
                vertices: h.vertices().to_vec(),
                at: (0..h.vertices().len()).map(|k| h.target(k)).collect(),
            });
        }
        pins
    }

    /// The vertices the grab holds, and the pinned ones (the handles-and-pins overlay).
    pub fn held_vertices(&self) -> (Vec<usize>, Vec<usize>) {
        let mut grabbed = Vec::new();
        let mut pinned = Vec::new();
        for h in self.assembly.handles() {
            match h.kind() {
                HandleKind::Grab => grabbed.extend(h.vertices().iter().copied()),
                HandleKind::Pin => pinned.extend(h.vertices().iter().copied()),
            }
        }
        (grabbed, pinned)
    }

    /// Whether an instance of `part` is held by a pin.
    pub fn is_pinned(&self, part: usize) -> bool {
        let asm = &self.assembly;
        (asm.data().part_instances(part).into_iter())
            .any(|i| clay::session::pin_of(asm, i).is_some())
            || (self.grab).is_some_and(|g| g.part() == Some(part) && g.was_pinned())
    }

    /// Applies one command.
    pub fn apply(&mut self, command: Command) {
        if matches!(command, Command::MoveGrab { .. }) {
            // applied to the model shown; a running frame picks the new target up when done
            self.moved_while_solving |= self.solving_in_background();
        } else {
            self.collect_job(true);
        }
        match command {
            Command::Grab { part, at } => self.grab(part, at),
            Command::MoveGrab { translation, angle } => {
                if let Some(g) = self.grab
                    && g.move_to(&mut self.assembly, translation, angle)
                {
                    self.unsettled = true;
                }
            }
            Command::Release => self.release(),
            Command::TogglePin { part, at } => {
                let Some(instance) = self.assembly.instance_of_part_at(part, at) else {
                    return;
                };
                self.release();
                self.checkpoint();
                let name = self.assembly.data().instances[instance].name.clone();
                if clay::session::toggle_pin(&mut self.assembly, instance) {
                    self.note(format!("pinned {name}"), None);
                } else {
                    self.note(format!("unpinned {name}"), None);
                }
                self.unsettled = true;
            }
            Command::Cut { point } => {
                self.release();
                self.cut(point);
            }
            Command::Undo => {
                self.release();
                if let Some(s) = self.undo.pop() {
                    self.history += 1;
                    self.redo.push(self.snapshot());
                    self.restore(s);
                    self.dirty = true;
                }
            }
            Command::Redo => {
                self.release();
                if let Some(s) = self.redo.pop() {
                    self.history += 1;
                    self.undo.push(self.snapshot());
                    self.restore(s);
                    self.dirty = true;
                }
            }
            Command::Reset => {
                self.release();
                self.checkpoint();
                self.restore(self.initial(self.grammar().clone()));
                self.note("reset to the initial model".to_string(), None);
            }
            Command::Settings(s) => {
                let valid = s.hysteresis.is_finite()
                    && (0.0..1.0).contains(&s.hysteresis)
                    && s.norm.is_finite()
                    && s.norm > 0.0
                    && s.merge_distance.is_finite()
                    && s.merge_distance >= 0.0;
                if valid && s != self.settings {
                    self.settings = s;
                    self.configure_solver();
                    self.unsettled = true;
                }
            }
        }
    }

    /// Replaces the grammar (hot reload), as one undoable step. When the grammar's model is
    /// unchanged and the sculpt still fits the new pieces, the sculpt is kept (positions, active
    /// states, pins) with the parts rebuilt from the new rest states, so editing a piece's
    /// shape or colours shows on the sculpted model; otherwise the new grammar's initial model.
    /// Returns whether the sculpt was kept.
    pub fn replace_grammar(&mut self, grammar: Arc<CompiledGrammar>) -> bool {
        self.collect_job(true);
        self.release();
        // A reload alone is not unsaved work: the session file would restore the same sculpt.
        let dirty = self.dirty;
        self.checkpoint();
        self.dirty = dirty;
        self.settings = Settings {
            hysteresis: grammar.solver.hysteresis,
            norm: grammar.solver.norm,
            merge_distance: grammar.solver.merge_distance,
        };
        self.configure_solver();
        let same_model = self.grammar().assembly.positions == grammar.assembly.positions
            && self.grammar().assembly.instances == grammar.assembly.instances
            && self.grammar().assembly.docks == grammar.assembly.docks
            && self.grammar().assembly.chains == grammar.assembly.chains;
        let mut data = self.assembly.data().clone();
        let keep = same_model && data.check(&grammar).is_ok();
        if keep {
            let old = std::mem::take(&mut data.parts);
            data.parts = grammar.parts(&data);
            for (new, old) in data.parts.iter_mut().zip(&old) {
                if new.kind == old.kind && old.active < new.states.len() {
                    new.active = old.active;
                }
            }
        }
        let snapshot = if keep && data.check(&grammar).is_ok() {
            Snapshot {
                grammar,
                data,
                pins: self.pins(),
                log: self.log.clone(),
            }
        } else {
            self.initial(grammar)
        };
        self.restore(snapshot);
        self.note(
            if keep {
                "grammar reloaded; sculpt kept".to_string()
            } else {
                "grammar reloaded; model rebuilt".to_string()
            },
            None,
        );
        keep
    }

    /// Runs solver frames until the model settles or `budget` is spent (at least one frame when
    /// there is work), on this thread. Returns whether work remains.
    pub fn step(&mut self, budget: Duration) -> bool {
        self.collect_job(true);
        let start = Instant::now();
        self.frames_last_step = 0;
        while self.needs_work() {
            // The frame gets what is left of the UI frame's budget: a frame the solver cannot
            // finish in time stops early with a proper least-squares pose and continues on the
            // next call, so a large model never blocks the window.
            let left = budget.saturating_sub(start.elapsed());
            let outcome = solve_frame(&mut self.assembly, &mut self.session, left);
            self.integrate(outcome);
            if start.elapsed() >= budget {
                break;
            }
        }
        self.needs_work()
    }

    /// Runs the solver on another thread (the machine's second core) so that drawing never
    /// waits for it: takes in the frame that finished since the last call, if any, and starts
    /// the next one (budgeted by `budget`) on a copy of the model as it is now. The model shown
    /// is the last finished frame, one frame behind the solver. Commands other than moving the
    /// grab wait for a running frame first, so they always act on the latest model. Returns
    /// whether work remains (call again next UI frame). The thread is the sculpt's own, started
    /// at the first call and ended with the sculpt; where it cannot be started the frame runs
    /// on this thread ([`Sculpt::step`]).
    pub fn step_in_background(&mut self, budget: Duration) -> bool {
        self.frames_last_step = 0;
        self.collect_job(false);
        if self.solving_in_background() || !self.needs_work() {
            return self.needs_work();
        }
        if self.worker.is_none() {
            match Worker::start("clay-sculpt-solver", run_request) {
                Ok(worker) => self.worker = Some(worker),
                Err(_) => return self.step(budget),
            }
        }
        // A frame moves positions, states, rotations and handles only: the spare copy of the
        // last frame is brought up to date in place; after a rule rewrote the model (new
        // generation) it is cloned afresh.
        let model = match self.spare.take() {
            Some(mut spare) => {
                if spare.sync_from(&self.assembly) {
                    spare
                } else {
                    self.stale = Some(spare);
                    self.assembly.clone()
                }
            }
            None => self.assembly.clone(),
        };
        let placeholder = Session::new(self.session.config());
        let session = std::mem::replace(&mut self.session, placeholder);
        let stale = self.stale.take();
        self.moved_while_solving = false;
        let request = Request {
            model,
            session,
            budget,
            stale,
        };
        let worker = self.worker.as_mut().expect("started above");
        if let Err(request) = worker.submit(request) {
            // the thread is gone: this frame runs here, and the next call starts another
            self.worker = None;
            self.session = request.session;
            self.spare = Some(request.model);
            return self.step(budget);
        }
        self.needs_work()
    }

    /// Whether a solver frame is running on another thread.
    pub fn solving_in_background(&self) -> bool {
        self.worker.as_ref().is_some_and(Worker::busy)
    }

    /// Takes in the background frame, waiting for it when `wait` (before any command that
    /// changes the model), else only if it has finished.
    fn collect_job(&mut self, wait: bool) {
        let Some(result) = self.worker.as_mut().and_then(|w| w.take(wait)) else {
            return;
        };
        match result {
            Ok(job) if job.outcome.panicked => {
                // The frame's copy may be half rewritten: the model shown stays.
                self.session = job.session;
                self.session.reset_solver();
                self.error = job.outcome.report.err().map(|e| e.to_string());
            }
            Ok(job) => {
                let mut solved = job.model;
                // The grab moved on while the frame ran: its latest target wins.
                if let Some(g) = &self.grab
                    && let Some(now) = self.assembly.handle(g.handle())
                {
                    g.move_to(&mut solved, now.translation(), now.angle());
                }
                let shown = std::mem::replace(&mut self.assembly, solved);
                match job.spare {
                    Some(spare) => {
                        self.spare = Some(spare);
                        self.stale = Some(shown);
                    }
                    None => self.spare = Some(shown),
                }
                self.session = job.session;
                self.integrate(job.outcome);
                if self.moved_while_solving {
                    self.unsettled = true;
                }
            }
            Err(_) => {
                // The frame's model is lost (a panic outside the guarded frame, or the thread
                // gone); the one shown stays.
                self.error = Some("the solver stopped unexpectedly".to_string());
            }
        }
    }

    /// Records what a solver frame did: counters, the log, the grab after rewrites, and
    /// whether the model has settled.
    fn integrate(&mut self, outcome: FrameOutcome) {
        match outcome.report {
            Ok(report) => {
                self.frame += 1;
                self.revision += 1;
                self.frames_last_step += 1;
                for (message, at) in outcome.notes {
                    self.note(message, at);
                }
                if outcome.rewrote && self.grab.is_some() {
                    self.follow_grab();
                }
                // `converged`: a complete frame with no state switch that moved no vertex
                // beyond the solver's settle tolerance, i.e. a fixed point.
                if report.converged && !outcome.rewrote {
                    self.unsettled = false;
                }
                self.last_report = Some(report);
            }
            Err(e) if outcome.panicked => {
                self.recover(e.to_string());
            }
            Err(e) => {
                self.error = Some(e.to_string());
            }
        }
    }

    /// After a frame on this thread panicked: the model from before the gesture (or the
    /// grammar's), a fresh solver, and the error shown; the solver stops until the next
    /// command.
    fn recover(&mut self, error: String) {
        self.grab = None;
        let snapshot = (self.undo.pop()).unwrap_or_else(|| self.initial(self.grammar().clone()));
        self.restore(snapshot);
        self.error = Some(error);
    }

    /// `grammar`'s initial model, nothing pinned, with the log as it is.
    fn initial(&self, grammar: Arc<CompiledGrammar>) -> Snapshot {
        Snapshot {
            data: grammar.assembly.clone(),
            grammar,
            pins: Vec::new(),
            log: self.log.clone(),
        }
    }

    /// Why `part` is in the state it is in.
    pub fn inspect(&self, part: usize) -> Option<PartReport> {
        let data = &self.assembly.data();
        let grammar = self.assembly.grammar();
        let p = data.parts.get(part)?;
        let name = |i: usize| data.instances.get(i).map_or("?", |x| x.name.as_str());
        let (piece, covers) = match p.kind {
            PartKind::Piece { instance } => {
                let piece = data
                    .instances
                    .get(instance)
                    .and_then(|x| grammar.pieces.get(x.piece))
                    .map_or("?".to_string(), |pc| pc.name.clone());
                (piece, format!("`{}`", name(instance)))
            }
            PartKind::Stretch { chain, first } => {
                let c = data.chains.get(chain)?;
                let piece = grammar
                    .stretch_rules
                    .get(c.rule)
                    .and_then(|r| grammar.pieces.get(r.piece))
                    .map_or("?".to_string(), |pc| pc.name.clone());
                let a = c.instances.get(first).copied().map_or("?", name);
                let b = c.instances.get(first + 1).copied().map_or("?", name);
                (piece, format!("`{a}` and `{b}`"))
            }
        };
        // The distances and the switch threshold are the session's (the solver's own rule).
        let why = self.session.inspect(&self.assembly, part)?;
        Some(PartReport {
            piece,
            covers,
            pinned: self.is_pinned(part),
            why,
        })
    }

    /// Where each dock (connection) is: the centre of its docked site.
    pub fn dock_centres(&self) -> Vec<DVec2> {
        Session::dock_centres(&self.assembly)
    }

    fn grab(&mut self, part: usize, at: DVec2) {
        self.release();
        if self.assembly.instance_of_part_at(part, at).is_none() {
            return;
        }
        self.checkpoint();
        self.grab = Grab::at(&mut self.assembly, part, at);
    }

    /// Ends the gesture: a pinned part stays pinned where it was dropped.
    fn release(&mut self) {
        if self.grab.is_none() {
            return;
        }
        if self.moved_while_solving {
            // The last moves came while a background frame ran: solve once more here, so the
            // part is dropped where the pointer let go, not a frame behind it.
            self.moved_while_solving = false;
            let outcome = solve_frame(&mut self.assembly, &mut self.session, Duration::MAX);
            self.integrate(outcome);
        }
        if let Some(g) = self.grab.take() {
            g.release(&mut self.assembly);
        }
        self.unsettled = true;
    }

    /// Records the model before a gesture.
    fn checkpoint(&mut self) {
        self.history += 1;
        let s = self.snapshot();
        self.undo.push(s);
        if self.undo.len() > UNDO_LIMIT {
            self.undo.remove(0);
        }
        self.redo.clear();
        self.dirty = true;
    }

    fn snapshot(&self) -> Snapshot {
        Snapshot {
            grammar: self.grammar().clone(),
            data: self.assembly.data().clone(),
            pins: self.pins(),
            log: self.log.clone(),
        }
    }

    fn restore(&mut self, s: Snapshot) {
        self.revision += 1;
        // The log goes back with the model, except for what happened outside the gestures
        // (failed reloads, file errors): those stay, in order.
        let outside: Vec<LogEntry> = self
            .log
            .iter()
            .filter(|e| e.outside && !s.log.contains(e))
            .cloned()
            .collect();
        self.log = s.log;
        self.log.extend(outside);
        self.log.sort_by_key(|e| e.seq);
        self.assembly = Assembly::from_data(s.grammar, s.data);
        for pin in s.pins {
            clay::session::pin_at(&mut self.assembly, pin.vertices, &pin.at);
        }
        // A fresh solver: the old one's pattern belongs to another topology. The spare copy
        // belongs to it too (and a restored model counts its generations from 0 again).
        self.session.reset_solver();
        self.spare = None;
        self.error = None;
        self.unsettled = true;
    }

    fn configure_solver(&mut self) {
        let mut config = SolverConfig::from_params(&self.grammar().solver);
        config.hysteresis = self.settings.hysteresis;
        config.norm = self.settings.norm;
        self.session.set_config(config);
    }

    fn cut(&mut self, point: DVec2) {
        self.checkpoint();
        match self.session.cut(&mut self.assembly, point) {
            Ok(e) => {
                self.session.clear_rule_log();
                self.revision += 1;
                self.note(
                    format!("{} at ({:.1}, {:.1})", e.detail, e.at.x, e.at.y),
                    Some(e.at),
                );
                self.unsettled = true;
            }
            Err(message) => {
                // Nothing changed: the gesture leaves no undo step.
                self.undo.pop();
                self.note(format!("cut failed: {message}"), Some(point));
            }
        }
    }

    /// After a rule renumbered the parts, the grabbed part is the one the handle still holds.
    fn follow_grab(&mut self) {
        if let Some(g) = &mut self.grab
            && !g.follow(&self.assembly)
        {
            self.grab = None;
        }
    }

    /// The connection a cut at `point` would cut, if any is within the cut's reach.
    pub fn cut_target(&self, point: DVec2) -> Option<usize> {
        Session::cut_target(&self.assembly, point)
    }

    /// Logs something that is not part of a gesture (a failed reload, a file error): undo
    /// does not take it back.
    pub fn note_outside_history(&mut self, message: String) {
        self.push_log(message, None, true);
    }

    fn note(&mut self, message: String, at: Option<DVec2>) {
        self.push_log(message, at, false);
    }

    fn push_log(&mut self, message: String, at: Option<DVec2>, outside: bool) {
        let seq = self
            .log
            .iter()
            .map(|e| e.seq + 1)
            .max()
            .unwrap_or(0)
            .max(self.next_seq);
        self.next_seq = seq + 1;
        self.log.push(LogEntry {
            frame: self.frame,
            message,
            at,
            outside,
            seq,
        });
        if self.log.len() > LOG_LIMIT {
            let extra = self.log.len() - LOG_LIMIT;
            self.log.drain(..extra);
        }
    }
}
