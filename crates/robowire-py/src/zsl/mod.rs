//! `robowire.zsl1` and `robowire.zsl1w`: drop-ins for ZsiBot's `mc_sdk_zsl_1_py` and
//! `mc_sdk_zsl_1w_py` over the `zsl` facade.

mod high_level;
mod low_level;
mod motor;
mod session;

use pyo3::prelude::*;
use zsl::udp::{CallError, Latched};

pub(crate) use high_level::{Zsl1HighLevel, Zsl1wHighLevel};
pub(crate) use low_level::Zsl1LowLevel;
pub(crate) use motor::{JointArray, MotorCommand, MotorState};
pub(crate) use session::connect_error;

use crate::errors::{Kind, error};

/// A call the vendor declares `void`: nothing, or an exception with the reason.
fn unit<T: session::Facade>(session: &session::Session<T>, outcome: Result<Latched, CallError>) -> PyResult<()> {
    session.accepted(outcome.map(drop)).map_err(|e| error(Kind::Error, e))
}

/// Adds the classes to the extension module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("Zsl1HighLevel", py.get_type::<Zsl1HighLevel>())?;
    m.add("Zsl1LowLevel", py.get_type::<Zsl1LowLevel>())?;
    m.add("Zsl1wHighLevel", py.get_type::<Zsl1wHighLevel>())?;
    m.add("MotorCommand", py.get_type::<MotorCommand>())?;
    m.add("MotorState", py.get_type::<MotorState>())?;
    m.add("JointArray", py.get_type::<JointArray>())?;
    Ok(())
}
