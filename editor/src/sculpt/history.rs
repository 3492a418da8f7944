//! The undo history: the model as it was before each gesture, taken and restored (with the
//! rule log of the gestures, but not what happened outside them).

use std::sync::Arc;

use clay::assembly::Assembly;
use clay_dsl::compiled::CompiledGrammar;

use super::{LogEntry, Sculpt, Snapshot};

/// Most gestures kept for undo.
const UNDO_LIMIT: usize = 200;

impl Sculpt {
    /// `grammar`'s initial model, nothing pinned, with the log as it is.
    pub(super) fn initial(&self, grammar: Arc<CompiledGrammar>) -> Snapshot {
        Snapshot {
            data: grammar.assembly.clone(),
            grammar,
            pins: Vec::new(),
            log: self.log.clone(),
        }
    }

    /// Records the model before a gesture.
    pub(super) fn checkpoint(&mut self) {
        self.history += 1;
        let s = self.snapshot();
        self.undo.push(s);
        if self.undo.len() > UNDO_LIMIT {
            self.undo.remove(0);
        }
        self.redo.clear();
        self.dirty = true;
    }

    pub(super) fn snapshot(&self) -> Snapshot {
        Snapshot {
            grammar: self.grammar().clone(),
            data: self.assembly.data().clone(),
            pins: self.pins(),
            log: self.log.clone(),
        }
    }

    pub(super) fn restore(&mut self, s: Snapshot) {
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
}
