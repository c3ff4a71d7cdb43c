//! `robowire.unitree`: Unitree LowCmd/LowState (Go2 and HG) as objects with the IDL field
//! names; struct image and CDR both ways, the CRC written and verified.

mod message;
mod view;

use pyo3::prelude::*;

pub(crate) use message::{PyHgLowCmd, PyHgLowState, PyLowCmd, PyLowState};

/// Adds the classes to the extension module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("LowCmd", py.get_type::<PyLowCmd>())?;
    m.add("LowState", py.get_type::<PyLowState>())?;
    m.add("HgLowCmd", py.get_type::<PyHgLowCmd>())?;
    m.add("HgLowState", py.get_type::<PyHgLowState>())?;
    m.add_class::<view::StructView>()?;
    m.add_class::<view::ArrayView>()?;
    Ok(())
}
