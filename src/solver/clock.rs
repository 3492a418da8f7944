//! The frame's clock: the milliseconds its phases took, and when its passes stop early
//! ([`Stop`]). Every pass reads it, so it is a module of its own rather than a helper of one
//! of them.

use std::time::{Duration, Instant};

/// Milliseconds since `t` (the phase times of [`FrameReport`](super::report::FrameReport)).
pub(super) fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// When a frame's two passes stop before their configured iterations or convergence: never,
/// when another iteration would overrun a moment (an editor's time budget), or after given
/// counts of iterations (a replay of a frame that a budget stopped: the counts its report
/// gave, so the replay stops where the budget did, whatever the clock says). Only the passes
/// stop early; the trials of other rest states and what they propose run whole, so a frame's
/// outcome depends on the clock only through the iterations its passes ran.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Stop {
    /// The passes run to convergence or their configured counts.
    #[default]
    Never,
    /// Another iteration is started only if one as long as the last fits before this moment.
    At(Instant),
    /// Pass 1 runs at most `pass1` iterations, pass 2 at most `pass2` (each at least what a
    /// budget lets it run: two and one).
    After { pass1: usize, pass2: usize },
}

impl Stop {
    /// A stop at `budget` from now (never, if that is beyond the clock's range).
    pub fn within(budget: Duration) -> Self {
        Instant::now()
            .checked_add(budget)
            .map_or(Stop::Never, Stop::At)
    }

    /// Whether pass 1 (or pass 2, `second`) stops before iteration `it` (0-based), the last
    /// having taken `last`.
    pub(super) fn before(self, second: bool, it: usize, last: Duration) -> bool {
        match self {
            Stop::Never => false,
            Stop::At(d) => Instant::now() + last > d,
            Stop::After { pass1, pass2 } => it >= if second { pass2 } else { pass1 },
        }
    }
}
