//! `robowire.sim`: every simulator in-process, as a context manager, with its faults.

mod chassis;
mod g1;
mod go2;
mod unitree;
mod zsl1;

pub(crate) use spline::state_dict;
mod spline;

use pyo3::prelude::*;

/// Adds the classes to the extension module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("SimZsl1", py.get_type::<zsl1::Zsl1>())?;
    m.add("SimChassis", py.get_type::<chassis::Chassis>())?;
    m.add("SimSpline", py.get_type::<spline::Spline>())?;
    m.add("SimGo2", py.get_type::<go2::Go2>())?;
    m.add("SimG1", py.get_type::<g1::G1>())?;
    m.add_function(wrap_pyfunction!(go2::loopback_has_multicast, m)?)?;
    m.add_function(wrap_pyfunction!(go2::enter_loopback_namespace, m)?)?;
    Ok(())
}
