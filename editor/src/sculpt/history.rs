//! The undo history: the model as it was before each gesture, taken and restored (with the
//! rule log of the gestures, but not what happened outside them, and with the gestures recorded
//! as a script up to it).

use std::sync::Arc;

use clay::Assembly;
use clay_dsl::compiled::CompiledGrammar;

use super::{LogEntry, Recording, Sculpt, Snapshot};

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
            state: self.state,
            record: Recording::new(),
        }
    }

    /// The new grammar's initial model with what of the sculpt survives a rebuild (issue 48: a
    /// parameter change dropped every pin): each pin of an instance the new model has (by its
    /// name, `row[0]`, `t_ne`) holds it where it was pinned, at its new shape
    /// ([`clay::carried_targets`]); each piece instance that survives keeps its rest state when
    /// its piece still has one of that name.
    pub(super) fn carried(&self, grammar: Arc<CompiledGrammar>) -> Snapshot {
        let mut snapshot = self.initial(grammar);
        let (old, old_grammar) = (self.assembly.data(), self.assembly.grammar());
        let new = &snapshot.data;
        let named = |name: &str| new.instances.iter().position(|i| i.name == name);
        let rest = |g: &CompiledGrammar, i: &clay_dsl::compiled::Instance| {
            (g.pieces.get(i.piece)?.states.get(i.state)).map(|s| s.positions.clone())
        };
        let mut pins = Vec::new();
        for pin in self.pins() {
            let Some(was) = old.instances.iter().find(|i| i.vertices == pin.vertices) else {
                continue;
            };
            let Some(now) = named(&was.name).map(|k| &new.instances[k]) else {
                continue;
            };
            let (Some(from), Some(to)) = (rest(old_grammar, was), rest(&snapshot.grammar, now))
            else {
                continue;
            };
            if let Some(at) = clay::carried_targets(&from, &pin.at, &to) {
                pins.push(crate::session::Pin {
                    vertices: now.vertices.clone(),
                    at,
                });
            }
        }
        snapshot.pins = pins;
        // Rest states of the piece instances that survive, by state name: one pass over the
        // new model's piece parts, the old instances looked up by name.
        let old_state: std::collections::HashMap<&str, (&str, &str)> = (old.instances.iter())
            .filter_map(|i| {
                let piece = old_grammar.pieces.get(i.piece)?;
                let state = piece.states.get(i.state)?;
                Some((i.name.as_str(), (piece.name.as_str(), state.name.as_str())))
            })
            .collect();
        let mut data = snapshot.data.clone();
        for part in &mut data.parts {
            let clay_dsl::compiled::PartKind::Piece { instance: k } = part.kind else {
                continue;
            };
            let Some(inst) = data.instances.get_mut(k) else {
                continue;
            };
            let Some(&(piece, state)) = old_state.get(inst.name.as_str()) else {
                continue;
            };
            let Some(p) = snapshot.grammar.pieces.get(inst.piece) else {
                continue;
            };
            if p.name == piece
                && let Some(s) = p.states.iter().position(|st| st.name == state)
                && s < part.states.len()
            {
                inst.state = s;
                part.active = s;
            }
        }
        if data.check(&snapshot.grammar).is_ok() {
            snapshot.data = data;
        }
        snapshot
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
        self.last_state += 1;
        self.state = self.last_state;
    }

    /// Takes back the checkpoint of a gesture that changed nothing: no undo step, and the
    /// model is in the state it was.
    pub(super) fn forget_checkpoint(&mut self) {
        if let Some(s) = self.undo.pop() {
            self.state = s.state;
        }
    }

    /// Undoes the last gesture, or redoes the last undone one.
    pub(super) fn step_history(&mut self, redo: bool) {
        let from = if redo { &mut self.redo } else { &mut self.undo };
        let Some(s) = from.pop() else {
            return;
        };
        let now = self.snapshot();
        if redo {
            self.undo.push(now);
        } else {
            self.redo.push(now);
        }
        self.history += 1;
        self.state = s.state;
        self.restore(s);
    }

    /// Whether the model differs from the one last saved or opened: a gesture since, or undo
    /// and redo to another state (undoing every change since a save is no unsaved work).
    pub fn dirty(&self) -> bool {
        self.saved != Some(self.state)
    }

    /// The model as it is now is saved (a session written, or its changes discarded).
    pub fn mark_saved(&mut self) {
        self.saved = Some(self.state);
    }

    /// The model as it is now is nowhere saved (work restored after a crash).
    pub fn mark_unsaved(&mut self) {
        self.saved = None;
    }

    pub(super) fn snapshot(&self) -> Snapshot {
        Snapshot {
            grammar: self.grammar().clone(),
            data: self.assembly.data().clone(),
            pins: self.pins(),
            log: self.log.clone(),
            state: self.state,
            record: self.record.clone(),
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
        self.record = s.record;
        self.assembly = Assembly::from_data(s.grammar, s.data);
        for pin in s.pins {
            clay::pin_at(&mut self.assembly, pin.vertices, &pin.at);
        }
        // A fresh solver: the old one's pattern belongs to another topology. The spare copy
        // belongs to it too (and a restored model counts its generations from 0 again).
        self.session.reset_solver();
        self.spare = None;
        self.error = None;
        self.unsettled = true;
    }
}
