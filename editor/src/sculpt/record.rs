//! The gestures recorded as a script (File > Save gestures as script): since the grammar's
//! initial model (opened, reset or rebuilt by a reload), every grab, move and turn of the
//! grab, release, pin, unpin and cut, and the solver frames run between them, as steps of
//! `clay::Script`. `clayc run GRAMMAR --script FILE` (or `clay::replay` on the
//! grammar's initial model) then does what the editor did: the same steps through the same
//! gesture functions, one solver frame per frame the editor ran.
//!
//! The recording is part of the undo history: a [`super::Snapshot`] keeps the recording as
//! it was before its gesture, so undoing a gesture takes its steps out of the script and redo
//! puts them back; the frames run after the undo are held from where the model went back to.
//! The steps are kept in shared chunks, so the copies in the undo history share them: a long
//! session's recording is in memory once, not once per undo step.

use std::sync::Arc;

use clay::{Motion, Script, Selector, Step};
use glam::DVec2;

/// Most frames one `hold` step may ask for; longer waits are split.
const MAX_HOLD: u64 = clay::MAX_FRAMES;

/// Steps kept unshared at most: more are frozen into a chunk the copies share.
const CHUNK: usize = 256;

/// The steps that make the sculpt from the grammar's initial model.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Recording {
    /// The steps before `steps`, in chunks shared with the copies in the undo history.
    frozen: Vec<Arc<[Step]>>,
    /// The latest steps (at most [`CHUNK`]).
    steps: Vec<Step>,
    /// Solver frames run since the last step, not yet written as a `hold`.
    held: u64,
    /// The grab's target (translation, angle in radians) as the steps have placed it.
    target: (DVec2, f64),
    /// The grab's target as the user last moved it, not yet seen by a solver frame.
    pending: Option<(DVec2, f64)>,
    /// Why the steps do not make the sculpt from the grammar's initial model (it was opened
    /// from a session, or restored after a crash): nothing is recorded then.
    unknown_start: Option<String>,
}

impl Recording {
    /// An empty recording, from the grammar's initial model.
    pub(super) fn new() -> Self {
        Self {
            frozen: Vec::new(),
            steps: Vec::new(),
            held: 0,
            target: (DVec2::ZERO, 0.0),
            pending: None,
            unknown_start: None,
        }
    }

    /// No recording: the sculpt did not start from the grammar's initial model (`why`).
    pub(super) fn unknown(why: String) -> Self {
        Self {
            unknown_start: Some(why),
            ..Self::new()
        }
    }

    fn on(&self) -> bool {
        self.unknown_start.is_none()
    }

    /// Writes the frames held since the last step, then `step`.
    fn push(&mut self, step: Step) {
        if !self.on() {
            return;
        }
        self.write_held();
        self.append(step);
    }

    fn append(&mut self, step: Step) {
        if self.steps.len() >= CHUNK {
            let chunk: Arc<[Step]> = std::mem::take(&mut self.steps).into();
            self.frozen.push(chunk);
        }
        self.steps.push(step);
    }

    fn write_held(&mut self) {
        while self.held > 0 {
            let frames = self.held.min(MAX_HOLD);
            self.append(Step::Hold { frames });
            self.held -= frames;
        }
    }

    /// A grab of the instance whose centroid is `centre` (the script selects the instance
    /// nearest a point: its own centroid).
    pub(super) fn grab(&mut self, centre: DVec2) {
        self.pending = None;
        self.push(Step::Grab(Selector::At(centre)));
        self.target = (DVec2::ZERO, 0.0);
    }

    /// The grab's target moved (applied from the next solver frame on).
    pub(super) fn moved(&mut self, translation: DVec2, angle: f64) {
        self.pending = Some((translation, angle));
    }

    /// A solver frame starts: the grab's last move is what it sees, so it becomes steps now
    /// (a drag and a turn that jump, without a frame of their own).
    pub(super) fn frame_starts(&mut self) {
        let Some((translation, angle)) = self.pending.take() else {
            return;
        };
        let (t0, a0) = self.target;
        self.target = (translation, angle);
        if translation != t0 {
            self.push(Step::Drag {
                motion: Motion::By(translation - t0),
                frames: 0,
            });
        }
        if angle != a0 {
            self.push(Step::Rotate {
                degrees: (angle - a0).to_degrees(),
                frames: 0,
            });
        }
    }

    /// A solver frame ran; `stopped`: the iterations of its two passes when the time budget
    /// stopped it early (`FrameReport::complete` false). Right after a move it is that move's
    /// frame (`"frames": 1` runs the frame after the jump, as a jump and a held frame do). A
    /// stopped frame is written as a `budget` step and a held frame after the frames before
    /// it, so the replay stops where the editor's clock did.
    pub(super) fn frame(&mut self, stopped: Option<(u64, u64)>) {
        if let Some((pass1, pass2)) = stopped {
            self.push(Step::Budget { pass1, pass2 });
            self.held = 1;
            return;
        }
        if self.held == 0
            && let Some(Step::Drag { frames, .. } | Step::Rotate { frames, .. }) =
                self.steps.last_mut()
            && *frames == 0
        {
            *frames = 1;
            return;
        }
        self.held += 1;
    }

    /// The grab was let go (a pinned instance is pinned again where it is dropped, as the
    /// script's `release` does through the same gesture).
    pub(super) fn release(&mut self) {
        self.frame_starts();
        self.push(Step::Release);
    }

    /// The instance whose centroid is `centre` was pinned (`true`) or unpinned.
    pub(super) fn pin(&mut self, centre: DVec2, pinned: bool) {
        let sel = Selector::At(centre);
        self.push(if pinned {
            Step::Pin(sel)
        } else {
            Step::Unpin(sel)
        });
    }

    /// A cut at `point` that cut a connection.
    pub(super) fn cut(&mut self, point: DVec2) {
        self.push(Step::Cut { at: point });
    }

    /// The script so far, the frames held since the last step and a move not yet solved
    /// included. `Err` says why there is none.
    pub(super) fn script(&self) -> Result<Script, String> {
        if let Some(why) = &self.unknown_start {
            return Err(why.clone());
        }
        // The move not yet solved and the frames held, as steps after the recorded ones.
        let mut done = Self {
            frozen: Vec::new(),
            steps: Vec::new(),
            held: self.held,
            target: self.target,
            pending: self.pending,
            unknown_start: None,
        };
        done.frame_starts();
        done.write_held();
        let steps = (self.frozen.iter().flat_map(|c| c.iter()))
            .chain(&self.steps)
            .chain(&done.steps)
            .cloned()
            .collect();
        Ok(Script {
            steps,
            ..Script::default()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moves_become_steps_when_a_frame_sees_them() {
        let mut r = Recording::new();
        r.frame(None);
        r.frame(None);
        r.grab(DVec2::new(7.0, 0.0));
        // Two moves before a frame: only the last is seen.
        r.moved(DVec2::new(0.5, 0.0), 0.0);
        r.moved(DVec2::new(1.0, 0.0), 0.0);
        r.frame_starts();
        r.frame(None);
        r.frame_starts();
        r.frame(None);
        r.moved(DVec2::new(1.0, 0.5), 0.25);
        r.frame_starts();
        r.frame(None);
        r.release();
        r.pin(DVec2::new(8.0, 0.0), true);
        r.frame(None);
        let steps = r.script().unwrap().steps;
        assert_eq!(
            steps,
            vec![
                Step::Hold { frames: 2 },
                Step::Grab(Selector::At(DVec2::new(7.0, 0.0))),
                Step::Drag {
                    motion: Motion::By(DVec2::new(1.0, 0.0)),
                    frames: 1
                },
                Step::Hold { frames: 1 },
                Step::Drag {
                    motion: Motion::By(DVec2::new(0.0, 0.5)),
                    frames: 0
                },
                Step::Rotate {
                    degrees: 0.25f64.to_degrees(),
                    frames: 1
                },
                Step::Release,
                Step::Pin(Selector::At(DVec2::new(8.0, 0.0))),
                Step::Hold { frames: 1 },
            ]
        );
    }

    #[test]
    fn a_frame_the_budget_stopped_is_a_budget_step_before_its_frame() {
        let mut r = Recording::new();
        r.frame(None);
        r.frame(None);
        // a held frame stopped: the frames before it, then its budget and itself
        r.frame(Some((2, 1)));
        r.frame(None);
        r.grab(DVec2::new(7.0, 0.0));
        r.moved(DVec2::new(1.0, 0.0), 0.0);
        r.frame_starts();
        // a move's frame stopped: the move jumps, then the budget and the frame
        r.frame(Some((3, 4)));
        let budget = |pass1, pass2| Step::Budget { pass1, pass2 };
        assert_eq!(
            r.script().unwrap().steps,
            vec![
                Step::Hold { frames: 2 },
                budget(2, 1),
                Step::Hold { frames: 2 },
                Step::Grab(Selector::At(DVec2::new(7.0, 0.0))),
                Step::Drag {
                    motion: Motion::By(DVec2::new(1.0, 0.0)),
                    frames: 0
                },
                budget(3, 4),
                Step::Hold { frames: 1 },
            ]
        );
    }

    #[test]
    fn copies_share_the_steps_and_the_script_keeps_their_order() {
        let mut r = Recording::new();
        for k in 0..(3 * CHUNK + 5) {
            r.pin(DVec2::new(k as f64, 0.0), k % 2 == 0);
            r.frame(None);
        }
        let copy = r.clone();
        // a pin and a held frame each, less the last frame (held, not yet a step)
        let recorded = 2 * (3 * CHUNK + 5) - 1;
        assert_eq!(r.frozen.len(), recorded / CHUNK);
        assert!((r.frozen.iter().zip(&copy.frozen)).all(|(a, b)| Arc::ptr_eq(a, b)));
        assert!(copy.steps.len() <= CHUNK);
        let steps = copy.script().unwrap().steps;
        assert_eq!(steps.len(), 2 * (3 * CHUNK + 5));
        for (k, pair) in steps.chunks(2).enumerate() {
            let sel = Selector::At(DVec2::new(k as f64, 0.0));
            let pin = if k % 2 == 0 {
                Step::Pin(sel)
            } else {
                Step::Unpin(sel)
            };
            assert_eq!(pair, [pin, Step::Hold { frames: 1 }]);
        }
    }

    #[test]
    fn a_sculpt_from_elsewhere_has_no_script() {
        let mut r = Recording::unknown("opened from a session".into());
        r.grab(DVec2::ZERO);
        r.frame(None);
        assert_eq!(r.script(), Err("opened from a session".to_string()));
    }
}
