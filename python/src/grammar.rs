//! `clay.Grammar`: a compiled grammar (what `clayc check` and `run` compile), its pieces and
//! its parameters.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use clay_dsl::CompileOptions;
use clay_dsl::compiled::{CompiledGrammar, ParamKind, ParamValue};

use crate::convert::{guard, is_bool, number, path_of, read, type_name};
use crate::diagnostics::{PyDiagnostic, grammar_error, to_python};

/// A grammar parameter (`param NAME [: TYPE] = DEFAULT [in LO..HI]`): its type, its value in
/// this compilation, the value the grammar gives it, its range (`None`: unbounded) and, for a
/// `choice`, its choices. Values are Python's: `float` for a number, `int` for an `int` or
/// `seed`, `bool`, and `str` for a choice.
#[pyclass(module = "clay", name = "Param", frozen)]
#[derive(Clone)]
pub struct PyParam {
    #[pyo3(get)]
    pub name: String,
    kind: ParamKind,
    value: ParamValue,
    default: ParamValue,
    #[pyo3(get)]
    pub range: Option<(f64, f64)>,
}

impl PyParam {
    fn of(p: &clay_dsl::compiled::Param) -> Self {
        Self {
            name: p.name.clone(),
            kind: p.kind.clone(),
            value: p.value.clone(),
            default: p.default.clone(),
            range: p.range.map(|[lo, hi]| (lo, hi)),
        }
    }

    fn python<'py>(&self, py: Python<'py>, v: &ParamValue) -> PyResult<Bound<'py, PyAny>> {
        Ok(match v {
            ParamValue::Number(x) if self.kind.is_whole() => {
                (*x as i64).into_pyobject(py)?.into_any()
            }
            ParamValue::Number(x) => x.into_pyobject(py)?.into_any(),
            ParamValue::Bool(b) => b.into_pyobject(py)?.to_owned().into_any(),
            ParamValue::Text(t) => t.into_pyobject(py)?.into_any(),
        })
    }
}

#[pymethods]
impl PyParam {
    /// The type: `"number"`, `"int"`, `"bool"`, `"seed"` or `"choice"`.
    #[getter]
    fn kind(&self) -> &'static str {
        self.kind.word()
    }

    #[getter]
    fn value<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.python(py, &self.value)
    }

    #[getter]
    fn default<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.python(py, &self.default)
    }

    /// A choice's pieces, in order; `None` for another type.
    #[getter]
    fn choices(&self) -> Option<Vec<String>> {
        match &self.kind {
            ParamKind::Choice { choices } => Some(choices.clone()),
            _ => None,
        }
    }

    fn __repr__(&self) -> String {
        let range = self
            .range
            .map_or(String::new(), |(lo, hi)| format!(" in {lo}..{hi}"));
        format!(
            "Param({}: {} = {}{range}, default {})",
            self.name,
            self.kind.word(),
            self.value,
            self.default
        )
    }
}

/// A piece of the grammar: its name, rest states, vertices and docking sites, by name.
#[pyclass(module = "clay", name = "Piece", frozen, get_all)]
#[derive(Clone)]
pub struct PyPiece {
    pub name: String,
    pub states: Vec<String>,
    pub vertices: Vec<String>,
    pub sites: Vec<String>,
}

#[pymethods]
impl PyPiece {
    fn __repr__(&self) -> String {
        format!("Piece({}, states={:?})", self.name, self.states)
    }
}

/// A compiled grammar. Make one with `Grammar.open(path)` or `Grammar.parse(text)`; a grammar
/// with errors raises `clay.GrammarError`. Warnings are kept in `.warnings`.
#[pyclass(module = "clay", frozen)]
pub struct Grammar {
    pub compiled: Arc<CompiledGrammar>,
    path: Option<String>,
    warnings: Vec<PyDiagnostic>,
    params: Vec<PyParam>,
}

/// Parameter overrides from Python: a mapping of names to numbers, bools (a `bool`
/// parameter) and strings (a `choice`); the grammar checks each against its parameter's type.
fn overrides(params: Option<&Bound<'_, PyAny>>) -> PyResult<BTreeMap<String, Given>> {
    let Some(params) = params.filter(|p| !p.is_none()) else {
        return Ok(BTreeMap::new());
    };
    let dict = params.cast::<PyDict>().map_err(|_| {
        PyTypeError::new_err(format!(
            "params must be a dict of names to values, found {}",
            type_name(params)
        ))
    })?;
    let mut out = BTreeMap::new();
    for (k, v) in dict.iter() {
        let name: String = k.extract().map_err(|_| {
            PyTypeError::new_err(format!(
                "params: a parameter's name must be a str, found {}",
                type_name(&k)
            ))
        })?;
        let what = format!("params: {name}");
        let value = if is_bool(&v) {
            ParamValue::Bool(v.is_truthy()?)
        } else if let Ok(t) = v.cast::<PyString>() {
            ParamValue::Text(t.to_string())
        } else {
            ParamValue::Number(number(&v, &what).map_err(|_| {
                PyTypeError::new_err(format!(
                    "{what} must be a number, a bool or a str, found {}",
                    type_name(&v)
                ))
            })?)
        };
        out.insert(
            name,
            Given {
                value,
                python_type: type_name(&v),
            },
        );
    }
    Ok(out)
}

/// A parameter value from Python, with its Python type's name for messages.
struct Given {
    value: ParamValue,
    python_type: String,
}

/// A `TypeError` for a value whose type is not its parameter's (a number for a `bool`, a
/// fraction for an `int`, a number for a `choice`); a name the grammar does not declare, or a
/// choice it does not list, is the compiler's to report (E070, E073).
fn check_types(
    declared: &[clay_dsl::compiled::Param],
    given: &BTreeMap<String, Given>,
) -> PyResult<()> {
    for (name, g) in given {
        let Some(p) = declared.iter().find(|p| p.name == *name) else {
            continue;
        };
        let expected = match (&p.kind, &g.value) {
            (ParamKind::Bool, ParamValue::Bool(_))
            | (ParamKind::Choice { .. }, ParamValue::Text(_)) => continue,
            (k, ParamValue::Number(v)) if k.is_numeric() && (!k.is_whole() || v.fract() == 0.0) => {
                continue;
            }
            (ParamKind::Bool, _) => "a bool".to_string(),
            (ParamKind::Choice { choices }, _) => {
                let all: Vec<String> = choices.iter().map(|c| format!("'{c}'")).collect();
                format!("a str, one of {}", all.join(", "))
            }
            (ParamKind::Int | ParamKind::Seed, ParamValue::Number(v)) => {
                return Err(PyTypeError::new_err(format!(
                    "params: {name} must be a whole number ({} parameter), found {v}",
                    p.kind.with_article().replace('`', "")
                )));
            }
            (ParamKind::Int | ParamKind::Seed, _) => "an int".to_string(),
            _ => "a number".to_string(),
        };
        return Err(PyTypeError::new_err(format!(
            "params: {name} must be {expected}, found {}",
            g.python_type
        )));
    }
    Ok(())
}

impl Grammar {
    /// Compiles `bytes` (the text of `path`) with parameter overrides.
    fn compile(
        py: Python<'_>,
        bytes: &[u8],
        path: &str,
        shown_path: Option<String>,
        given: BTreeMap<String, Given>,
    ) -> PyResult<Self> {
        let run = |params: Vec<(String, ParamValue)>| {
            py.detach(|| {
                guard("compiling the grammar", || {
                    // Made here: the file system loader it holds stays on this thread.
                    let options = CompileOptions {
                        params,
                        ..CompileOptions::default()
                    };
                    Ok(clay_dsl::decode_utf8(bytes)
                        .and_then(|s| clay_dsl::compile(s, path, &options)))
                })
            })
        };
        // Python's types first: the grammar compiled with its defaults says each
        // parameter's type (a grammar with errors reports them below, as without values).
        if !given.is_empty()
            && let Ok(plain) = run(Vec::new())?
        {
            check_types(&plain.grammar.params, &given)?;
        }
        let params = given.into_iter().map(|(n, g)| (n, g.value)).collect();
        let compiled = run(params)?;
        let text = String::from_utf8_lossy(bytes);
        // An unknown parameter (E070) or a value outside its range (E071) is a diagnostic
        // like any other: a GrammarError naming the parameter, its range and the known names.
        let compiled = compiled.map_err(|d| grammar_error(py, &d, &text, path))?;
        let params = compiled.grammar.params.iter().map(PyParam::of).collect();
        Ok(Self {
            warnings: to_python(&compiled.warnings, &text, path),
            compiled: Arc::new(compiled.grammar),
            path: shown_path,
            params,
        })
    }
}

#[pymethods]
impl Grammar {
    /// Reads and compiles the grammar at `path` (imports are found beside it). `params` sets
    /// grammar parameters by name. Raises `OSError` when the file cannot be read,
    /// `clay.GrammarError` when it has errors, also for an unknown parameter (E070) or a value
    /// outside its range (E071).
    #[staticmethod]
    #[pyo3(signature = (path, params = None))]
    fn open(
        py: Python<'_>,
        path: &Bound<'_, PyAny>,
        params: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let path: PathBuf = path_of(path)?;
        let params = overrides(params)?;
        let bytes = read(&path)?;
        let name = path.display().to_string();
        Self::compile(py, &bytes, &name, Some(name.clone()), params)
    }

    /// Compiles grammar text. `path` names it in diagnostics and is where its imports are
    /// found from (without it, `<string>` in the current directory). `params` as in `open`.
    #[staticmethod]
    #[pyo3(signature = (text, path = None, params = None))]
    fn parse(
        py: Python<'_>,
        text: &str,
        path: Option<&Bound<'_, PyAny>>,
        params: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let params = overrides(params)?;
        let path = path.filter(|p| !p.is_none()).map(path_of).transpose()?;
        let name = path
            .as_ref()
            .map_or("<string>".to_string(), |p| p.display().to_string());
        Self::compile(
            py,
            text.as_bytes(),
            &name,
            path.map(|p| p.display().to_string()),
            params,
        )
    }

    /// The file the grammar was read from (`None` for text without a path).
    #[getter]
    fn path(&self) -> Option<String> {
        self.path.clone()
    }

    /// The compiler's warnings (clay.Diagnostic, severity "warning").
    #[getter]
    fn warnings(&self) -> Vec<PyDiagnostic> {
        self.warnings.clone()
    }

    /// The grammar's parameters with the values of this compilation (clay.Param).
    #[getter]
    fn params(&self) -> Vec<PyParam> {
        self.params.clone()
    }

    /// The pieces (clay.Piece), in declaration order.
    #[getter]
    fn pieces(&self) -> Vec<PyPiece> {
        self.compiled
            .pieces
            .iter()
            .map(|p| PyPiece {
                name: p.name.clone(),
                states: p.states.iter().map(|s| s.name.clone()).collect(),
                vertices: p.vertices.clone(),
                sites: p.sites.iter().map(|s| s.name.clone()).collect(),
            })
            .collect()
    }

    /// How many instances the grammar's model starts with.
    #[getter]
    fn instance_count(&self) -> usize {
        self.compiled.assembly.instances.len()
    }

    /// The grammar's `solver` block: hysteresis, norm, irls_epsilon, merge_distance.
    #[getter]
    fn solver<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = &self.compiled.solver;
        let d = PyDict::new(py);
        d.set_item("hysteresis", s.hysteresis)?;
        d.set_item("norm", s.norm)?;
        d.set_item("irls_epsilon", s.irls_epsilon)?;
        d.set_item("merge_distance", s.merge_distance)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        let count = |n: usize, one: &str| format!("{n} {one}{}", if n == 1 { "" } else { "s" });
        format!(
            "Grammar({}, {}, {})",
            self.path.as_deref().unwrap_or("<string>"),
            count(self.compiled.pieces.len(), "piece"),
            count(self.compiled.assembly.instances.len(), "instance")
        )
    }
}
