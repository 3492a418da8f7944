//! `clayc check` (print diagnostics for grammar files) and `clayc build` (compile one grammar to
//! JSON). Exit codes: 0 no errors (warnings allowed), 1 the input has errors, 2 usage or I/O.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use crate::out;
use crate::params::ParamArgs;
use clay_dsl::codes::UNREADABLE;
use clay_dsl::{Diagnostics, Severity, compile, decode_utf8};
use clay_dsl::{JsonDiagnostic, JsonLabel, JsonPos};

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
    // Parameter values, the same for every file checked.
    #[command(flatten)]
    pub params: ParamArgs,
}

#[derive(clap::Args)]
pub struct BuildArgs {
    /// The grammar file to compile.
    pub file: PathBuf,
    /// Where to write the compiled grammar as JSON (`-` for stdout).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Indent the JSON for reading (several times larger: a 100,000-element chain's is about
    /// 20 MB compact).
    #[arg(long)]
    pub pretty: bool,
    #[command(flatten)]
    pub params: ParamArgs,
}

/// Colour only on a terminal, and never when NO_COLOR is set (<https://no-color.org>).
fn stderr_color() -> bool {
    std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none_or(|v| v.is_empty())
}

/// A file that could not be read: what went wrong, in words, and what to do about it.
pub struct Unreadable {
    pub path: String,
    pub why: String,
    pub hint: String,
}

impl Unreadable {
    /// The human form: a rustc-style error line with the code and a help line.
    pub fn human(&self) -> String {
        format!(
            "error[{UNREADABLE}]: cannot read `{}`: {}\n  = help: {}",
            self.path, self.why, self.hint
        )
    }

    /// The JSON form: one diagnostic object at the start of the file, as `to_json` writes them.
    pub fn json(&self) -> JsonDiagnostic {
        let start = JsonPos { line: 1, column: 1 };
        JsonDiagnostic {
            code: UNREADABLE,
            severity: Severity::Error,
            message: format!("cannot read `{}`: {}", self.path, self.why),
            file: self.path.clone(),
            line: 1,
            column: 1,
            end: start,
            labels: vec![JsonLabel {
                message: "the file cannot be read".into(),
                primary: true,
                file: self.path.clone(),
                start,
                end: start,
                byte_start: 0,
                byte_end: 0,
            }],
            hints: vec![self.hint.clone()],
        }
    }
}

/// The file's bytes, or why they cannot be had.
pub fn read(path: &Path) -> Result<Vec<u8>, Unreadable> {
    clay_dsl::read_input(path, clay_dsl::MAX_SOURCE_BYTES).map_err(|e| {
        let (why, hint) = match e.kind() {
            std::io::ErrorKind::NotFound => (
                "no such file".to_string(),
                "check the spelling; a relative path starts in the current directory".to_string(),
            ),
            std::io::ErrorKind::PermissionDenied => (
                "permission denied".to_string(),
                "the file's permissions must allow reading it".to_string(),
            ),
            std::io::ErrorKind::IsADirectory => (
                "it is a directory".to_string(),
                "name a grammar file (.clay), not a directory".to_string(),
            ),
            _ => (
                e.to_string(),
                "name a readable grammar file (.clay)".to_string(),
            ),
        };
        Unreadable {
            path: path.display().to_string(),
            why,
            hint,
        }
    })
}

fn print_human(diags: &Diagnostics, bytes: &[u8], path: &str) {
    use std::io::Write;
    let source = String::from_utf8_lossy(bytes);
    // in one piece: codespan writes a source line a character at a time, a system call each
    // on unbuffered stderr
    let text = clay_dsl::render(diags, &source, path, stderr_color());
    let _ = std::io::stderr().lock().write_all(text.as_bytes());
}

pub fn check(args: CheckArgs) -> u8 {
    let mut worst = 0u8;
    let mut json = Vec::new();
    let mut counts = Counts {
        files: args.files.len(),
        ..Counts::default()
    };
    let options = args.params.options();
    for file in &args.files {
        let bytes = match read(file) {
            Ok(b) => b,
            Err(unreadable) => {
                match args.format {
                    Format::Human => errln!("{}", unreadable.human()),
                    Format::Json => json.push(unreadable.json()),
                }
                counts.unreadable += 1;
                worst = 2;
                continue;
            }
        };
        let path = file.display().to_string();
        let diags = match decode_utf8(&bytes).and_then(|s| compile(s, &path, &options)) {
            Ok(c) => c.warnings,
            Err(d) => d,
        };
        counts.errors += diags.error_count();
        counts.warnings += diags.warning_count();
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
            Ok(text) => {
                if let Err(stop) = out::stdout_line(&text) {
                    return stop.exit(worst);
                }
            }
            Err(e) => {
                errln!("error: cannot write JSON: {e}");
                return 2;
            }
        },
        // A clean check says so: silence would leave an author unsure anything was read.
        Format::Human => errln!("{}", counts.summary()),
    }
    worst
}

/// What a check found, for its last line.
#[derive(Default)]
struct Counts {
    files: usize,
    /// Files that could not be read: the check cannot have passed.
    unreadable: usize,
    errors: usize,
    warnings: usize,
}

impl Counts {
    fn summary(&self) -> String {
        let plural = |n: usize, w: &str| format!("{n} {w}{}", if n == 1 { "" } else { "s" });
        let mut problems = Vec::new();
        if self.unreadable > 0 {
            problems.push(format!(
                "{} of {} could not be read",
                self.unreadable,
                plural(self.files, "file")
            ));
        }
        if self.errors > 0 {
            problems.push(plural(self.errors, "error"));
        }
        match (problems.is_empty(), self.warnings) {
            (true, 0) => format!(
                "check passed: {}, no errors or warnings",
                plural(self.files, "file")
            ),
            (true, w) => format!("check passed with {}", plural(w, "warning")),
            (false, 0) => format!("check failed: {}", problems.join(", ")),
            (false, w) => format!(
                "check failed: {}, {}",
                problems.join(", "),
                plural(w, "warning")
            ),
        }
    }
}

pub fn build(args: BuildArgs) -> u8 {
    let bytes = match read(&args.file) {
        Ok(b) => b,
        Err(unreadable) => {
            errln!("{}", unreadable.human());
            return 2;
        }
    };
    let path = args.file.display().to_string();
    let compiled = match decode_utf8(&bytes).and_then(|s| compile(s, &path, &args.params.options()))
    {
        Ok(c) => c,
        Err(diags) => {
            print_human(&diags, &bytes, &path);
            let counts = Counts {
                files: 1,
                errors: diags.error_count(),
                warnings: diags.warning_count(),
                ..Counts::default()
            };
            errln!("{}", counts.summary());
            return 1;
        }
    };
    print_human(&compiled.warnings, &bytes, &path);
    let json = if args.pretty {
        serde_json::to_string_pretty(&compiled.grammar)
    } else {
        serde_json::to_string(&compiled.grammar)
    };
    let text = match json {
        Ok(t) => t,
        Err(e) => {
            errln!("error: cannot serialise the grammar: {e}");
            return 2;
        }
    };
    out::write_output(&args.output, (text + "\n").as_bytes())
}
