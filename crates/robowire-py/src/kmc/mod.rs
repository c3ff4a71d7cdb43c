//! `robowire.kmc`: the KMC chassis's streaming `Driver` and the one-frame-at-a-time
//! `UartClient`, over the `kmc` facade. Frames and states from the chassis become the
//! dataclasses of `robowire/kmc.py`.

mod driver;
mod uart;

use kmc::{ChassisFrame, ChassisState, KmcError};
use kmc_proto::Rw;
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyBytes, PyString, PyTuple};

pub(crate) use driver::{Driver, Messages};
pub(crate) use uart::UartClient;

use crate::errors::{Kind, chain, error};

/// A `KmcError` as the exception a Python user expects.
pub(crate) fn raise(e: KmcError) -> PyErr {
    let kind = match &e {
        KmcError::Argument(_) | KmcError::Option { .. } => Kind::Argument,
        KmcError::Link(_) => Kind::Port,
        KmcError::NotRunning => Kind::Closed,
        _ => Kind::Error,
    };
    error(kind, chain(&e))
}

static MODULE: PyOnceLock<Py<PyModule>> = PyOnceLock::new();

/// `robowire.kmc.<name>` (the module is imported once).
fn class<'py>(py: Python<'py>, name: &Bound<'py, PyString>) -> PyResult<Bound<'py, PyAny>> {
    MODULE.get_or_try_init(py, || py.import("robowire.kmc").map(Bound::unbind))?.bind(py).getattr(name)
}

/// A frame from the chassis as `robowire.kmc.VehicleSpeed`, `BatteryVoltage`, `MotorState` or
/// `AfResponse`.
fn frame_to_py<'py>(py: Python<'py>, frame: &ChassisFrame) -> PyResult<Bound<'py, PyAny>> {
    match frame {
        ChassisFrame::VehicleSpeed(v) => class(py, intern!(py, "VehicleSpeed"))?.call1((f64::from(v.speed_mps),)),
        ChassisFrame::BatteryVoltage(b) => {
            class(py, intern!(py, "BatteryVoltage"))?.call1((b.motor_id, f64::from(b.volts)))
        }
        ChassisFrame::AllState(s) => class(py, intern!(py, "MotorState"))?.call1((
            s.motor_id,
            s.id,
            f64::from(s.position_deg),
            f64::from(s.speed_rpm),
            f64::from(s.current_a),
            f64::from(s.temperature_c),
            s.error_code,
            PyTuple::new(py, s.reserved.map(f64::from))?,
        )),
        ChassisFrame::Af(f) => {
            let ids: Vec<u8> = f.ids().iter().map(|id| id.to_byte()).collect();
            let slots: Vec<Bound<'py, PyBytes>> = f.slots().iter().map(|s| PyBytes::new(py, s)).collect();
            let rw = if f.rw() == Rw::Read { "read" } else { "write" };
            class(py, intern!(py, "AfResponse"))?.call1((
                f.motor_id(),
                rw,
                PyTuple::new(py, ids)?,
                PyTuple::new(py, slots)?,
            ))
        }
    }
}

/// The chassis's state as `robowire.kmc.ChassisState` (its odometry an `Odometry`, its reports
/// the frames' dataclasses).
fn state_to_py<'py>(py: Python<'py>, state: &ChassisState) -> PyResult<Bound<'py, PyAny>> {
    let battery = state.battery.map(|b| frame_to_py(py, &ChassisFrame::BatteryVoltage(b))).transpose()?;
    let motors = state
        .motors
        .iter()
        .map(|m| m.map(|s| frame_to_py(py, &ChassisFrame::AllState(s))).transpose())
        .collect::<PyResult<Vec<_>>>()?;
    let o = &state.odometry;
    let odometry =
        class(py, intern!(py, "Odometry"))?.call1((o.x_m, o.y_m, o.heading_rad, o.speed_mps, o.yaw_rate_radps))?;
    class(py, intern!(py, "ChassisState"))?.call1((
        state.speed_mps.map(f64::from),
        battery,
        PyTuple::new(py, motors)?,
        odometry,
    ))
}

/// Adds the classes to the extension module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Driver>()?;
    m.add_class::<Messages>()?;
    m.add_class::<UartClient>()?;
    Ok(())
}
