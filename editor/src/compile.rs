//! Turns grammar text into a compiled grammar for the editor, and the compiler's diagnostics
//! into `file:line:col` problems the diagnostics panel lists.

use std::fmt;
use std::path::Path;
use std::sync::Arc;

use clay_dsl::compiled::{AssemblyData, CompiledGrammar, FORMAT_VERSION, ParamValue, SolverParams};

/// The castle example, bundled so the editor opens something useful with no argument.
pub const CASTLE_SOURCE: &str = include_str!("../../grammars/castle.clay");
/// The path the bundled castle is shown under (and compiled with).
pub const CASTLE_PATH: &str = "grammars/castle.clay";

/// How bad a problem is: errors keep the last good model live, warnings travel with a model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Severity {
    Error,
    Warning,
}

/// One diagnostic of a grammar, located by line and column (1-based).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Problem {
    pub severity: Severity,
    /// Stable code (`E001`, `W001`, ...) or empty.
    pub code: String,
    pub file: String,
    pub line: usize,
    pub col: usize,
    /// Where the underline ends on `line` (1-based, exclusive; at least `col + 1`).
    pub end_col: usize,
    pub message: String,
    /// What the primary span is (`no piece of this name`), or empty.
    pub label: String,
    /// The source line the problem is on, without its newline (empty if unknown).
    pub snippet: String,
    /// Other places that explain it: line, column and what is there.
    pub related: Vec<(usize, usize, String)>,
    /// `help:` notes.
    pub hints: Vec<String>,
}

impl Problem {
    /// A problem about the file as a whole (I/O, missing compiler), placed at 1:1.
    pub fn whole_file(file: &str, message: impl Into<String>) -> Self {
        Self {
            severity: Severity::Error,
            code: String::new(),
            file: file.to_string(),
            line: 1,
            col: 1,
            end_col: 2,
            message: message.into(),
            label: String::new(),
            snippet: String::new(),
            related: Vec::new(),
            hints: Vec::new(),
        }
    }

    /// The underline under `snippet`: spaces up to the span, then `^` across it.
    pub fn underline(&self) -> String {
        let width = self.end_col.saturating_sub(self.col).max(1);
        format!(
            "{}{}",
            " ".repeat(self.col.saturating_sub(1)),
            "^".repeat(width)
        )
    }
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let kind = match self.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        let code = if self.code.is_empty() {
            String::new()
        } else {
            format!("[{}]", self.code)
        };
        write!(
            f,
            "{}:{}:{}: {kind}{code}: {}",
            self.file, self.line, self.col, self.message
        )
    }
}

/// A grammar that compiled, with its warnings.
#[derive(Clone, Debug)]
pub struct Compiled {
    pub grammar: Arc<CompiledGrammar>,
    pub warnings: Vec<Problem>,
    /// The files the grammar imports (as resolved from its path), for hot reload to watch.
    pub imports: Vec<String>,
}

/// Compiles grammar text. `path` is used in messages and recorded in the grammar; `params`
/// are values for the grammar's parameters (`param NAME = ...`) replacing their defaults, by
/// name (what the Grammar parameters panel sets; `&[]` for none).
///
/// Besides `.clay` text this accepts a compiled grammar in JSON (what `clayc compile` writes),
/// recognised by its leading `{` (a `.clay` file starts with a keyword or comment); it has its
/// parameters' values already, and takes none.
///
/// A panic in the compiler is caught and reported as a problem at 1:1 (the caller keeps the
/// last good model): the editor never exits on what a user wrote.
pub fn compile(
    source: &str,
    path: &str,
    params: &[(String, ParamValue)],
) -> Result<Compiled, Vec<Problem>> {
    let compiled = crate::guard::catching(|| {
        if source.trim_start().starts_with('{') {
            compile_json(source, path)
        } else {
            compile_clay(source, path, params)
        }
    });
    compiled.unwrap_or_else(|why| {
        Err(vec![Problem::whole_file(
            path,
            format!(
                "internal error: the compiler stopped ({why}); the last good model stays. \
                 Please report this file"
            ),
        )])
    })
}

/// Reads and compiles a grammar file without touching the editor's state.
pub fn check_grammar(path: &Path) -> Result<Compiled, Vec<Problem>> {
    let shown = path.display().to_string();
    let source = clay_dsl::read_input_string(path, clay_dsl::MAX_SOURCE_BYTES)
        .map_err(|e| vec![Problem::whole_file(&shown, format!("cannot read it: {e}"))])?;
    compile(&source, &shown, &[])
}

/// A grammar with nothing in it: the model shown when the first compile fails.
pub fn empty_grammar(path: &str) -> Arc<CompiledGrammar> {
    Arc::new(CompiledGrammar {
        format_version: FORMAT_VERSION,
        source: path.to_string(),
        solver: SolverParams::default(),
        params: Vec::new(),
        site_types: Vec::new(),
        pieces: Vec::new(),
        stretch_rules: Vec::new(),
        merge_rules: Vec::new(),
        cut_rules: Vec::new(),
        assembly: AssemblyData::default(),
    })
}

fn compile_json(source: &str, path: &str) -> Result<Compiled, Vec<Problem>> {
    let grammar: CompiledGrammar = serde_json::from_str(source).map_err(|e| {
        let line = e.line().max(1);
        let col = e.column().max(1);
        vec![Problem {
            line,
            col,
            end_col: col + 1,
            snippet: source.lines().nth(line - 1).unwrap_or("").to_string(),
            ..Problem::whole_file(path, format!("not a compiled grammar: {e}"))
        }]
    })?;
    // read back, not compiled: every index and number checked before anything uses it
    let problems = grammar.problems();
    if !problems.is_empty() {
        return Err(problems
            .into_iter()
            .map(|p| Problem::whole_file(path, format!("not a compiled grammar Clay can use: {p}")))
            .collect());
    }
    Ok(Compiled {
        grammar: Arc::new(grammar),
        warnings: Vec::new(),
        imports: Vec::new(),
    })
}

fn compile_clay(
    source: &str,
    path: &str,
    params: &[(String, ParamValue)],
) -> Result<Compiled, Vec<Problem>> {
    let options = clay_dsl::CompileOptions {
        params: params.to_vec(),
        ..Default::default()
    };
    match clay_dsl::compile(source, path, &options) {
        Ok(c) => Ok(Compiled {
            imports: c.imported_files().map(str::to_string).collect(),
            warnings: problems(&c.warnings, source, path),
            grammar: Arc::new(c.grammar),
        }),
        Err(diagnostics) => Err(problems(&diagnostics, source, path)),
    }
}

/// The compiler's diagnostics located by file, line and column of their primary span (a span in
/// an imported file is shown in that file, through the diagnostics' source map), with the
/// source line, the span's label, the secondary spans and the hints.
fn problems(diagnostics: &clay_dsl::Diagnostics, source: &str, path: &str) -> Vec<Problem> {
    let map = &diagnostics.sources;
    diagnostics
        .iter()
        .map(|d| {
            let at = map.locate(source, path, d.primary.span);
            let (line, col) = clay_dsl::line_col(at.text, at.start);
            let (end_line, end) = clay_dsl::line_col(at.text, at.end);
            let snippet = at.text.lines().nth(line - 1).unwrap_or("").to_string();
            let end_col = if end_line == line {
                end
            } else {
                snippet.chars().count() + 1
            }
            .max(col + 1);
            let related = d
                .secondary
                .iter()
                .map(|l| {
                    let (file, line, col) = map.line_col(source, path, l.span.start);
                    let message = if file == at.path {
                        l.message.clone()
                    } else {
                        format!("{} (in {file})", l.message)
                    };
                    (line, col, message)
                })
                .collect();
            Problem {
                severity: if d.is_error() {
                    Severity::Error
                } else {
                    Severity::Warning
                },
                code: d.code.to_string(),
                file: at.path.to_string(),
                line,
                col,
                end_col,
                message: d.message.clone(),
                label: d.primary.message.clone(),
                snippet,
                related,
                hints: d.hints.clone(),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bundled_castle_compiles() {
        let c = compile(CASTLE_SOURCE, CASTLE_PATH, &[]).unwrap();
        assert!(!c.grammar.assembly.instances.is_empty());
    }

    #[test]
    fn clay_errors_carry_line_and_column() {
        let source = "solver {\n    hysteresis = 0.15\n}\npiece {\n";
        let problems = compile(source, "bad.clay", &[]).unwrap_err();
        assert!(!problems.is_empty());
        let p = &problems[0];
        assert_eq!(p.severity, Severity::Error);
        assert!(
            p.line >= 4,
            "error should point at the broken piece, got {p}"
        );
        assert!(p.to_string().starts_with("bad.clay:"));
    }

    #[test]
    fn a_problem_carries_its_line_underline_label_and_hint() {
        let source = CASTLE_SOURCE.replacen("chain wall x 4", "chain wal x 4", 1);
        let problems = compile(&source, "castle.clay", &[]).unwrap_err();
        let p = problems
            .iter()
            .find(|p| p.code == "E011")
            .expect("unknown piece");
        assert!(p.snippet.contains("wal x"), "{:?}", p.snippet);
        let under = p.underline();
        let start = under.find('^').unwrap();
        let chars: Vec<char> = p.snippet.chars().collect();
        let spanned: String = chars[start..start + under.len() - start].iter().collect();
        assert_eq!(spanned, "wal", "the underline is under the name");
        assert!(!p.label.is_empty());
        assert!(
            !p.message.contains(&p.label),
            "the label is not repeated in the message"
        );
        assert!(
            p.hints.iter().any(|h| h.contains("`wall`")),
            "{:?}",
            p.hints
        );
    }

    #[test]
    fn a_problem_in_an_imported_file_names_that_file_and_its_line() {
        let dir = std::env::temp_dir().join(format!("clay-editor-import-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("lib.clay"), "// line 1\nsite type x docks y\n").unwrap();
        let main = dir.join("main.clay");
        let shown = main.display().to_string();
        let problems = compile("import \"lib.clay\"\nmodel {}\n", &shown, &[]).unwrap_err();
        let p = problems.iter().find(|p| p.code == "E011").unwrap();
        assert_eq!(p.file, dir.join("lib.clay").display().to_string());
        assert_eq!((p.line, p.snippet.as_str()), (2, "site type x docks y"));
        assert!(p.to_string().contains("lib.clay:2:"), "{p}");
        std::fs::write(dir.join("lib.clay"), CASTLE_SOURCE).unwrap();
        let c = compile("import \"lib.clay\"\nmodel { t = tower }\n", &shown, &[]).unwrap();
        assert_eq!(c.imports, [dir.join("lib.clay").display().to_string()]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn malformed_json_grammar_is_located() {
        let problems = compile("{\n  \"format_version\": }", "g.json", &[]).unwrap_err();
        assert_eq!(problems.len(), 1);
        assert_eq!(problems[0].line, 2);
        assert!(problems[0].to_string().starts_with("g.json:2:"));
    }
}
