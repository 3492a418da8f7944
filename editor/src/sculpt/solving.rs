//! Running the sculpt's frames: on the UI thread within a budget, or on the background worker
//! one frame behind (a running frame is taken in before any command but moving the grab), and
//! what a frame did folded into the sculpt.

use std::time::{Duration, Instant};

use clay::Session;

use super::Sculpt;
use super::frame::{FrameOutcome, Request, run_request, solve_frame};
use super::worker::Worker;

impl Sculpt {
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
            self.record.frame_starts();
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
        // The frame sees the grab where it is now: its last move is recorded before it.
        self.record.frame_starts();
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
    pub(super) fn collect_job(&mut self, wait: bool) {
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
    pub(super) fn integrate(&mut self, outcome: FrameOutcome) {
        match outcome.report {
            Ok(report) => {
                self.frame += 1;
                let stopped = (!report.complete)
                    .then_some((report.pass1_iterations as u64, report.l2_iterations as u64));
                self.record.frame(stopped);
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
    pub(super) fn recover(&mut self, error: String) {
        self.grab = None;
        let snapshot = match self.undo.pop() {
            Some(s) => {
                self.state = s.state;
                s
            }
            None => self.initial(self.grammar().clone()),
        };
        self.restore(snapshot);
        self.error = Some(error);
    }
}
