//! The drop-in `LowLevel` of `robowire.zsl1`: twelve motors, the vendor's calls and codes.

use super::session::session_methods;
use pyo3::prelude::*;
use zsl::udp::{LowLevel, Model};

use super::motor::{MotorCommand, MotorState};
use super::session::Session;

type Floats = Vec<f64>;

fn floats<const N: usize>(v: [f32; N]) -> Floats {
    v.iter().map(|x| f64::from(*x)).collect()
}

/// The ZSL-1 LowLevel client, a drop-in for `mc_sdk_zsl_1_py.LowLevel`. Streams the all-zero
/// idle command (kp = kd = 0: nothing driven) from `initRobot` on, then the last accepted
/// `MotorCommand` every 2 ms.
#[pyclass(name = "LowLevel", module = "robowire.zsl1", frozen)]
pub(crate) struct Zsl1LowLevel {
    session: Session<LowLevel>,
}

#[allow(non_snake_case)]
#[pymethods]
impl Zsl1LowLevel {
    /// Not connected until `initRobot`. `record` (not the vendor's): a path or a
    /// `robowire.Recorder` to record every datagram both ways into (`zsl1/low_level`).
    #[new]
    #[pyo3(signature = (*, record = None))]
    fn new(record: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        Ok(Self { session: Session::new(Model::Zsl1, record)? })
    }

    /// Binds `local_ip:local_port` and starts streaming to `dog_ip:43900`. Raises `BindError`
    /// if the address cannot be bound.
    #[pyo3(signature = (local_ip, local_port, dog_ip = "192.168.234.1"))]
    fn initRobot(&self, py: Python<'_>, local_ip: &str, local_port: i64, dog_ip: &str) -> PyResult<()> {
        self.session.init(py, local_ip, local_port, dog_ip)
    }

    /// State arrived within the last 3 s.
    fn checkConnect(&self) -> bool {
        self.session.is_connected()
    }

    /// Latches `cmd`; the stream sends it at once and every 2 ms. 0 accepted; -1 refused and
    /// nothing changed (the previous command keeps streaming): a position outside the vendor's
    /// bounds (abad −0.7…0.7, hip −1.15…3.0, knee −2.9…−0.65 rad), or any NaN or infinite value
    /// (the vendor sends NaN). `last_error` says which.
    fn sendMotorCmd(&self, cmd: &MotorCommand) -> PyResult<i32> {
        let c = self.session.running()?.client;
        Ok(if self.session.accepted(c.send_motor_command(&cmd.to_facade())).is_ok() { 0 } else { -1 })
    }

    /// The twelve motors (a new `MotorState` per call). Raises `NoStateError` without state.
    fn getMotorState(&self) -> PyResult<MotorState> {
        self.session.read(|c| c.motor_state().map(|s| MotorState::from(&s)))
    }

    /// The last state carried the motor-data magic 0x5AA5 (False without state).
    fn haveMotorData(&self) -> bool {
        self.session.client().is_some_and(|c| c.has_motor_data())
    }

    /// Orientation quaternion w, x, y, z.
    fn getQuaternion(&self) -> PyResult<Floats> {
        self.session.read(|c| c.quaternion().map(floats))
    }

    /// Roll, pitch, yaw, rad.
    fn getRPY(&self) -> PyResult<Floats> {
        self.session.read(|c| c.rpy().map(floats))
    }

    /// Body acceleration x, y, z, m/s².
    fn getBodyAcc(&self) -> PyResult<Floats> {
        self.session.read(|c| c.body_acc().map(floats))
    }

    /// Body angular rate x, y, z, rad/s.
    fn getBodyGyro(&self) -> PyResult<Floats> {
        self.session.read(|c| c.body_gyro().map(floats))
    }
}

session_methods!(Zsl1LowLevel);
