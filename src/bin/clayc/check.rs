//! `clayc check` (print diagnostics for grammar files) and `clayc build` (compile one grammar to
//! JSON). Exit codes: 0 no errors (warnings allowed), 1 the input has errors, 2 usage or I/O.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};

use clay_dsl::{Diagnostics, compile_bytes};

/// How diagnostics are printed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// rustc-style text on stderr.
    #[default]
    Human,
    /// One JSON array of diagnostics on stdout.
    Json,
}

#[derive(clap::Args)]
pub struct CheckArgs {
    /// Grammar files to check.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Output format of the diagnostics.
    #[arg(long, value_enum, default_value_t = Format::Human)]
    pub format: Format,
}

#[derive(clap::Args)]
pub struct BuildArgs {
    /// The grammar file to compile.
    pub file: PathBuf,
    /// Where to write the compiled grammar as JSON (`-` for stdout).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
}

/// Colour only on a terminal, and never when NO_COLOR is set (https://no-color.org).
fn stderr_color() -> bool {
    std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none_or(|v| v.is_empty())
}

/// The file's bytes, or a message naming it.
fn read(path: &Path) -> Result<Vec<u8>, String> {
    std::fs::read(path).map_err(|e| {
        let why = match e.kind() {
            std::io::ErrorKind::NotFound => "no such file".to_string(),
            std::io::ErrorKind::PermissionDenied => "permission denied".to_string(),
            _ => e.to_string(),
        };
        format!("error: cannot read `{}`: {why}", path.display())
    })
}

fn print_human(diags: &Diagnostics, bytes: &[u8], path: &str) {
    let source = String::from_utf8_lossy(bytes);
    clay_dsl::diagnostic::emit_to_stderr(diags, &source, path, stderr_color());
}

pub fn check(args: CheckArgs) -> u8 {
    let mut worst = 0u8;
    let mut json = Vec::new();
    let (mut errors, mut warnings) = (0, 0);
    for file in &args.files {
        let bytes = match read(file) {
            Ok(b) => b,
            Err(msg) => {
                eprintln!("{msg}");
                worst = 2;
                continue;
            }
        };
        let path = file.display().to_string();
        let diags = match compile_bytes(&bytes, &path) {
            Ok(c) => c.warnings,
            Err(d) => d,
        };
        errors += diags.error_count();
        warnings += diags.warning_count();
        if diags.has_errors() && worst == 0 {
            worst = 1;
        }
        match args.format {
            Format::Human => print_human(&diags, &bytes, &path),
            Format::Json => json.extend(clay_dsl::to_json(
                &diags,
                &String::from_utf8_lossy(&bytes),
                &path,
            )),
        }
    }
    match args.format {
        Format::Json => match serde_json::to_string_pretty(&json) {
            Ok(text) => println!("{text}"),
            Err(e) => {
                eprintln!("error: cannot write JSON: {e}");
                return 2;
            }
        },
        // A clean check says so: silence would leave an author unsure anything was read.
        Format::Human => eprintln!("{}", summary(args.files.len(), errors, warnings)),
    }
    worst
}

fn summary(files: usize, errors: usize, warnings: usize) -> String {
    let plural = |n: usize, w: &str| format!("{n} {w}{}", if n == 1 { "" } else { "s" });
    match (errors, warnings) {
        (0, 0) => format!(
            "check passed: {}, no errors or warnings",
            plural(files, "file")
        ),
        (0, w) => format!("check passed with {}", plural(w, "warning")),
        (e, 0) => format!("check failed: {}", plural(e, "error")),
        (e, w) => format!(
            "check failed: {}, {}",
            plural(e, "error"),
            plural(w, "warning")
        ),
    }
}

pub fn build(args: BuildArgs) -> u8 {
    let bytes = match read(&args.file) {
        Ok(b) => b,
        Err(msg) => {
            eprintln!("{msg}");
            return 2;
        }
    };
    let path = args.file.display().to_string();
    let compiled = match compile_bytes(&bytes, &path) {
        Ok(c) => c,
        Err(diags) => {
            print_human(&diags, &bytes, &path);
            eprintln!("{}", summary(1, diags.error_count(), diags.warning_count()));
            return 1;
        }
    };
    print_human(&compiled.warnings, &bytes, &path);
    let text = match serde_json::to_string_pretty(&compiled.grammar) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("error: cannot serialise the grammar: {e}");
            return 2;
        }
    };
    if args.output.as_os_str() == "-" {
        let mut out = std::io::stdout().lock();
        if writeln!(out, "{text}").is_err() {
            return 2;
        }
    } else if let Err(e) = std::fs::write(&args.output, text + "\n") {
        eprintln!("error: cannot write `{}`: {e}", args.output.display());
        return 2;
    }
    0
}
