//! robowire for Python: the `robowire._native` extension behind the `robowire` package
//! (`python/robowire`). Importing it starts no thread and opens nothing: each client and
//! simulator starts its own threads when it is opened, and stops them when it is closed.
#![forbid(unsafe_code)]

mod device;
mod errors;
mod g1;
mod go2;
mod joints;
mod kmc;
mod owned;
mod policy;
mod pyjson;
mod record;
mod runtime;
mod sim;
mod spline;
mod stats;
mod unitree;
mod zsl;

use pyo3::prelude::*;

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    zsl::register(m)?;
    sim::register(m)?;
    kmc::register(m)?;
    unitree::register(m)?;
    go2::register(m)?;
    g1::register(m)?;
    spline::register(m)?;
    device::register(m)?;
    record::register(m)?;
    policy::register(m)?;
    Ok(())
}
