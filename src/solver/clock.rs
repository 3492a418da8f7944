//! The frame's clock: the milliseconds its phases took, and whether another iteration fits
//! before the deadline of a budgeted frame. Every pass reads it, so it is a module of its
//! own rather than a helper of one of them.

use std::time::{Duration, Instant};

/// Milliseconds since `t` (the phase times of [`FrameReport`](super::report::FrameReport)).
pub(super) fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// Would another iteration that lasts as long as the last one overrun the deadline?
pub(super) fn out_of_time(deadline: Option<Instant>, last: Duration) -> bool {
    deadline.is_some_and(|d| Instant::now() + last > d)
}
