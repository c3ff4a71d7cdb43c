//! Counters and lateness summaries as Python dicts.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use robowire_core::timing::LatenessSummary;

/// `{"count", "p50_us", "p99_us", "max_us"}`.
pub(crate) fn lateness<'py>(py: Python<'py>, summary: &LatenessSummary) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("count", summary.count)?;
    d.set_item("p50_us", summary.p50_us)?;
    d.set_item("p99_us", summary.p99_us)?;
    d.set_item("max_us", summary.max_us)?;
    Ok(d)
}

/// A dict from `name => value` pairs.
macro_rules! dict {
    ($py:expr, { $($key:literal => $value:expr),* $(,)? }) => {{
        let d = pyo3::types::PyDict::new($py);
        $(d.set_item($key, $value)?;)*
        d
    }};
}

pub(crate) use dict;
