//! File actions performed after the frame: opening (checked first, confirmed when it would
//! discard unsaved work), saving, exporting, authoring's writes and tries, recent files, crash
//! recovery, and asking for a path.

use std::path::{Path, PathBuf};
use std::time::Duration;

use crate::action::Action;
use crate::compile::{self, CASTLE_PATH, Compiled, check_grammar};
use crate::files::{FileKind, NativeDialog};

use super::document::load_session;
use super::{EditorApp, Mode, PathDialog};

impl EditorApp {
    /// Puts a file first in the recent files, kept in the user's config folder.
    pub(super) fn remember(&mut self, path: &Path, session: bool) {
        self.recent.add(path, session);
        if let Some(store) = self.desktop.recent_store.clone()
            && let Err(e) = self.recent.save(&store)
        {
            self.sculpt
                .note_outside_history(format!("could not remember recent files: {e}"));
        }
    }

    /// Writes the unsaved sculpt to the recovery file when it is due (`Recovery::keep`).
    pub(super) fn keep_recovery(&mut self) {
        let Some(mut r) = self.recovery.take() else {
            return;
        };
        let stamp = (self.sculpt.history(), self.sculpt.revision());
        let unsaved = self.sculpt.dirty() && !self.quitting;
        let savable = self.grammar_path.is_some() || self.sculpt.grammar().source == CASTLE_PATH;
        if let Some(m) = r.keep(stamp, unsaved, || savable.then(|| self.session())) {
            self.message = Some(m);
        }
        self.recovery = Some(r);
    }

    /// Restores the sculpt in the recovery file: unsaved, with no session file of its own.
    pub(super) fn restore_recovery(&mut self) -> Result<Option<String>, String> {
        let Some(path) = self.recovery.as_ref().map(|r| r.path().to_path_buf()) else {
            return Ok(None);
        };
        let restored = self.open_session(&path);
        if let Some(r) = &mut self.recovery {
            r.answered();
        }
        restored?;
        self.session_path = None;
        self.sculpt.mark_unsaved();
        Ok(Some("restored the unsaved sculpt".to_string()))
    }

    /// Performs a file action now (tests and the UI's queue). An action that would replace
    /// the sculpt is checked first (the file read and compiled), so a mistyped path or a broken
    /// file is reported without asking to discard anything; with unsaved changes it then asks
    /// Save, Discard or Cancel.
    pub fn perform(&mut self, action: Action) {
        let discards = matches!(
            action,
            Action::OpenGrammar(_) | Action::OpenSession(_) | Action::TryAuthored
        );
        if discards && self.sculpt.dirty() {
            match self.precheck(&action) {
                Ok(()) => self.confirm = Some(action),
                Err(e) => self.fail(e),
            }
            return;
        }
        let result = match action {
            Action::Ask(kind) => {
                self.ask(kind);
                Ok(None)
            }
            Action::OpenGrammar(p) => self.open_grammar(&p).map(Some),
            Action::OpenSession(p) => self.open_session(&p).map(|()| {
                self.remember(&p, true);
                Some(format!("opened session {}", p.display()))
            }),
            Action::SaveSession(p) => self.save_session(&p).map(|()| {
                self.remember(&p, true);
                if let Some(next) = self.after_save.take() {
                    self.actions.push(next);
                }
                Some(format!("saved {}", p.display()))
            }),
            Action::ExportPng(p) => self
                .export_png(&p)
                .map(|()| Some(format!("exported {}", p.display()))),
            Action::ExportJson(p) => self
                .export_json(&p)
                .map(|()| Some(format!("exported {}", p.display()))),
            Action::Export3d(p) => self
                .export_3d(&p)
                .map(|()| Some(format!("exported {}", p.display()))),
            Action::SaveGestures(p) => self.save_gestures(&p).map(Some),
            Action::Quit => {
                if self.sculpt.dirty() {
                    self.confirm = Some(Action::Quit);
                } else {
                    self.quitting = true;
                }
                Ok(None)
            }
            Action::ImportSvg(p, scale) => self.author.import_svg(&p, scale).map(|()| {
                self.author_canvas.request_fit();
                Some(format!("imported {}", p.display()))
            }),
            Action::WriteGrammar(p) => self.author.write(&p).map(|()| {
                let verdict = if self.author.compiles {
                    "it compiles"
                } else {
                    "it does not compile yet"
                };
                Some(format!("wrote {}; {verdict}", p.display()))
            }),
            Action::TryAuthored => self.try_authored().map(Some),
            Action::Report(m) => Ok(Some(m)),
            Action::RestoreRecovery => self.restore_recovery(),
            Action::DiscardRecovery => {
                if let Some(r) = &mut self.recovery {
                    r.clear();
                }
                Ok(Some("discarded the unsaved work".to_string()))
            }
        };
        match result {
            Ok(Some(m)) => self.message = Some(m),
            Ok(None) => {}
            Err(e) => self.fail(e),
        }
    }

    /// A file action failed: said in the status bar and kept in the log.
    pub(super) fn fail(&mut self, e: String) {
        // A Save from the unsaved-changes prompt that failed must not go on to discard.
        self.after_save = None;
        self.sculpt.note_outside_history(e.clone());
        self.message = Some(format!("error: {e}"));
    }

    /// Whether an action that replaces the sculpt would succeed, without doing it.
    pub(super) fn precheck(&mut self, action: &Action) -> Result<(), String> {
        match action {
            Action::OpenGrammar(p) => check_grammar(p).map(drop).map_err(|problems| {
                let shown = p.display().to_string();
                let why = problems
                    .first()
                    .map_or(String::new(), |p| format!(" ({})", p.message));
                self.refused = Some((shown.clone(), problems));
                format!("{shown} was not opened{why}; the current model stays")
            }),
            Action::OpenSession(p) => load_session(p).map(drop),
            Action::TryAuthored => self.authored().map(drop),
            _ => Ok(()),
        }
    }

    /// Asks for a path: the desktop's file dialog where there is one, else a typed path.
    pub(super) fn ask(&mut self, kind: FileKind) {
        let path = match kind {
            FileKind::Grammar => PathBuf::from(self.display_path()),
            FileKind::OpenSession | FileKind::SaveSession => match &self.session_path {
                Some(p) => p.clone(),
                None => self.suggested("clay-session.json"),
            },
            FileKind::Png => self.suggested("png"),
            FileKind::Json => self.suggested("assembly.json"),
            FileKind::Model3d => self.suggested("glb"),
            FileKind::GestureScript => self.suggested("script.json"),
            FileKind::WriteGrammar => match &self.author.written {
                Some((p, _)) => p.clone(),
                None => self.folder().join(crate::author::UNSAVED_NAME),
            },
        };
        // Absolute: the dialog shows where the file goes, whatever folder the editor runs in.
        let path = std::path::absolute(&path).unwrap_or(path);
        let text = path.display().to_string();
        if self.desktop.native_dialogs {
            self.native = Some(NativeDialog::open(kind, Path::new(&text)));
        } else {
            self.dialog = Some(PathDialog {
                kind,
                text,
                replace: None,
            });
        }
    }

    /// The folder a new file is suggested in: the grammar's, else the session's, else the
    /// user's home (never just the folder the editor was started in).
    fn folder(&self) -> PathBuf {
        let beside = |p: &Path| {
            std::path::absolute(p)
                .ok()
                .and_then(|p| p.parent().map(Path::to_path_buf))
        };
        (self.grammar_path.as_deref().and_then(beside))
            .or_else(|| self.session_path.as_deref().and_then(beside))
            .or_else(|| directories::UserDirs::new().map(|d| d.home_dir().to_path_buf()))
            .unwrap_or_else(|| std::env::current_dir().unwrap_or_default())
    }

    /// A new file's suggested path: in [`Self::folder`], named after the grammar with
    /// `extension` (`castle.png`), or `sculpt.EXTENSION` for a grammar with no file.
    /// A new file's suggested name: the grammar's stem and `extension` beside it, numbered
    /// (`wall-2.script.json`) past files that exist, so accepting a suggestion never replaces
    /// one (the bundled `wall.script.json` was).
    fn suggested(&self, extension: &str) -> PathBuf {
        let stem = (self.grammar_path.as_deref())
            .and_then(Path::file_stem)
            .map_or("sculpt".to_string(), |s| s.to_string_lossy().into_owned());
        let folder = self.folder();
        let first = folder.join(format!("{stem}.{extension}"));
        if !first.exists() {
            return first;
        }
        // All taken: the first, and the dialog asks before replacing it.
        (2..1000)
            .map(|k| folder.join(format!("{stem}-{k}.{extension}")))
            .find(|p| !p.exists())
            .unwrap_or(first)
    }

    /// Takes the native dialog's answer once it has one.
    pub(super) fn poll_native_dialog(&mut self, ctx: &egui::Context) {
        let Some(d) = &self.native else {
            return;
        };
        match d.poll() {
            None => ctx.request_repaint_after(Duration::from_millis(100)),
            Some(picked) => {
                let kind = d.kind;
                self.native = None;
                match picked {
                    Some(p) => self.actions.push(Action::for_path(kind, p)),
                    // Cancelled: a Save the prompt asked for is not made, so nothing goes on.
                    None => self.after_save = None,
                }
            }
        }
    }

    /// The authored grammar compiled, its name, and the file it was written to (if the text
    /// there is the same).
    pub(super) fn authored(&self) -> Result<(Compiled, String, Option<PathBuf>), String> {
        let text = match &self.author.result {
            Ok(c) => c.text.clone(),
            Err(e) => return Err(format!("nothing to try: {e}")),
        };
        let name = self.author.source_name();
        let compiled = compile::compile(&text, &name, &[]).map_err(|problems| {
            let first = problems.first().map_or(String::new(), |p| p.to_string());
            format!("the authored grammar does not compile: {first}")
        })?;
        let written = self
            .author
            .written
            .as_ref()
            .filter(|(_, t)| *t == text)
            .map(|(p, _)| p.clone());
        Ok((compiled, name, written))
    }

    /// Compiles the authored grammar and sculpts it (switching to sculpt mode). The grammar
    /// file is watched if the text was written to one; the authoring work stays.
    pub fn try_authored(&mut self) -> Result<String, String> {
        let (compiled, name, written) = self.authored()?;
        self.adopt(compiled);
        self.grammar_path = written.clone();
        self.session_path = None;
        match written {
            Some(p) => {
                self.start_watch(&p);
                self.remember(&p, false);
            }
            None => self.watch = None,
        }
        self.mode = Mode::Sculpt;
        Ok(format!("sculpting {name}"))
    }
}
