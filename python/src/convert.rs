//! Conversions at the edge: files' errors to `OSError`, panics to `InternalError`, Python
//! numbers and points to the library's, checked.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

use pyo3::exceptions::{PyOSError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyBytes, PyDict, PyFloat, PyInt, PyString};

use crate::InternalError;

/// An `OSError` for `path` (Python picks the subclass from the errno: `FileNotFoundError`,
/// `PermissionError`, `IsADirectoryError`, ...), with the path in its message.
pub fn os_error(e: &std::io::Error, path: &Path) -> PyErr {
    let why = match e.kind() {
        std::io::ErrorKind::NotFound => "No such file or directory".to_string(),
        std::io::ErrorKind::PermissionDenied => "Permission denied".to_string(),
        _ => e.to_string(),
    };
    let name = path.display().to_string();
    // the reader's own refusals carry no errno: give a folder its own (Python's
    // `IsADirectoryError`) and a file past the limit `EFBIG`
    let errno = e.raw_os_error().or(match e.kind() {
        std::io::ErrorKind::IsADirectory => Some(21),
        std::io::ErrorKind::FileTooLarge => Some(27),
        _ => None,
    });
    match errno {
        Some(errno) => PyOSError::new_err((errno, why, name)),
        None => PyOSError::new_err(format!("{name}: {why}")),
    }
}

/// Reads a grammar whole (a regular file of at most `clay_dsl::MAX_SOURCE_BYTES`: no named
/// pipe is waited on, no `/dev/zero` read without end), or says why not as an `OSError`.
pub fn read(path: &Path) -> PyResult<Vec<u8>> {
    clay_dsl::read_input(path, clay_dsl::MAX_SOURCE_BYTES).map_err(|e| os_error(&e, path))
}

/// Runs library code, turning a panic (a bug) into `InternalError` instead of letting it
/// unwind into the interpreter.
pub fn guard<T>(what: &str, f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(result) => result,
        Err(payload) => {
            let why = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "no message".into());
            Err(InternalError::new_err(format!(
                "{what} failed inside Clay (a bug, please report it): {why}"
            )))
        }
    }
}

/// A path argument: `str` or `os.PathLike`.
pub fn path_of(value: &Bound<'_, PyAny>) -> PyResult<PathBuf> {
    value.extract::<PathBuf>().map_err(|_| {
        PyTypeError::new_err(format!(
            "expected a path (str or os.PathLike), found {}",
            type_name(value)
        ))
    })
}

pub fn type_name(value: &Bound<'_, PyAny>) -> String {
    value
        .get_type()
        .name()
        .map_or_else(|_| "an object".into(), |n| n.to_string())
}

/// A finite number for a JSON step (`what` names it in the message as a script would).
pub fn finite(value: f64, what: &str) -> PyResult<serde_json::Value> {
    serde_json::Number::from_f64(value)
        .map(serde_json::Value::Number)
        .ok_or_else(|| {
            // As Python spells them.
            let shown = if value.is_nan() {
                "nan"
            } else if value > 0.0 {
                "inf"
            } else {
                "-inf"
            };
            PyValueError::new_err(format!("{what} must be a finite number, found {shown}"))
        })
}

/// Whether `value` is a truth value: Python's `bool` or numpy's (`numpy.bool_`, which is no
/// subclass of `bool`). A number argument refuses them: `True` for a frame count is a mistake.
pub fn is_bool(value: &Bound<'_, PyAny>) -> bool {
    value.is_instance_of::<PyBool>() || matches!(type_name(value).as_str(), "bool" | "bool_")
}

/// A number: a Python `int` or `float` or anything that converts as one (numpy's scalars,
/// a `Fraction`, a `Decimal`), not a truth value or a string. Not yet checked for finiteness.
pub fn number(value: &Bound<'_, PyAny>, what: &str) -> PyResult<f64> {
    if is_bool(value) {
        return Err(PyTypeError::new_err(format!(
            "{what} must be a number, found bool"
        )));
    }
    if value.is_instance_of::<PyString>() || value.is_instance_of::<PyBytes>() {
        return Err(PyTypeError::new_err(format!(
            "{what} must be a number, found {}",
            type_name(value)
        )));
    }
    value.extract::<f64>().map_err(|_| {
        PyTypeError::new_err(format!(
            "{what} must be a number, found {}",
            type_name(value)
        ))
    })
}

/// A whole number given as one: a Python `int` or anything with `__index__` (numpy's
/// integers), not a truth value; `None` when `value` is not of an integer type (a float, to
/// be judged as a number). Too large for 64 bits is a `ValueError`.
pub fn integer(value: &Bound<'_, PyAny>, what: &str) -> PyResult<Option<i64>> {
    if is_bool(value) {
        return Err(PyTypeError::new_err(format!(
            "{what} must be a number, found bool"
        )));
    }
    let index = if value.is_instance_of::<PyInt>() {
        value.clone()
    } else if value.hasattr("__index__")? && !value.is_instance_of::<PyFloat>() {
        value.call_method0("__index__")?
    } else {
        return Ok(None);
    };
    index.extract::<i64>().map(Some).map_err(|_| {
        PyValueError::new_err(format!(
            "{what} is too large: {}",
            value
                .repr()
                .map_or_else(|_| type_name(value), |r| r.to_string())
        ))
    })
}

/// A point `(x, y)` of finite numbers, as a JSON array for a step: a tuple, a list, a numpy
/// array or any other iterable of exactly two numbers (numpy's scalars too).
pub fn point(value: &Bound<'_, PyAny>, what: &str) -> PyResult<serde_json::Value> {
    let shown = || {
        value
            .repr()
            .map_or_else(|_| type_name(value), |r| r.to_string())
    };
    let wrong = || {
        PyTypeError::new_err(format!(
            "{what} must be a pair of numbers (x, y), found {}",
            shown()
        ))
    };
    // A string iterates as characters and a dict as its keys: neither is a point.
    if value.is_instance_of::<PyString>()
        || value.is_instance_of::<PyBytes>()
        || value.is_instance_of::<PyDict>()
    {
        return Err(wrong());
    }
    let items: Vec<Bound<'_, PyAny>> = value
        .try_iter()
        .map_err(|_| wrong())?
        .take(3)
        .collect::<PyResult<_>>()
        .map_err(|_| wrong())?;
    let [x, y] = items.as_slice() else {
        return Err(wrong());
    };
    let coordinate = |c: &Bound<'_, PyAny>| number(c, what).map_err(|_| wrong());
    Ok(serde_json::Value::Array(vec![
        finite(coordinate(x)?, what)?,
        finite(coordinate(y)?, what)?,
    ]))
}
