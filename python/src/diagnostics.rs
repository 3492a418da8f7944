//! Diagnostics as Python objects, `clay.check` and `clay.GrammarError` (what `clayc check`
//! prints, as data: the JSON form's positions, 1-based lines and character columns).

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyList;

use clay_dsl::{Diagnostics, JsonDiagnostic, Severity};

use crate::convert::{guard, path_of, read};

pyo3::create_exception!(
    clay,
    GrammarError,
    pyo3::exceptions::PyValueError,
    "A grammar did not compile. `.diagnostics` lists every error and warning \
     (clay.Diagnostic); the message is the rustc-style rendering `clayc check` prints."
);

/// One error or warning about a grammar, as `clayc check --format json` gives it.
#[pyclass(module = "clay", name = "Diagnostic", frozen, get_all)]
#[derive(Clone)]
pub struct PyDiagnostic {
    /// The stable code (`E011`, `W001`, ...), listed in docs/language.md.
    pub code: String,
    /// `"error"` or `"warning"`.
    pub severity: String,
    pub message: String,
    /// The file the diagnostic is in: the grammar, or a file it imports.
    pub path: String,
    /// Where it starts: 1-based line and column (in characters).
    pub line: usize,
    pub column: usize,
    /// Where it ends.
    pub end_line: usize,
    pub end_column: usize,
    /// What to do about it (`did you mean `brick`?`).
    pub hints: Vec<String>,
}

#[pymethods]
impl PyDiagnostic {
    fn __repr__(&self) -> String {
        format!(
            "Diagnostic({} {} at {}:{}:{}: {:?})",
            self.severity, self.code, self.path, self.line, self.column, self.message
        )
    }

    /// `PATH:LINE:COLUMN: error[CODE]: MESSAGE`.
    fn __str__(&self) -> String {
        format!(
            "{}:{}:{}: {}[{}]: {}",
            self.path, self.line, self.column, self.severity, self.code, self.message
        )
    }
}

impl From<JsonDiagnostic> for PyDiagnostic {
    fn from(d: JsonDiagnostic) -> Self {
        Self {
            code: d.code.to_string(),
            severity: match d.severity {
                Severity::Error => "error",
                Severity::Warning => "warning",
            }
            .to_string(),
            message: d.message,
            path: d.file,
            line: d.line,
            column: d.column,
            end_line: d.end.line,
            end_column: d.end.column,
            hints: d.hints,
        }
    }
}

/// The diagnostics of a compilation of `source` (the text of `path`), in file order.
pub fn to_python(diagnostics: &Diagnostics, source: &str, path: &str) -> Vec<PyDiagnostic> {
    clay_dsl::to_json(diagnostics, source, path)
        .into_iter()
        .map(PyDiagnostic::from)
        .collect()
}

/// A `GrammarError` for a failed compilation: the rendered diagnostics as its message and
/// the list as `.diagnostics`.
pub fn grammar_error(py: Python<'_>, diagnostics: &Diagnostics, source: &str, path: &str) -> PyErr {
    let text = clay_dsl::render(diagnostics, source, path, false);
    let summary = match diagnostics.error_count() {
        1 => "1 error".to_string(),
        n => format!("{n} errors"),
    };
    let err = GrammarError::new_err(format!("{path}: {summary}\n{}", text.trim_end()));
    let list = to_python(diagnostics, source, path);
    let attached = PyList::new(py, list).and_then(|l| err.value(py).setattr("diagnostics", l));
    match attached {
        Ok(()) => err,
        Err(e) => e,
    }
}

/// Compiles the grammar at `path` and returns its diagnostics, errors and warnings in file
/// order (an empty list: it is clean). Raises `OSError` when the file cannot be read.
///
/// >>> [str(d) for d in clay.check("grammars/wall.clay")]
/// []
#[pyfunction]
pub fn check(py: Python<'_>, path: &Bound<'_, PyAny>) -> PyResult<Vec<PyDiagnostic>> {
    let path: PathBuf = path_of(path)?;
    let bytes = read(&path)?;
    let name = path.display().to_string();
    let compiled = py.detach(|| {
        guard("check", || {
            Ok(clay_dsl::decode_utf8(&bytes)
                .and_then(|s| clay_dsl::compile(s, &name, &clay_dsl::CompileOptions::default()))
                .map(|c| c.warnings))
        })
    })?;
    let text = String::from_utf8_lossy(&bytes);
    let diagnostics = match compiled {
        Ok(warnings) => warnings,
        Err(errors) => errors,
    };
    Ok(to_python(&diagnostics, &text, &name))
}
