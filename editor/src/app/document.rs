//! The open grammar: opening it, hot reload of it and its imports, the window title, and
//! sessions (the sculpt saved and opened with its grammar). No drawing here.

use std::path::{Path, PathBuf};

use clay_dsl::compiled::ParamValue;

use crate::compile::{
    self, CASTLE_PATH, CASTLE_SOURCE, Compiled, Problem, Severity, check_grammar, empty_grammar,
};
use crate::sculpt::Sculpt;
use crate::session::{self, SavedSession};
use crate::watch::FileWatch;

use super::{EditorApp, TITLE};

/// A session read and checked against its grammar, not yet the editor's.
pub(super) struct LoadedSession {
    pub(super) sculpt: Sculpt,
    pub(super) warnings: Vec<Problem>,
    /// The grammar's file (`None`: the bundled castle).
    pub(super) grammar_file: Option<PathBuf>,
    /// The grammar's parameters as the session set them.
    pub(super) params: Vec<(String, ParamValue)>,
}

/// Reads a session and rebuilds its sculpt, touching nothing of the editor's.
pub(super) fn load_session(path: &Path) -> Result<LoadedSession, String> {
    let s = session::read(path).map_err(|e| e.to_string())?;
    let grammar_path = PathBuf::from(&s.grammar);
    let (source, file) =
        match clay_dsl::read_input_string(&grammar_path, clay_dsl::MAX_SOURCE_BYTES) {
            Ok(text) => (text, Some(grammar_path.clone())),
            Err(_) if s.grammar == CASTLE_PATH => (CASTLE_SOURCE.to_string(), None),
            Err(e) => return Err(format!("the session's grammar {}: {e}", s.grammar)),
        };
    // The parameters as set when it was saved, so the assembly fits the grammar it was made
    // with.
    let params: Vec<(String, ParamValue)> = s.params.into_iter().collect();
    let compiled = compile::compile(&source, &s.grammar, &params).map_err(|problems| {
        let first = problems.first().map_or(String::new(), |p| p.to_string());
        format!("the session's grammar does not compile: {first}")
    })?;
    let sculpt = Sculpt::from_saved(compiled.grammar, s.assembly, s.pins, s.settings, s.log)?;
    Ok(LoadedSession {
        sculpt,
        warnings: compiled.warnings,
        grammar_file: file,
        params,
    })
}

impl EditorApp {
    /// The window title: the file's name, `*` when the sculpt has unsaved changes, and `Clay`.
    pub fn title(&self) -> String {
        let shown = self.display_path();
        let name = Path::new(&shown)
            .file_name()
            .map_or(shown.clone(), |n| n.to_string_lossy().into_owned());
        let dirty = if self.sculpt.dirty() { "*" } else { "" };
        format!("{name}{dirty} \u{2022} {TITLE}")
    }

    pub(super) fn display_path(&self) -> String {
        match &self.grammar_path {
            Some(p) => p.display().to_string(),
            // The bundled castle, or an authored grammar not written to a file.
            None if self.sculpt.grammar().source.is_empty() => CASTLE_PATH.to_string(),
            None => self.sculpt.grammar().source.clone(),
        }
    }

    /// Opens a grammar file. A file that cannot be read or does not compile is not opened:
    /// the current model stays and the file's problems are listed as the refused file's. Only
    /// an editor with no model yet takes a broken file, and watches it, so that hot reload
    /// picks up the fix.
    pub(super) fn open_grammar(&mut self, path: &Path) -> Result<String, String> {
        let shown = path.display().to_string();
        match check_grammar(path) {
            Ok(compiled) => {
                self.refused = None;
                self.grammar_path = Some(path.to_path_buf());
                self.session_path = None;
                self.adopt(compiled);
                self.start_watch(path);
                self.remember(path, false);
                Ok(format!("opened {shown}"))
            }
            Err(problems) if self.sculpt.data().parts.is_empty() => {
                self.refused = None;
                self.problems = problems;
                self.stale = true;
                self.grammar_path = Some(path.to_path_buf());
                self.session_path = None;
                self.param_overrides.clear();
                self.sculpt = Sculpt::new(empty_grammar(&shown));
                self.canvas.grammar_changed();
                self.start_watch(path);
                Err(format!(
                    "{shown} has problems (see Diagnostics); it loads as soon as it compiles"
                ))
            }
            Err(problems) => {
                let why = problems
                    .first()
                    .map_or("it does not compile".to_string(), |p| p.message.clone());
                let errors = problems
                    .iter()
                    .filter(|p| p.severity == Severity::Error)
                    .count();
                self.refused = Some((shown.clone(), problems));
                Err(format!(
                    "{shown} was not opened ({why}{}); the current model stays",
                    if errors > 1 {
                        format!(", and {} more errors", errors - 1)
                    } else {
                        String::new()
                    }
                ))
            }
        }
    }

    /// A good compile becomes the model: a new sculpt, the view fitted, no parameter set.
    pub(super) fn adopt(&mut self, compiled: Compiled) {
        self.param_overrides.clear();
        self.watch_imports(compiled.imports.clone());
        self.problems = compiled.warnings;
        self.stale = false;
        self.sculpt = Sculpt::new(compiled.grammar);
        self.canvas.grammar_changed();
        self.canvas.request_fit();
    }

    pub(super) fn load_grammar_text(&mut self, path: Option<&Path>, source: &str, shown: &str) {
        self.grammar_path = path.map(Path::to_path_buf);
        match compile::compile(source, shown, &[]) {
            Ok(c) => self.adopt(c),
            Err(problems) => {
                self.param_overrides.clear();
                self.imports.clear();
                self.problems = problems;
                self.stale = true;
                self.sculpt = Sculpt::new(empty_grammar(shown));
                self.canvas.grammar_changed();
                self.canvas.request_fit();
            }
        }
    }

    /// Hot reload also follows the grammar's imported files.
    pub(super) fn watch_imports(&mut self, imports: Vec<String>) {
        self.imports = imports;
        if let Some(w) = &mut self.watch {
            w.also(&self.imports);
        }
    }

    pub(super) fn start_watch(&mut self, path: &Path) {
        let waker = self.waker.clone();
        match FileWatch::new(path, move || {
            if let Some(ctx) = &waker {
                ctx.request_repaint();
            }
        }) {
            Ok(mut w) => {
                w.also(&self.imports);
                self.watch = Some(w);
            }
            Err(e) => {
                self.watch = None;
                self.message = Some(format!(
                    "hot reload is off: cannot watch {}: {e}",
                    path.display()
                ));
            }
        }
    }

    /// Recompiles the grammar file: a good compile replaces the model (keeping the view, as
    /// one undoable step); a bad one keeps the last good model and shows the errors.
    pub fn reload(&mut self) {
        if self.grammar_path.is_some() {
            self.recompile(None);
        }
    }

    /// Recompiles the open grammar with the parameters' overrides, for hot reload (`change`
    /// `None`) or for a change of a parameter (`change` says which). A good compile replaces
    /// the model, keeping the sculpt where the structure allows; a bad one keeps the last
    /// good model and shows the errors.
    pub(super) fn recompile(&mut self, change: Option<&str>) {
        let path = self.grammar_path.clone();
        let shown = self.display_path();
        if path.is_none() && shown != CASTLE_PATH {
            self.message = Some(
                "write the authored grammar to a file first (Author mode, Write grammar) to set its parameters"
                    .into(),
            );
            return;
        }
        let mut notes = Vec::new();
        match self.compile_current(path.as_deref(), &mut notes) {
            Ok(c) => {
                self.watch_imports(c.imports.clone());
                self.problems = c.warnings;
                let first_good = self.stale && self.sculpt.data().parts.is_empty();
                self.stale = false;
                let kept = self.sculpt.replace_grammar(c.grammar);
                self.canvas.grammar_changed();
                if first_good {
                    self.canvas.request_fit();
                }
                let what = change.map_or_else(|| format!("reloaded {shown}"), str::to_string);
                let pins = self.sculpt.pins().len();
                let mut m = match (kept, pins) {
                    (true, _) => format!("{what}; sculpt kept"),
                    (false, 0) => format!("{what}; model rebuilt"),
                    (false, n) => format!(
                        "{what}; model rebuilt, {n} pin{} kept",
                        if n == 1 { "" } else { "s" }
                    ),
                };
                for n in notes {
                    m.push_str("; ");
                    m.push_str(&n);
                }
                self.message = Some(m);
            }
            Err(problems) => {
                let first = problems.first().map_or(String::new(), |p| {
                    format!(" (line {}: {})", p.line, p.message)
                });
                self.problems = problems;
                self.stale = true;
                let what = if self.sculpt.data().parts.is_empty() {
                    "no model yet"
                } else {
                    "the last good model stays"
                };
                let mut m = format!("{shown} does not compile{first}; {what}");
                if let Some(c) = change {
                    m = format!("{c}: {m}");
                }
                self.sculpt
                    .note_outside_history(format!("reload failed: {m}"));
                self.message = Some(m);
            }
        }
        self.drop_stale_source();
    }

    /// The sculpt as a session.
    pub fn session(&self) -> SavedSession {
        let grammar = match &self.grammar_path {
            Some(p) => std::path::absolute(p)
                .unwrap_or_else(|_| p.clone())
                .display()
                .to_string(),
            None => CASTLE_PATH.to_string(),
        };
        let mut session = SavedSession::new(
            grammar,
            self.sculpt.data().clone(),
            self.sculpt.pins(),
            Some(self.sculpt.settings()),
        );
        session.log = self.sculpt.log().to_vec();
        session.params = self.param_overrides.iter().cloned().collect();
        session
    }

    /// Saves the sculpt atomically.
    pub fn save_session(&mut self, path: &Path) -> Result<(), String> {
        if self.grammar_path.is_none() && self.sculpt.grammar().source != CASTLE_PATH {
            return Err(
                "write the authored grammar to a file first (Author mode, Write grammar): a session names its grammar file"
                    .into(),
            );
        }
        session::write(path, &self.session()).map_err(|e| e.to_string())?;
        self.session_path = Some(path.to_path_buf());
        self.sculpt.mark_saved();
        Ok(())
    }

    /// Opens a session: compiles its grammar and restores the sculpt (and its rule log). On
    /// any error the current sculpt stays.
    pub fn open_session(&mut self, path: &Path) -> Result<(), String> {
        let loaded = load_session(path)?;
        self.sculpt = loaded.sculpt;
        self.param_overrides = loaded.params;
        self.problems = loaded.warnings;
        self.stale = false;
        self.refused = None;
        self.grammar_path = loaded.grammar_file.clone();
        self.session_path = Some(path.to_path_buf());
        self.canvas.grammar_changed();
        self.canvas.request_fit();
        match loaded.grammar_file {
            Some(f) => self.start_watch(&f),
            None => self.watch = None,
        }
        Ok(())
    }
}
