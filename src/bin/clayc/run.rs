//! `clayc run FILE [--script SCRIPT.json] [--json] [--set NAME=VALUE]...`: compiles a grammar,
//! replays a scripted sculpting session headlessly and prints its summary.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::out;
use clay::assembly::Assembly;
use clay::script::{Script, ScriptError};
use clay::session::{Session, replay};
use clay::solver::{SolverConfig, SolverKind};

#[derive(clap::Args)]
pub struct RunArgs {
    /// The grammar (.clay) whose model is sculpted.
    pub file: PathBuf,
    /// The session script (JSON, {"steps": [...]}); without it the initial assembly is reported.
    #[arg(long)]
    pub script: Option<PathBuf>,
    /// Print one JSON summary object instead of the human summary.
    #[arg(long)]
    pub json: bool,
    /// Override a solver parameter: hysteresis, norm, irls_epsilon, merge_distance,
    /// irls_iterations, l2_iterations, l2_anderson, handle_weight, solver (cholesky|cg).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
}

/// The message for a malformed script: `error: FILE:LINE:COLUMN: step N: ...` and its hint.
pub fn script_error(path: &Path, e: &ScriptError) -> String {
    let at = match e.position {
        Some((line, column)) => format!("{}:{line}:{column}", path.display()),
        None => path.display().to_string(),
    };
    match &e.hint {
        Some(hint) => format!("error: {at}: {e}\n  = help: {hint}"),
        None => format!("error: {at}: {e}"),
    }
}

/// Applies one `NAME=VALUE` override, checking the name and the range.
pub fn apply_setting(
    config: &mut SolverConfig,
    merge_distance: &mut f64,
    setting: &str,
) -> Result<(), String> {
    let (name, value) = setting
        .split_once('=')
        .ok_or_else(|| format!("--set {setting}: expected NAME=VALUE"))?;
    let (name, value) = (name.trim(), value.trim());
    if name == "solver" {
        config.kind = match value {
            "cholesky" => SolverKind::Cholesky,
            "cg" => SolverKind::Cg,
            _ => return Err(format!("--set solver={value}: expected cholesky or cg")),
        };
        return Ok(());
    }
    let number: f64 = value
        .parse()
        .ok()
        .filter(|x: &f64| x.is_finite())
        .ok_or_else(|| format!("--set {name}={value}: the value must be a finite number"))?;
    let check = |ok: bool, range: &str| {
        if ok {
            Ok(())
        } else {
            Err(format!("--set {name}={value}: must be {range}"))
        }
    };
    let count = |x: f64| x.fract() == 0.0 && (0.0..=1000.0).contains(&x);
    match name {
        "hysteresis" => {
            check((0.0..1.0).contains(&number), "in [0, 1)")?;
            config.hysteresis = number;
        }
        "norm" => {
            check(number > 0.0 && number <= 2.0, "in (0, 2]")?;
            config.norm = number;
        }
        "irls_epsilon" => {
            check(number > 0.0 && number <= 1.0, "in (0, 1]")?;
            config.irls_epsilon = number;
        }
        "merge_distance" => {
            check(number >= 0.0, "at least 0")?;
            *merge_distance = number;
        }
        "irls_iterations" => {
            check(count(number), "an integer from 0 to 1000")?;
            config.irls_iterations = number as usize;
        }
        "l2_iterations" => {
            check(count(number), "an integer from 0 to 1000")?;
            config.l2_iterations = number as usize;
        }
        "l2_anderson" => {
            check(
                number.fract() == 0.0 && (0.0..=16.0).contains(&number),
                "an integer from 0 to 16",
            )?;
            config.l2_anderson = number as usize;
        }
        "handle_weight" => {
            check((1.0..=1e12).contains(&number), "in [1, 1e12]")?;
            config.handle_weight = number;
        }
        _ => {
            return Err(format!(
                "--set {name}: unknown parameter (expected hysteresis, norm, irls_epsilon, merge_distance, irls_iterations, l2_iterations, l2_anderson, handle_weight or solver)"
            ));
        }
    }
    Ok(())
}

pub fn run(args: RunArgs) -> u8 {
    let path = args.file.display().to_string();
    let source = match std::fs::read(&args.file) {
        Ok(bytes) => bytes,
        Err(e) => {
            errln!("error: cannot read {path}: {e}");
            return 2;
        }
    };
    let script = match &args.script {
        None => Script::default(),
        Some(p) => match std::fs::read_to_string(p) {
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
    let text = String::from_utf8_lossy(&source);
    let compiled = match clay_dsl::compile_bytes(&source, &path) {
        Ok(c) => c,
        Err(diagnostics) => {
            err!("{}", clay_dsl::render(&diagnostics, &text, &path, false));
            return 1;
        }
    };
    if !compiled.warnings.items.is_empty() {
        err!(
            "{}",
            clay_dsl::render(&compiled.warnings, &text, &path, false)
        );
    }
    let mut grammar = compiled.grammar;
    let mut config = SolverConfig::from_params(&grammar.solver);
    let mut merge_distance = grammar.solver.merge_distance;
    for s in &args.set {
        if let Err(e) = apply_setting(&mut config, &mut merge_distance, s) {
            errln!("error: {e}");
            return 2;
        }
    }
    grammar.solver.hysteresis = config.hysteresis;
    grammar.solver.norm = config.norm;
    grammar.solver.irls_epsilon = config.irls_epsilon;
    grammar.solver.merge_distance = merge_distance;
    let mut assembly = Assembly::new(Arc::new(grammar));
    if let Err(problems) = assembly.validate() {
        errln!(
            "error: the compiled assembly is inconsistent:\n  {}",
            problems.join("\n  ")
        );
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
    let text = if args.json {
        match serde_json::to_string_pretty(&summary) {
            Ok(s) => s + "\n",
            Err(e) => {
                errln!("error: cannot write the summary: {e}");
                return 2;
            }
        }
    } else {
        summary.human()
    };
    out::stdout(text.as_bytes())
        .err()
        .map_or(0, |stop| stop.exit(0))
}
