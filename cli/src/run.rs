//! `clayc run FILE|--session SESSION.json [--script SCRIPT.json] [--json] [--set NAME=VALUE]...
//! [--param NAME=VALUE]...`: compiles a grammar (or rebuilds a saved sculpt), replays a
//! scripted sculpting session headlessly and prints its summary.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::out;
use crate::params::ParamArgs;
use clay::{Assembly, Script, ScriptError, Session, configure, replay};

#[derive(clap::Args)]
pub struct RunArgs {
    #[command(flatten)]
    pub model: crate::from_session::ModelArgs,
    /// The session script (JSON, {"steps": [...]}); without it the initial assembly is reported.
    #[arg(long)]
    pub script: Option<PathBuf>,
    /// Print one JSON summary object instead of the human summary.
    #[arg(long)]
    pub json: bool,
    /// Also print the rule log: every rule that fired, its frame and why (with --json, as
    /// the summary's "log" array).
    #[arg(long)]
    pub log: bool,
    /// Override a solver parameter: hysteresis, norm, irls_epsilon, merge_distance,
    /// irls_iterations, l2_iterations, l2_anderson, handle_weight, solver (cholesky|cg).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    #[command(flatten)]
    pub params: ParamArgs,
}

/// The message for a malformed script: `error: FILE:LINE:COLUMN: step N: ...` and its hint.
pub fn script_error(path: &Path, e: &ScriptError) -> String {
    e.located(path)
}

/// The grammar `file`'s initial assembly and the solver settings (its own, with `settings`).
fn initial(
    file: &Path,
    params: &ParamArgs,
    settings: Vec<(&str, &str)>,
) -> Result<(Assembly, clay::SolverConfig), u8> {
    let path = file.display().to_string();
    let source = match clay_dsl::read_input(file, clay_dsl::MAX_SOURCE_BYTES) {
        Ok(bytes) => bytes,
        Err(e) => {
            errln!("error: cannot read {path}: {e}");
            return Err(2);
        }
    };
    let text = String::from_utf8_lossy(&source);
    let compiled = match clay_dsl::decode_utf8(&source)
        .and_then(|s| clay_dsl::compile(s, &path, &params.options()))
    {
        Ok(c) => c,
        Err(diagnostics) => {
            err!("{}", clay_dsl::render(&diagnostics, &text, &path, false));
            return Err(1);
        }
    };
    if !compiled.warnings.items.is_empty() {
        err!(
            "{}",
            clay_dsl::render(&compiled.warnings, &text, &path, false)
        );
    }
    let mut grammar = compiled.grammar;
    let config = match configure(&mut grammar, settings) {
        Ok(config) => config,
        Err(e) => {
            errln!("error: --set {e}");
            return Err(2);
        }
    };
    let assembly = Assembly::new(Arc::new(grammar));
    if let Err(problems) = assembly.validate() {
        errln!(
            "error: the compiled assembly is inconsistent:\n  {}",
            problems.join("\n  ")
        );
        return Err(1);
    }
    Ok((assembly, config))
}

pub fn run(args: RunArgs) -> u8 {
    let script = match &args.script {
        None => Script::default(),
        Some(p) => match clay_dsl::read_input_string(p, clay_dsl::MAX_SOURCE_BYTES) {
            Err(e) => {
                errln!("error: cannot read script {}: {e}", p.display());
                return 2;
            }
            Ok(text) => match Script::parse(&text) {
                Ok(s) => s,
                Err(e) => {
                    errln!("{}", script_error(p, &e));
                    return 1;
                }
            },
        },
    };
    let mut settings = Vec::with_capacity(args.set.len());
    for s in &args.set {
        match s.split_once('=') {
            Some(pair) => settings.push(pair),
            None => {
                errln!("error: --set {s}: expected NAME=VALUE");
                return 2;
            }
        }
    }
    let (mut assembly, config) = match (&args.model.session, &args.model.file) {
        (Some(session), _) => match crate::from_session::load(session, &args.params, &settings) {
            Ok(loaded) => (loaded.assembly, loaded.config),
            Err(code) => return code,
        },
        (None, Some(file)) => match initial(file, &args.params, settings) {
            Ok(model) => model,
            Err(code) => return code,
        },
        (None, None) => {
            errln!("error: name a grammar FILE or a --session");
            return 2;
        }
    };
    if let Err(why) = script.check_params(assembly.grammar()) {
        let shown = args.script.as_deref().map(|p| p.display().to_string());
        errln!("error: {}: {why}", shown.unwrap_or_default());
        return 1;
    }
    let mut session = Session::new(config);
    let summary = match replay(&mut assembly, &script, &mut session) {
        Ok(r) => r,
        Err(e) => {
            errln!("error: {e}");
            return 1;
        }
    };
    for note in session.notes() {
        errln!("note: {note}");
    }
    let log = args.log.then(|| session.rule_log());
    let text = if args.json {
        let value = serde_json::to_value(&summary).map(|mut v| {
            if let (Some(log), Some(map)) = (log, v.as_object_mut()) {
                let events = log.iter().map(|e| {
                    serde_json::json!({"frame": e.frame, "kind": e.kind.name(), "detail": e.detail})
                });
                map.insert("log".into(), events.collect());
            }
            v
        });
        match value.and_then(|v| serde_json::to_string_pretty(&v)) {
            Ok(s) => s + "\n",
            Err(e) => {
                errln!("error: cannot write the summary: {e}");
                return 2;
            }
        }
    } else {
        let lines = log
            .unwrap_or_default()
            .iter()
            .map(|e| format!("frame {}: {}: {}\n", e.frame, e.kind.name(), e.detail));
        lines.collect::<String>() + &summary.human()
    };
    out::stdout(text.as_bytes())
        .err()
        .map_or(0, |stop| stop.exit(0))
}
