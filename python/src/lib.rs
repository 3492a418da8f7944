//! The Python package `clay` (its native half, `clay._clay`): a thin binding over the Clay
//! library, calling what `clayc check`, `run`, `render` and `export` call. docs/python.md.
//!
//! Every failure reaches Python as an exception: a grammar's diagnostics as
//! `clay.GrammarError`, bad arguments and scripts as `ValueError`, files as `OSError`,
//! a solver failure as `SolverError`. A panic inside the library (a bug) is caught at the call
//! and raised as `InternalError`; the session it happened in refuses further use.

#![deny(clippy::print_stdout, clippy::print_stderr)]

use pyo3::prelude::*;

mod convert;
mod diagnostics;
mod grammar;
mod session;

pyo3::create_exception!(
    clay,
    SolverError,
    pyo3::exceptions::PyRuntimeError,
    "A solver frame failed (the step it failed in is named in the message)."
);

pyo3::create_exception!(
    clay,
    InternalError,
    pyo3::exceptions::PyRuntimeError,
    "A bug in Clay: the library failed where it should not. Please report it with the message."
);

pyo3::create_exception!(
    clay,
    ScriptParamsError,
    pyo3::exceptions::PyValueError,
    "A script says it was recorded with grammar parameters other than the session's: its \
     gestures would grab other parts of this model (a ValueError)."
);

#[pymodule]
fn _clay(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("GrammarError", py.get_type::<diagnostics::GrammarError>())?;
    m.add("SolverError", py.get_type::<SolverError>())?;
    m.add("InternalError", py.get_type::<InternalError>())?;
    m.add("ScriptParamsError", py.get_type::<ScriptParamsError>())?;
    m.add_class::<diagnostics::PyDiagnostic>()?;
    m.add_function(wrap_pyfunction!(diagnostics::check, m)?)?;
    m.add_class::<grammar::Grammar>()?;
    m.add_class::<grammar::PyParam>()?;
    m.add_class::<grammar::PyPiece>()?;
    m.add_class::<session::PySession>()?;
    m.add_class::<session::PyInstance>()?;
    m.add_class::<session::PyRuleEvent>()?;
    m.add_class::<session::SceneNode>()?;
    m.add_class::<session::PyPrimitive>()?;
    m.add("SOLVER_SETTINGS", clay::SETTING_NAMES.to_vec())?;
    Ok(())
}
