//! One sculpting frame (the session's solver frame, then its rules) within a budget, on
//! whichever thread runs it, with its log lines; a panic in it is caught. Also the request and
//! result of a frame run on the background worker.

use std::time::Duration;

use clay::{Assembly, FrameReport, Session, SolverError};
use glam::DVec2;

/// A background solver frame to run: the model, solver and rules to work on, within `budget`.
pub(super) struct Request {
    pub(super) model: Assembly,
    pub(super) session: Session,
    pub(super) budget: Duration,
    /// A model no longer needed, freed on the worker's thread.
    pub(super) stale: Option<Assembly>,
}

/// One background solver frame, as the worker's thread runs it.
pub(super) fn run_request(request: Request) -> Job {
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
pub(super) struct Job {
    pub(super) model: Assembly,
    /// A copy of `model`, made when a rule rewrote it (the next frame starts from it).
    pub(super) spare: Option<Assembly>,
    pub(super) session: Session,
    pub(super) outcome: FrameOutcome,
}

/// What one solver frame and the rules after it did.
pub(super) struct FrameOutcome {
    pub(super) report: Result<FrameReport, SolverError>,
    /// Log lines of the frame (state switches of stretch parts, rule events), in order.
    pub(super) notes: Vec<(String, Option<DVec2>)>,
    /// A rule rewrote the model.
    pub(super) rewrote: bool,
    /// The frame panicked: the model it worked on may be half rewritten.
    pub(super) panicked: bool,
}

/// One sculpting frame within `budget` (the session's: a solver frame, then the rules), on
/// whichever thread, with its log lines in the grammar's names.
///
/// A panic in the solver or the rules is caught: the outcome says so, and the caller keeps
/// the last good model (the editor never exits on a model it was given).
pub(super) fn solve_frame(
    assembly: &mut Assembly,
    session: &mut Session,
    budget: Duration,
) -> FrameOutcome {
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
