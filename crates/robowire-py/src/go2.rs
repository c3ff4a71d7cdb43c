//! `robowire.go2`: a Unitree robot's low-level interface over DDS (the Go2, or an HG robot:
//! G1, H1-2), over the `unitree` facade.

use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use unitree::{Connection, Device, Go2, Hg, LowLevel, LowLevelOptions};

use crate::errors::{Kind, error, unitree_error};
use crate::joints::JointArgs;
use crate::owned::{Owned, closeable};
use crate::record::{Capture, record_arg};
use crate::runtime::{self, seconds};
use crate::stats::low_level_stats;
use crate::unitree::{PyHgLowCmd, PyHgLowState, PyLowCmd, PyLowState};

/// The client of either robot family.
enum Client {
    Go2(Arc<LowLevel<Go2>>),
    Hg(Arc<LowLevel<Hg>>),
}

/// `$body` with `$c` bound to the client, whichever robot it is.
macro_rules! with_client {
    ($client:expr, |$c:ident| $body:expr) => {
        match $client {
            Client::Go2($c) => $body,
            Client::Hg($c) => $body,
        }
    };
}

/// A Unitree robot's low-level interface over DDS, as Unitree's low-level examples use it,
/// with robowire's safety: commands are checked (NaN, infinities, gains, torques, the Go2's
/// joint limits) before anything is sent; nothing is sent until the first command; a command
/// older than 100 ms is replaced by damping; a state silent for 100 ms is reported; closing
/// (or leaving a `with` block) sends damping last.
///
/// ```python
/// with robowire.go2.LowLevel(interface="eth0") as robot:
///     robot.release_sport_mode()                 # the robot lies down, sport mode lets go
///     robot.wait_state(timeout_s=3.0)
///     for _ in range(1000):
///         robot.set_joints(q=[0.0, 0.67, -1.3] * 4, kp=60.0, kd=5.0)
///         time.sleep(0.002)
/// ```
#[pyclass(name = "LowLevel", module = "robowire.go2", frozen)]
pub(crate) struct Go2LowLevel {
    client: Owned<Client>,
    robot: &'static str,
    capture: Capture,
}

impl Go2LowLevel {
    fn client(&self) -> PyResult<Client> {
        self.client.with(|c| match c {
            Client::Go2(c) => Client::Go2(c.clone()),
            Client::Hg(c) => Client::Hg(c.clone()),
        })
    }
}

#[pymethods]
impl Go2LowLevel {
    /// Joins DDS domain `domain` on `interface` (the robot's network, 192.168.123.x: `"eth0"`,
    /// `"enp3s0"`; `None` lets the library choose). `robot` `"go2"` or `"hg"` (G1, H1-2).
    /// `record`: a path or a `robowire.Recorder` to record the client's side of
    /// `go2/low_level` and `go2/api` (`hg/…` for an HG robot) into.
    #[new]
    #[pyo3(signature = (*, domain = 0, interface = None, robot = "go2", service_timeout_s = 5.0, record = None))]
    fn new(
        py: Python<'_>,
        domain: u16,
        interface: Option<&str>,
        robot: &str,
        service_timeout_s: f64,
        record: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let low_level = match robot {
            "go2" => &unitree_proto::description::GO2_LOW_LEVEL,
            "hg" => &unitree_proto::description::HG_LOW_LEVEL,
            other => return Err(error(Kind::Argument, format!("robot = {other:?}: \"go2\" or \"hg\""))),
        };
        let service_timeout = seconds("service_timeout_s", service_timeout_s)?;
        let (links, capture) = record_arg(record, "robowire.go2.LowLevel")?;
        let options = LowLevelOptions { service_timeout, ..LowLevelOptions::on(interface, domain) }.recorded(
            links.as_ref(),
            robot,
            low_level,
        );
        let (client, robot) = match robot {
            "go2" => {
                (Client::Go2(Arc::new(py.detach(|| LowLevel::<Go2>::open(options)).map_err(unitree_error)?)), "go2")
            }
            _ => (Client::Hg(Arc::new(py.detach(|| LowLevel::<Hg>::open(options)).map_err(unitree_error)?)), "hg"),
        };
        Ok(Self { client: Owned::new("Go2 client", client), robot, capture })
    }

    /// `"go2"` or `"hg"`.
    #[getter]
    fn robot(&self) -> &'static str {
        self.robot
    }

    /// Releases the sport mode as Unitree's low-level example does (CheckMode; while a mode
    /// owns the motors: StandDown, ReleaseMode, CheckMode). Returns the ReleaseMode calls it
    /// took (0 if nothing owned the motors). Raises `ServiceError` if a service refuses or does
    /// not answer within `service_timeout_s`. Ctrl-C interrupts.
    fn release_sport_mode(&self, py: Python<'_>) -> PyResult<u32> {
        let outcome =
            with_client!(self.client()?, |c| runtime::wait(py, None, async move { c.release_sport_mode().await })?);
        outcome.expect("no timeout").map_err(unitree_error)
    }

    /// The sport mode that owns the motors (`""`: none).
    fn sport_mode(&self, py: Python<'_>) -> PyResult<String> {
        let outcome = with_client!(self.client()?, |c| runtime::wait(py, None, async move { c.sport_mode().await })?);
        outcome.expect("no timeout").map_err(unitree_error)
    }

    /// Go2: latches a command for the 12 joints (motor order FR, FL, RR, RL × hip, thigh, calf),
    /// each argument one number for every joint or 12: position `q` rad, gains `kp` (0–500),
    /// `kd` (0–50), velocity `dq` rad/s, torque `tau` N·m. Raises `ArgumentError` (nothing
    /// sent, the previous command stays) for NaN, infinities, values out of range.
    #[pyo3(signature = (q, kp, kd, dq = None, tau = None))]
    fn set_joints(
        &self,
        q: &Bound<'_, PyAny>,
        kp: &Bound<'_, PyAny>,
        kd: &Bound<'_, PyAny>,
        dq: Option<&Bound<'_, PyAny>>,
        tau: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let Client::Go2(c) = self.client()? else {
            return Err(error(Kind::Argument, "set_joints is the Go2's; an HG robot takes set_command(HgLowCmd)"));
        };
        let joints = JointArgs { q, kp, kd, dq, tau }
            .commands::<12>("motor order FR, FL, RR, RL × hip, thigh, calf", |_| true)?;
        c.set_joints(&joints).map_err(unitree_error)
    }

    /// Latches a whole `robowire.unitree.LowCmd` (Go2) or `HgLowCmd` (HG), checked like
    /// `set_joints`; the CRC is written when sent.
    fn set_command(&self, command: &Bound<'_, PyAny>) -> PyResult<()> {
        match self.client()? {
            Client::Go2(c) => {
                let cmd = command
                    .cast::<PyLowCmd>()
                    .map_err(|_| error(Kind::Argument, "a Go2 takes a robowire.unitree.LowCmd"))?;
                c.set_command(cmd.get().message()).map_err(unitree_error)
            }
            Client::Hg(c) => {
                let cmd = command
                    .cast::<PyHgLowCmd>()
                    .map_err(|_| error(Kind::Argument, "an HG robot takes a robowire.unitree.HgLowCmd"))?;
                c.set_command(cmd.get().message()).map_err(unitree_error)
            }
        }
    }

    /// Damping (kp 0, a small kd) from the next tick on, until the next command.
    fn damp(&self) -> PyResult<()> {
        with_client!(self.client()?, |c| c.damp());
        Ok(())
    }

    /// The latest state (`LowState` or `HgLowState`, CRC verified). Raises `NoStateError`
    /// before the first and while the robot is silent (100 ms).
    fn state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let client = self.client()?;
        let silent = with_client!(&client, |c| c.connection() == Connection::Disconnected);
        let none = || {
            error(
                Kind::NoState,
                if silent { "the robot has been silent for 100 ms or more" } else { "no LowState yet" },
            )
        };
        if silent {
            return Err(none());
        }
        match client {
            Client::Go2(c) => {
                Ok(Bound::new(py, PyLowState::from_message(&c.latest().ok_or_else(none)?.state))?.into_any())
            }
            Client::Hg(c) => {
                Ok(Bound::new(py, PyHgLowState::from_message(&c.latest().ok_or_else(none)?.state))?.into_any())
            }
        }
    }

    /// Seconds since the latest state arrived (`None` before the first).
    #[getter]
    fn state_age_s(&self) -> PyResult<Option<f64>> {
        Ok(with_client!(self.client()?, |c| c.latest().map(|s| s.age().as_secs_f64())))
    }

    /// Waits up to `timeout_s` for the next state and returns it; raises `TimeoutError` if
    /// none came. Ctrl-C interrupts.
    #[pyo3(signature = (timeout_s = 3.0))]
    fn wait_state<'py>(&self, py: Python<'py>, timeout_s: f64) -> PyResult<Bound<'py, PyAny>> {
        let timeout = seconds("timeout_s", timeout_s)?;
        let timed_out = || error(Kind::Timeout, format!("no LowState within {timeout_s} s"));
        match self.client()? {
            Client::Go2(c) => {
                let state =
                    runtime::wait(py, Some(timeout), async move { c.wait_state(timeout, |_| true).await })?.flatten();
                Ok(Bound::new(py, PyLowState::from_message(&state.ok_or_else(timed_out)?))?.into_any())
            }
            Client::Hg(c) => {
                let state =
                    runtime::wait(py, Some(timeout), async move { c.wait_state(timeout, |_| true).await })?.flatten();
                Ok(Bound::new(py, PyHgLowState::from_message(&state.ok_or_else(timed_out)?))?.into_any())
            }
        }
    }

    /// Go2: the 12 joint positions of the latest state, rad (motor order). Raises `NoStateError`.
    fn joint_positions(&self) -> PyResult<Vec<f64>> {
        let Client::Go2(c) = self.client()? else {
            return Err(error(Kind::Argument, "joint_positions is the Go2's; read state().motor_state"));
        };
        c.joint_positions().map(|q| q.map(f64::from).to_vec()).ok_or_else(|| error(Kind::NoState, "no LowState yet"))
    }

    /// `"waiting"`, `"connected"` or `"disconnected"` (no state for 100 ms).
    #[getter]
    fn connection(&self) -> PyResult<&'static str> {
        Ok(with_client!(self.client()?, |c| c.connection()).name())
    }

    /// Topics, commands sent, damping, timeouts, lost states, timing.
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        low_level_stats(py, &with_client!(self.client()?, |c| c.stats()))
    }

    fn __repr__(&self) -> String {
        format!("LowLevel(robot={:?}, open={})", self.robot, self.client.is_open())
    }
}

closeable!(
    Go2LowLevel,
    client,
    capture,
    "Sends damping last, leaves the domain, then finishes its own capture. Idempotent."
);

/// Adds the classes to the extension module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("Go2LowLevel", m.py().get_type::<Go2LowLevel>())?;
    Ok(())
}
