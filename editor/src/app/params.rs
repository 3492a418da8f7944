//! The grammar's parameters set from the editor (`param NAME = ...`): the overrides the
//! Grammar parameters panel asks for, recompiled through hot reload's path so the sculpt is
//! kept where the structure allows. The overrides are the open document's: kept across hot
//! reloads of the file (reconciled with what it declares), dropped when another grammar opens.

use std::path::Path;

use clay_dsl::compiled::{Param, ParamKind, ParamValue};

use crate::compile::{self, CASTLE_PATH, CASTLE_SOURCE, Compiled, Problem};
use crate::sculpt::panels::ParamChange;

use super::EditorApp;

impl EditorApp {
    /// Queues a parameter change as if the Grammar parameters panel had emitted it.
    pub fn param_change(&mut self, c: ParamChange) {
        self.param_changes.push(c);
    }

    /// The values the user set for the grammar's parameters, by name, in the order set.
    pub fn param_overrides(&self) -> &[(String, ParamValue)] {
        &self.param_overrides
    }

    /// Applies one parameter change: the override set (or dropped) and the grammar recompiled
    /// with the overrides, as a hot reload.
    pub(super) fn apply_param_change(&mut self, c: ParamChange) {
        let what = match c {
            ParamChange::Set(name, value) => {
                self.param_overrides.retain(|(n, _)| *n != name);
                let what = format!("{name} = {value}");
                self.param_overrides.push((name, value));
                what
            }
            ParamChange::Reset(name) => {
                self.param_overrides.retain(|(n, _)| *n != name);
                format!("{name} back to its default")
            }
        };
        self.recompile(Some(&what));
    }

    /// Follows the model's grammar: undo and redo bring back a grammar compiled with other
    /// values, and the overrides are those it was compiled with. While the file does not
    /// compile the overrides stay as set (the last good grammar is not theirs).
    pub(super) fn sync_params(&mut self) {
        if self.stale {
            return;
        }
        let grammar = self.sculpt.grammar().clone();
        let set: Vec<&Param> = grammar
            .params
            .iter()
            .filter(|p| p.value != p.default)
            .collect();
        self.param_overrides
            .retain(|(n, _)| set.iter().any(|p| p.name == *n));
        for p in set {
            match self.param_overrides.iter_mut().find(|(n, _)| *n == p.name) {
                Some(o) => o.1 = p.value.clone(),
                None => self.param_overrides.push((p.name.clone(), p.value.clone())),
            }
        }
    }

    /// The overrides for the status bar: `bays = 6, height = 2.5`.
    pub(super) fn params_status(&self) -> Option<String> {
        (!self.param_overrides.is_empty()).then(|| {
            let set: Vec<String> = self
                .param_overrides
                .iter()
                .map(|(n, v)| format!("{n} = {v}"))
                .collect();
            format!("parameters: {}", set.join(", "))
        })
    }

    /// Compiles the open grammar (its file, or the bundled castle) with the overrides. The
    /// grammar is compiled with its defaults first: overrides for parameters it no longer
    /// declares are dropped and values now outside a range clamped, each said in the notes.
    pub(super) fn compile_current(
        &mut self,
        path: Option<&Path>,
        notes: &mut Vec<String>,
    ) -> Result<Compiled, Vec<Problem>> {
        let (source, shown) = match path {
            Some(p) => {
                let shown = p.display().to_string();
                match clay_dsl::read_input_string(p, clay_dsl::MAX_SOURCE_BYTES) {
                    Ok(t) => (t, shown),
                    Err(e) => {
                        return Err(vec![Problem::whole_file(
                            &shown,
                            format!("cannot read it: {e}"),
                        )]);
                    }
                }
            }
            None => (CASTLE_SOURCE.to_string(), CASTLE_PATH.to_string()),
        };
        let plain = compile::compile(&source, &shown, &[])?;
        if self.param_overrides.is_empty() {
            return Ok(plain);
        }
        notes.extend(self.reconcile_params(&plain.grammar.params));
        if self.param_overrides.is_empty() {
            return Ok(plain);
        }
        compile::compile(&source, &shown, &self.param_overrides)
    }

    /// Fits the overrides to the parameters the grammar declares now; says what changed.
    fn reconcile_params(&mut self, declared: &[Param]) -> Vec<String> {
        let mut notes = Vec::new();
        self.param_overrides.retain_mut(|(name, value)| {
            let Some(p) = declared.iter().find(|p| p.name == *name) else {
                notes.push(format!(
                    "{name} is no longer a parameter: its value {value} dropped"
                ));
                return false;
            };
            let fits = match (&p.kind, &*value) {
                (ParamKind::Bool, ParamValue::Bool(_)) => true,
                (ParamKind::Choice { choices }, ParamValue::Text(t)) => choices.contains(t),
                (k, ParamValue::Number(v)) if k.is_numeric() => !k.is_whole() || v.fract() == 0.0,
                _ => false,
            };
            if !fits {
                notes.push(format!(
                    "{name} = {value} is no value of its type `{}` now: dropped",
                    p.kind.word()
                ));
                return false;
            }
            if let (Some([lo, hi]), ParamValue::Number(v)) = (p.range, &*value)
                && !(lo..=hi).contains(v)
            {
                let clamped = v.clamp(lo, hi);
                notes.push(format!(
                    "{name} = {value} is outside {lo}..{hi} now: clamped to {clamped}"
                ));
                *value = ParamValue::Number(clamped);
            }
            true
        });
        notes
    }
}
