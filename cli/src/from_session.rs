//! `--session FILE.json` on `clayc run`, `render` and `export` (issue 40): a sculpt the editor
//! saved (`clay::session_file`), replayed headlessly. The session's grammar is read from its
//! path (a relative one from the session file's folder, else, as the editor opened it, from the
//! current directory) and compiled (with `--param`s, if given); the saved assembly must fit
//! it; its pins are held again as pins and its settings applied, so a `--script` after it goes
//! on from the sculpt as the editor would.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use clay::{Assembly, SolverConfig, configure, session_file, session_file::SessionError};
use clay_dsl::compiled::CompiledGrammar;

use crate::out::IO_ERROR;
use crate::params::ParamArgs;

/// Where a command's model comes from: a grammar FILE, or a sculpt the editor saved
/// (`--session`), one of the two (`clayc run`, `render`, `export`).
#[derive(clap::Args)]
pub struct ModelArgs {
    /// A grammar (.clay; `render` and `export` also take a compiled grammar, .json from
    /// `clayc build`); not with --session.
    #[arg(required_unless_present = "session", conflicts_with = "session")]
    pub file: Option<PathBuf>,
    /// A sculpt session the editor saved (.json): its grammar (compiled with the parameters it
    /// was saved with), sculpted assembly, pins and settings; a --script goes on from it.
    #[arg(long, value_name = "SESSION.json")]
    pub session: Option<PathBuf>,
}

/// Exit code of input errors (a malformed session, a grammar with errors, a misfit).
const INPUT_ERROR: u8 = 1;

/// A saved sculpt, ready to go on.
pub struct Loaded {
    /// The grammar, its solver block with the session's settings.
    pub grammar: CompiledGrammar,
    /// The saved assembly with its pins held.
    pub assembly: Assembly,
    /// The solver settings: the grammar's, with the session's hysteresis and norm.
    pub config: SolverConfig,
}

/// The grammar file a session names, `grammar` as written in `session`.
fn grammar_path(session: &Path, grammar: &str) -> PathBuf {
    let written = Path::new(grammar);
    if written.is_absolute() {
        return written.to_path_buf();
    }
    let beside = session.parent().unwrap_or(Path::new("")).join(written);
    if !beside.exists() && written.exists() {
        return written.to_path_buf();
    }
    beside
}

/// Prints that the session at `session` does not fit its grammar `grammar`, and why; gives
/// the exit code.
fn misfit<'a>(session: &'a Path, grammar: &'a Path) -> impl Fn(String) -> u8 + 'a {
    move |why| {
        errln!(
            "error: {}: the session does not fit its grammar {}: {why}",
            session.display(),
            grammar.display()
        );
        INPUT_ERROR
    }
}

/// Reads the session at `path` and rebuilds its sculpt, with the solver `settings` of
/// `--set` (NAME, VALUE) over the session's; on failure prints why (the session file and,
/// for a JSON mistake, its line and column) and gives the exit code.
pub fn load(path: &Path, params: &ParamArgs, settings: &[(&str, &str)]) -> Result<Loaded, u8> {
    let shown = path.display();
    let saved = session_file::read(path).map_err(|e| match e {
        SessionError::Io { error, .. } => {
            errln!("error: cannot read session {shown}: {error}");
            IO_ERROR
        }
        SessionError::Malformed(m) => {
            errln!("error: {shown}: {m}");
            INPUT_ERROR
        }
    })?;
    let grammar_file = grammar_path(path, &saved.grammar);
    let source =
        clay_dsl::read_input_string(&grammar_file, clay_dsl::MAX_SOURCE_BYTES).map_err(|e| {
            errln!(
                "error: {shown}: cannot read the session's grammar {}: {e}",
                grammar_file.display()
            );
            IO_ERROR
        })?;
    // The parameters the session was saved with, then `--param`'s (the last value counts).
    let params = crate::params::ParamArgs {
        params: saved
            .params
            .iter()
            .map(|(n, v)| (n.clone(), v.clone()))
            .chain(params.params.iter().cloned())
            .collect(),
    };
    let mut grammar = crate::params::compile(&source, &grammar_file, &params)?;
    saved
        .assembly
        .check(&grammar)
        .map_err(misfit(path, &grammar_file))?;
    // The session's settings, then `--set`'s, through the one definition of their ranges.
    let saved_settings: Vec<(&str, String)> = saved.settings.map_or(Vec::new(), |s| {
        vec![
            ("hysteresis", s.hysteresis.to_string()),
            ("norm", s.norm.to_string()),
            ("merge_distance", s.merge_distance.to_string()),
        ]
    });
    configure(
        &mut grammar,
        saved_settings.iter().map(|(n, v)| (*n, v.as_str())),
    )
    .map_err(|e| {
        errln!("error: {shown}: the session's settings: {e}");
        INPUT_ERROR
    })?;
    let config = configure(&mut grammar, settings.iter().copied()).map_err(|e| {
        errln!("error: --set {e}");
        IO_ERROR
    })?;
    let mut assembly = Assembly::from_data(Arc::new(grammar.clone()), saved.assembly);
    for (k, pin) in saved.pins.into_iter().enumerate() {
        if clay::pin_at(&mut assembly, pin.vertices, &pin.at).is_none() {
            return Err(misfit(path, &grammar_file)(format!(
                "pin {k} holds a vertex the assembly lacks"
            )));
        }
    }
    assembly
        .validate()
        .map_err(|problems| misfit(path, &grammar_file)(problems.join("; ")))?;
    Ok(Loaded {
        grammar,
        assembly,
        config,
    })
}
