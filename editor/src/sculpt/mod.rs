//! Sculpting mode. This module is the sculpt: the live assembly, its solver, the user's grab
//! and pins, and the undo history of whole gestures. Everything the canvas and panels change
//! goes through [`Command`]s applied here, so it is tested without a window.
//!
//! The model's parts are private children: `gestures` (the grab, pins and cuts as the
//! session's gestures), `history` (undo), `record` (the gestures as a script), `frame` and
//! `solving` (a frame on the UI thread or on the background `worker`), `log` (the rule log)
//! and `inspect` (the inspector's report). The mode's view is in public ones: `canvas` (the
//! model drawn, pointer and keys to [`Command`]s), its `overlay` (the View overlays) and `iso`
//! (the isometric 3D view), `panels` (the side panels) and `follow` (`--follow`'s highlight).
//! The children import this module; it imports only the model's children, never the view's.

use std::sync::Arc;

use clay::{Assembly, FrameReport, Grab, Session, SolverConfig};
use clay_dsl::compiled::{AssemblyData, CompiledGrammar};
use glam::DVec2;

use crate::session::{Pin, Settings};

pub mod canvas;
pub mod follow;
pub mod iso;
pub mod overlay;
pub mod panels;

mod frame;
mod gestures;
mod history;
mod inspect;
mod log;
mod record;
mod solving;
mod worker;

use frame::{Job, Request};
use record::Recording;
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
    /// Which state of the history this is ([`Sculpt::dirty`] compares it with the saved one).
    state: u64,
    /// The gestures recorded as a script up to the gesture (undo takes the gesture's steps out).
    record: Recording,
}

/// Why a part is in the state it is in: the session's report
/// ([`clay::PartReport`]) with the names the inspector shows.
#[derive(Clone, Debug, PartialEq)]
pub struct PartReport {
    /// `tower`, or `wall` for a stretch part.
    pub piece: String,
    /// "`t1`", or "`wall[3]` and `wall[4]`" for a stretch part.
    pub covers: String,
    pub pinned: bool,
    /// What the solver's state choice compares, from the session.
    pub why: clay::PartReport,
}

/// The live sculpt.
pub struct Sculpt {
    assembly: Assembly,
    /// The solver and the rules (what a frame is).
    session: Session,
    settings: Settings,
    grab: Option<Grab>,
    /// The gestures since the grammar's initial model, as a script ([`Sculpt::gesture_script`]).
    record: Recording,
    undo: Vec<Snapshot>,
    redo: Vec<Snapshot>,
    /// Which state of the undo history the model is in: a new one for every gesture, the
    /// snapshot's own when undone or redone to.
    state: u64,
    /// The last state given out.
    last_state: u64,
    /// The state last saved or opened (`None`: none in this history, e.g. restored work).
    saved: Option<u64>,
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
            record: Recording::new(),
            undo: Vec::new(),
            redo: Vec::new(),
            state: 0,
            last_state: 0,
            saved: Some(0),
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
            state: 0,
            record: Recording::unknown(
                "the sculpt was opened from a session, so the gestures that made it are not known; \
                 Edit > Reset starts a new recording from the grammar's initial model"
                    .to_string(),
            ),
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
            Command::MoveGrab { translation, angle } => self.move_grab(translation, angle),
            Command::Release => self.release(),
            Command::TogglePin { part, at } => self.toggle_pin(part, at),
            Command::Cut { point } => {
                self.release();
                self.cut(point);
            }
            Command::Undo => {
                self.release();
                self.step_history(false);
            }
            Command::Redo => {
                self.release();
                self.step_history(true);
            }
            Command::Reset => {
                self.release();
                self.checkpoint();
                self.restore(self.initial(self.grammar().clone()));
                self.note("reset to the initial model".to_string(), None);
            }
            Command::Settings(s) => {
                // the one table's ranges (`clay_dsl::settings`)
                let allows =
                    |name, x| clay_dsl::settings::setting(name).is_some_and(|t| t.range.allows(x));
                let valid = allows("hysteresis", s.hysteresis)
                    && allows("norm", s.norm)
                    && allows("merge_distance", s.merge_distance);
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
        let saved = !self.dirty();
        self.checkpoint();
        if saved {
            self.mark_saved();
        }
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
                state: self.state,
                // The same model block: the gestures replay on the new pieces.
                record: self.record.clone(),
            }
        } else {
            self.carried(grammar)
        };
        let carried = snapshot.pins.len();
        self.restore(snapshot);
        self.note(
            match (keep, carried) {
                (true, _) => "grammar reloaded; sculpt kept".to_string(),
                (false, 0) => "grammar reloaded; model rebuilt".to_string(),
                (false, n) => format!(
                    "grammar reloaded; model rebuilt, {n} pin{} kept",
                    if n == 1 { "" } else { "s" }
                ),
            },
            None,
        );
        keep
    }

    /// Where each dock (connection) is: the centre of its docked site.
    pub fn dock_centres(&self) -> Vec<DVec2> {
        Session::dock_centres(&self.assembly)
    }

    fn configure_solver(&mut self) {
        let mut config = SolverConfig::from_params(&self.grammar().solver);
        config.hysteresis = self.settings.hysteresis;
        config.norm = self.settings.norm;
        self.session.set_config(config);
    }

    /// The connection a cut at `point` would cut, if any is within the cut's reach.
    pub fn cut_target(&self, point: DVec2) -> Option<usize> {
        Session::cut_target(&self.assembly, point)
    }
}
