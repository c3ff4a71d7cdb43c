//! `robowire.open(address)` and `robowire.Device`: any device by its address, in the one shape
//! every app drives (`robowire_devices`): status, connection, a neutral observation, drive,
//! services, close. The simulators of `sim:` addresses are in the wheel.

use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use robowire_devices::{AnyDevice, DeviceAddress, DeviceError, Observation, OpenOptions, SimPhysics};
use zsl::udp::{CallError, Refusal};

use crate::errors::{Kind, chain, error};
use crate::owned::Owned;
use crate::pyjson::to_py;
use crate::record::{Capture, record_arg};
use crate::runtime::{self, seconds};
use crate::stats::dict;

/// A `DeviceError` as the exception a Python user expects: the facade's own mapping where there
/// is one.
pub(crate) fn raise(e: DeviceError) -> PyErr {
    match e {
        DeviceError::Kmc(e) => crate::kmc::raise(e),
        DeviceError::Unitree(e) => crate::errors::unitree_error(e),
        DeviceError::ZslConnect(e) => crate::zsl::connect_error("ZSL-1 client", &e),
        e @ (DeviceError::Address(_)
        | DeviceError::NoSuchService { .. }
        | DeviceError::NoPhysics { .. }
        | DeviceError::ZslCall(CallError::Refused(Refusal::Argument(_)))) => error(Kind::Argument, chain(&e)),
        e => error(Kind::Error, chain(&e)),
    }
}

/// The state's parts as dicts (units in the keys), or `None` where the device has no such part.
fn observation<'py>(py: Python<'py>, o: &Observation) -> PyResult<Bound<'py, PyDict>> {
    let odometry = o
        .odometry
        .map(|d| -> PyResult<_> {
            Ok(dict!(py, {
                "position_m" => d.position_m.to_vec(),
                "orientation_xyzw" => d.orientation_xyzw.to_vec(),
                "linear_mps" => d.linear_mps.to_vec(),
                "angular_radps" => d.angular_radps.to_vec(),
            }))
        })
        .transpose()?;
    let imu = o
        .imu
        .map(|i| -> PyResult<_> {
            Ok(dict!(py, {
                "orientation_xyzw" => i.orientation_xyzw.to_vec(),
                "gyro_radps" => i.gyro_radps.to_vec(),
                "acc_mps2" => i.acc_mps2.to_vec(),
            }))
        })
        .transpose()?;
    let joints = o
        .joints
        .as_ref()
        .map(|j| -> PyResult<_> {
            Ok(dict!(py, {
                "names" => j.names.clone(),
                "position_rad" => j.position_rad.clone(),
                "velocity_radps" => j.velocity_radps.clone(),
                "effort_nm" => j.effort_nm.clone(),
            }))
        })
        .transpose()?;
    let battery = o
        .battery
        .as_ref()
        .map(|b| -> PyResult<_> {
            Ok(dict!(py, {
                "voltage_v" => b.voltage_v,
                "current_a" => b.current_a,
                "charge_fraction" => b.charge_fraction,
                "cells_v" => b.cells_v.clone(),
            }))
        })
        .transpose()?;
    let motors = o
        .motors
        .iter()
        .map(|m| -> PyResult<_> {
            Ok(dict!(py, {
                "name" => m.name.as_str(),
                "hardware_id" => m.hardware_id.as_str(),
                "ok" => m.ok,
                "message" => m.message.as_str(),
                "values" => m.values.clone(),
            }))
        })
        .collect::<PyResult<Vec<_>>>()?;
    let passthrough = o
        .passthrough
        .as_ref()
        .map(|p| -> PyResult<_> {
            Ok(dict!(py, {
                "topic" => p.topic,
                "type_name" => p.type_name,
                "body" => pyo3::types::PyBytes::new(py, &p.body),
            }))
        })
        .transpose()?;
    Ok(dict!(py, {
        "odometry" => odometry,
        "imu" => imu,
        "joints" => joints,
        "battery" => battery,
        "motors" => motors,
        "passthrough" => passthrough,
    }))
}

/// A device opened by `robowire.open(address)`.
///
/// ```python
/// with robowire.open("sim:zsl1") as dog:
///     dog.wait_state(timeout_s=5.0)
///     dog.call("stand_up")
///     print(dog.status_text())
/// ```
#[pyclass(module = "robowire", frozen)]
pub(crate) struct Device {
    device: Owned<Arc<AnyDevice>>,
    address: String,
    kind: &'static str,
    capture: Capture,
}

impl Device {
    fn device(&self) -> PyResult<Arc<AnyDevice>> {
        self.device.with(|d| d.clone())
    }

    fn no_state(&self) -> PyErr {
        error(Kind::NoState, format!("no state from {} yet", self.address))
    }
}

#[pymethods]
impl Device {
    /// The address it was opened by.
    #[getter]
    fn address(&self) -> &str {
        &self.address
    }

    /// What it is: `"kmc"`, `"zsl1"`, `"zsl1w"`, `"go2"` or `"hg"`.
    #[getter]
    fn kind(&self) -> &'static str {
        self.kind
    }

    /// `"waiting"` (no state yet), `"connected"`, `"disconnected"` (silent past its watchdog) or
    /// `"closed"`.
    #[getter]
    fn connection(&self) -> &'static str {
        self.device().map_or("closed", |d| d.connection().name())
    }

    /// Waits up to `timeout_s` for a first state; whether one arrived. Ctrl-C interrupts.
    #[pyo3(signature = (timeout_s = 3.0))]
    fn wait_state(&self, py: Python<'_>, timeout_s: f64) -> PyResult<bool> {
        let timeout = seconds("timeout_s", timeout_s)?;
        let device = self.device()?;
        Ok(runtime::wait(py, Some(timeout), async move { device.wait_state(timeout).await })?.unwrap_or(false))
    }

    /// The latest state as a dict: the fields of `robowire status --json` for this device.
    /// Raises `NoStateError` before the first state.
    fn status<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let status = self.device()?.status_json().ok_or_else(|| self.no_state())?;
        to_py(py, &status)
    }

    /// The latest state as a few lines of text. Raises `NoStateError` before the first state.
    fn status_text(&self) -> PyResult<String> {
        self.device()?.status_text().ok_or_else(|| self.no_state())
    }

    /// The latest state, the same for every device: a dict of `odometry`, `imu`, `joints`,
    /// `battery` (each a dict, or `None` where the device does not report it), `motors` (a list)
    /// and `passthrough` (the vendor's own state message: `topic`, `type_name`, `body`); `None`
    /// before the first state.
    fn observe<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.device()?.observe().map(|o| observation(py, &o)).transpose()
    }

    /// Whether `drive` moves it (a mobile base).
    #[getter]
    fn can_drive(&self) -> PyResult<bool> {
        Ok(self.device()?.can_drive())
    }

    /// Drives a mobile base: `vx` m/s forward, `vy` m/s left, `yaw_rate` rad/s, checked by the
    /// device's own rules before anything is sent (`ArgumentError`: NaN, out of range). A device
    /// that is not driven by a velocity raises `robowire.Error`.
    fn drive(&self, vx: f32, vy: f32, yaw_rate: f32) -> PyResult<()> {
        self.device()?.drive(vx, vy, yaw_rate).map_err(raise)
    }

    /// Its named actions (`["stand_up", "lie_down", "passive"]` on a ZSL-1).
    #[getter]
    fn services(&self) -> PyResult<Vec<&'static str>> {
        Ok(self.device()?.services().to_vec())
    }

    /// Runs the named action; what the device said. An unknown name raises `ArgumentError`.
    fn call(&self, py: Python<'_>, name: &str) -> PyResult<String> {
        let device = self.device()?;
        py.detach(|| device.call(name)).map_err(raise)
    }

    fn __repr__(&self) -> String {
        let state = if self.device.is_open() { "open" } else { "closed" };
        format!("Device({:?}, {state})", self.address)
    }
}

#[pymethods]
impl Device {
    /// Does the device's safe thing (a stop burst, a stop, damping) and closes it, then stops its
    /// simulator, then finishes the capture of `record=PATH`. Idempotent.
    fn close(&self, py: Python<'_>) -> PyResult<()> {
        let closed = close(py, &self.device);
        let finished = self.capture.finish(py);
        closed.and(finished)
    }

    fn __enter__(slf: Py<Self>) -> Py<Self> {
        slf
    }

    #[pyo3(signature = (*_exc))]
    fn __exit__(&self, py: Python<'_>, _exc: &Bound<'_, pyo3::types::PyTuple>) -> PyResult<()> {
        self.close(py)
    }
}

/// Closes the device `owned` holds, the GIL released: its safe action, then its simulator.
/// Idempotent.
pub(crate) fn close(py: Python<'_>, owned: &Owned<Arc<AnyDevice>>) -> PyResult<()> {
    match owned.take().map(Arc::try_unwrap) {
        None => Ok(()),
        Some(Ok(device)) => py.detach(move || device.close()).map_err(raise),
        // Another thread is inside a call: the last one out closes it (dropping does the same).
        Some(Err(shared)) => {
            py.detach(move || drop(shared));
            Ok(())
        }
    }
}

/// `physics`, `model` and `free_base` as `OpenOptions::sim_physics`: the latter two need the first.
pub(crate) fn sim_physics(
    physics: bool,
    model: Option<std::path::PathBuf>,
    free_base: bool,
) -> PyResult<Option<SimPhysics>> {
    if !physics && (model.is_some() || free_base) {
        return Err(error(Kind::Argument, "model and free_base need physics=True"));
    }
    Ok(physics.then(|| SimPhysics { model, hanging: free_base.then_some(false), walk: None }))
}

/// Opens the device at `address` (`kmc:/dev/ttyUSB0`, `zsl1:192.168.234.1`, `zsl1w:IP`,
/// `go2:eth0`, `hg:eth0`, `sim:kmc|zsl1|zsl1w|go2`); `domain` is the DDS domain of `go2:`, `hg:`
/// and `sim:go2`. `record`: a path or a `robowire.Recorder` to record the client's links into
/// (`kmc/serial`, `zsl1/high_level`, `go2/low_level` and `go2/api`, …). A bad address raises
/// `ArgumentError`. `physics`: `sim:go2`'s or `sim:g1`'s body in MuJoCo (a wheel built with the
/// `mujoco` feature; `robowire.Error` without it, `ArgumentError` for any other address), the
/// G1 hanging by its pelvis unless `free_base`; `model`: a user's MJCF instead of robowire's.
#[pyfunction]
#[pyo3(signature = (address, *, domain = 0, record = None, physics = false, model = None, free_base = false))]
pub(crate) fn open(
    py: Python<'_>,
    address: &str,
    domain: u16,
    record: Option<&Bound<'_, PyAny>>,
    physics: bool,
    model: Option<std::path::PathBuf>,
    free_base: bool,
) -> PyResult<Device> {
    let parsed: DeviceAddress =
        address.parse().map_err(|e: robowire_devices::AddressError| error(Kind::Argument, e))?;
    let sim_physics = sim_physics(physics, model, free_base)?;
    let (record, capture) = record_arg(record, &format!("robowire.open({address:?})"))?;
    let options = OpenOptions { domain, record, sim_physics, ..OpenOptions::default() };
    let device = py.detach(|| robowire_devices::open(&parsed, &options)).map_err(raise)?;
    let kind = device.kind().name();
    Ok(Device { device: Owned::new("device", Arc::new(device)), address: parsed.to_string(), kind, capture })
}

/// Adds the function and the class to the extension module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Device>()?;
    m.add_function(wrap_pyfunction!(open, m)?)?;
    Ok(())
}
