//! The sculpt's rule log: what gestures and rules did, in order and bounded, and what happened
//! outside the gestures (kept through undo).

use glam::DVec2;

use super::{LogEntry, Sculpt};

/// Most log entries kept; older ones are dropped.
const LOG_LIMIT: usize = 500;

impl Sculpt {
    /// Logs something that is not part of a gesture (a failed reload, a file error): undo
    /// does not take it back.
    pub fn note_outside_history(&mut self, message: String) {
        self.push_log(message, None, true);
    }

    pub(super) fn note(&mut self, message: String, at: Option<DVec2>) {
        self.push_log(message, at, false);
    }

    pub(super) fn push_log(&mut self, message: String, at: Option<DVec2>, outside: bool) {
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
