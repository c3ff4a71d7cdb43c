//! Values with a JSON form (the codecs' `serde`, what `robowire decode --json` prints) to and
//! from Python objects, through that same JSON: the Python objects equal `json.loads` of the
//! CLI's output.

use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::IntoPyDict;
use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::errors::{Kind, error};

static JSON: PyOnceLock<Py<PyModule>> = PyOnceLock::new();

fn json(py: Python<'_>) -> PyResult<&Bound<'_, PyModule>> {
    Ok(JSON.get_or_try_init(py, || py.import("json").map(Bound::unbind))?.bind(py))
}

/// `value` as Python objects (dicts, lists, numbers, strings; non-finite floats as the strings
/// `"NaN"`, `"Infinity"`, …).
pub(crate) fn to_py<'py, T: Serialize + ?Sized>(py: Python<'py>, value: &T) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(|e| error(Kind::Error, format!("to JSON: {e}")))?;
    json(py)?.call_method1("loads", (text,))
}

/// A `T` from Python objects of its JSON shape; `what` names it in the error.
pub(crate) fn from_py<T: DeserializeOwned>(what: &str, value: &Bound<'_, PyAny>) -> PyResult<T> {
    let py = value.py();
    let text: String = json(py)?
        .call_method("dumps", (value,), Some(&[("allow_nan", false)].into_py_dict(py)?))
        .map_err(|e| error(Kind::Argument, format!("{what}: {e} (write NaN and infinities as \"NaN\", \"Infinity\")")))?
        .extract()?;
    serde_json::from_str(&text).map_err(|e| error(Kind::Argument, format!("{what}: {e}")))
}
