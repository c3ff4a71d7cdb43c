//! `robowire.g1`: the Unitree G1 humanoid over DDS, over the `unitree` facade's G1 (`rt/lowcmd` with the
//! robot's `mode_machine`, `rt/arm_sdk` with a ramped weight, the loco and arm services).

mod services;
pub(crate) mod variant;

use std::future::Future;
use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use unitree::g1::{ARM_JOINTS, ARM_SDK_JOINTS, Connection, Device, G1, G1Error, G1Options, JOINTS, LowLevelOptions};
use unitree_proto::api::{g1_arm, g1_loco};

use crate::errors::{Kind, chain, error, service_error};
use crate::joints::{JointArgs, per_joint};
use crate::owned::{Owned, closeable};
use crate::record::{Capture, record_arg};
use crate::runtime::{self, seconds};
use crate::stats::{dict, lateness, low_level_stats, topic};
use crate::unitree::{PyHgLowCmd, PyHgLowState};
use services::{ArmActions, Loco};
use variant::{variant_name, variant_named};

/// A `G1Error` as the exception a Python user expects: a refused command or argument
/// `ArgumentError`; a refusal of the `sport` or `arm` service `ServiceError` with its service,
/// API id and code; the link as `robowire.go2` raises it.
pub(crate) fn raise(e: G1Error) -> PyErr {
    use g1_arm::error as arm;
    use g1_loco::error as loco;
    let e = match e {
        G1Error::LowLevel(e) => return crate::errors::unitree_error(e),
        e => e,
    };
    let refused = |service, api_id, code| service_error(chain(&e), service, api_id, code);
    match &e {
        G1Error::Command(_) | G1Error::Argument { .. } | G1Error::NoArmTargets => error(Kind::Argument, chain(&e)),
        G1Error::LocoStateUnavailable { api_id } => refused(g1_loco::SERVICE, *api_id, loco::LOCO_STATE_UNAVAILABLE),
        G1Error::InvalidFsmId { .. } => refused(g1_loco::SERVICE, g1_loco::SET_FSM_ID, loco::INVALID_FSM_ID),
        G1Error::InvalidTaskId { .. } => refused(g1_loco::SERVICE, g1_loco::SET_ARM_TASK, loco::INVALID_TASK_ID),
        G1Error::ArmSdkOccupied { .. } => refused(g1_arm::SERVICE, g1_arm::EXECUTE_ACTION, arm::ARM_SDK_OCCUPIED),
        G1Error::ArmHolding { .. } => refused(g1_arm::SERVICE, g1_arm::EXECUTE_ACTION, arm::HOLDING),
        G1Error::InvalidActionId { .. } => refused(g1_arm::SERVICE, g1_arm::EXECUTE_ACTION, arm::INVALID_ACTION_ID),
        G1Error::ArmFsm { .. } => refused(g1_arm::SERVICE, g1_arm::EXECUTE_ACTION, arm::INVALID_FSM_ID),
        _ => error(Kind::Error, chain(&e)),
    }
}

/// Runs a facade call with the GIL released (Ctrl-C interrupts); its error raised.
fn blocking<T: Send>(py: Python<'_>, call: impl Future<Output = Result<T, G1Error>> + Send) -> PyResult<T> {
    match runtime::wait(py, None, call)? {
        Some(outcome) => outcome.map_err(raise),
        None => Err(error(Kind::Timeout, "the call did not end")),
    }
}

/// The client, shared by the `G1` object and its `loco` and `arm` objects until `close()`.
type Shared = Arc<Owned<Arc<G1>>>;

fn client(shared: &Shared) -> PyResult<Arc<G1>> {
    shared.with(|c| c.clone())
}

/// The Unitree G1 humanoid over DDS, as Unitree's G1 examples drive it, with robowire's safety.
///
/// - `rt/lowcmd` (500 Hz once a command is set): the robot's `mode_machine` is read from its
///   LowState and copied into every command; before the first LowState every command raises
///   `ArgumentError` (nothing is sent with a guessed `mode_machine`). Each command is checked
///   for the robot's variant (joint ranges, speeds, torques, gains, disabled and undriven slots)
///   before it is latched; a command older than 100 ms becomes damping; closing damps last.
/// - `rt/arm_sdk` (50 Hz from the first `set_arm_joints`): the arm and waist targets blended
///   with the robot's own controller, the weight ramped at 0.5/s (never switched), ramped out
///   when no arm command came for 500 ms and when closing.
/// - `loco` (service `sport`) and `arm` (service `arm`): the typed service calls.
///
/// ```python
/// with robowire.g1.G1("eth0") as robot:
///     robot.wait_state(timeout_s=3.0)
///     mode = robot.mode()                        # "ai": the robot's controller owns the motors
///     robot.release()                            # hang the robot first: its controller lets go
///     q = robot.joint_positions()
///     for _ in range(1500):                      # 3 s at 500 Hz
///         robot.hold(q)
///         time.sleep(0.002)
///     robot.damp()
///     robot.select_mode(mode)                    # the controller takes the motors back
/// ```
#[pyclass(name = "G1", module = "robowire.g1", frozen)]
pub(crate) struct PyG1 {
    client: Shared,
    capture: Capture,
}

#[pymethods]
impl PyG1 {
    /// Joins DDS domain `domain` on `interface` (the robot's network, 192.168.123.x: `"eth0"`;
    /// `None` lets the library choose). `variant`: `"29dof"`, `"23dof"`, `"29dof_waist_locked"`
    /// or `"dual_arm"` whatever the LowState's `mode_machine` says (`None`: from it).
    /// `service_timeout_s`: the longest a service call waits for its answer. `record`: a path
    /// or a `robowire.Recorder` to record the client's side of `g1/low_level` (`rt/lowcmd`,
    /// `rt/lowstate`), `g1/api` and `g1/arm_sdk` into.
    #[new]
    #[pyo3(signature = (interface = None, domain = 0, *, variant = None, service_timeout_s = 5.0, record = None))]
    fn new(
        py: Python<'_>,
        interface: Option<&str>,
        domain: u16,
        variant: Option<&str>,
        service_timeout_s: f64,
        record: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let variant = variant.map(variant_named).transpose()?;
        let service_timeout = seconds("service_timeout_s", service_timeout_s)?;
        let (links, capture) = record_arg(record, "robowire.g1.G1")?;
        let low_level = LowLevelOptions { service_timeout, ..LowLevelOptions::on(interface, domain) };
        let options = G1Options { low_level, variant, ..G1Options::default() }.recorded(links.as_ref());
        let robot = py.detach(|| G1::open(options)).map_err(raise)?;
        Ok(Self { client: Arc::new(Owned::new("G1 client", Arc::new(robot))), capture })
    }

    /// Releases the robot's controller as Unitree's G1 low-level example does (motion_switcher
    /// CheckMode; while a mode is reported, ReleaseMode; a bounded number of attempts). Returns
    /// the ReleaseMode calls it took (0: nothing owned the motors). Afterwards `loco` raises
    /// `ServiceError` (code 7301) until `select_mode`. Raises `ServiceError` if a service
    /// refuses, does not answer or does not let go. On a real robot: hang it first.
    fn release(&self, py: Python<'_>) -> PyResult<u32> {
        let c = client(&self.client)?;
        blocking(py, async move { c.release().await })
    }

    /// The mode that owns the motors as CheckMode reports it (`""`: released).
    fn mode(&self, py: Python<'_>) -> PyResult<String> {
        let c = client(&self.client)?;
        blocking(py, async move { c.mode().await })
    }

    /// SelectMode `name` (a name `mode()` reported before `release()`): the robot's controller
    /// takes the motors back (and ignores LowCmds from then on); `loco` answers again.
    fn select_mode(&self, py: Python<'_>, name: &str) -> PyResult<()> {
        let c = client(&self.client)?;
        let name = name.to_owned();
        blocking(py, async move { c.select_mode(&name).await })
    }

    /// The robot's `mode_machine` (0..=255) from its latest LowState (`None` before the first).
    #[getter]
    fn mode_machine(&self) -> PyResult<Option<u8>> {
        Ok(client(&self.client)?.mode_machine())
    }

    /// Which G1: `"29dof"`, `"23dof"`, `"29dof_waist_locked"` or `"dual_arm"`; the constructor's
    /// `variant` if given, else what the LowState's `mode_machine` names (a value not in
    /// Unitree's table, a simulator's 0 included, is `"29dof"`); `None` before the first LowState.
    #[getter]
    fn variant(&self) -> PyResult<Option<&'static str>> {
        Ok(client(&self.client)?.variant().map(variant_name))
    }

    /// The latest `robowire.unitree.HgLowState` (CRC verified). Raises `NoStateError` before the
    /// first and while the robot is silent (100 ms).
    fn state(&self) -> PyResult<PyHgLowState> {
        let c = client(&self.client)?;
        if c.connection() == Connection::Disconnected {
            return Err(error(Kind::NoState, "the robot has been silent for 100 ms or more"));
        }
        let latest = c.latest().ok_or_else(|| error(Kind::NoState, "no LowState yet"))?;
        Ok(PyHgLowState::from_message(&latest.state))
    }

    /// Seconds since the latest state arrived (`None` before the first).
    #[getter]
    fn state_age_s(&self) -> PyResult<Option<f64>> {
        Ok(client(&self.client)?.latest().map(|s| s.age().as_secs_f64()))
    }

    /// Waits up to `timeout_s` for a LowState (the latest counts) and returns it; raises
    /// `TimeoutError` if none came. Ctrl-C interrupts.
    #[pyo3(signature = (timeout_s = 3.0))]
    fn wait_state(&self, py: Python<'_>, timeout_s: f64) -> PyResult<PyHgLowState> {
        let timeout = seconds("timeout_s", timeout_s)?;
        let c = client(&self.client)?;
        let state = runtime::wait(py, Some(timeout), async move { c.wait_state(timeout, |_| true).await })?.flatten();
        let state = state.ok_or_else(|| error(Kind::Timeout, format!("no LowState within {timeout_s} s")))?;
        Ok(PyHgLowState::from_message(&state))
    }

    /// `"waiting"`, `"connected"` or `"disconnected"` (no state for 100 ms).
    #[getter]
    fn connection(&self) -> PyResult<&'static str> {
        Ok(client(&self.client)?.connection().name())
    }

    /// Latches a whole `robowire.unitree.HgLowCmd` for `rt/lowcmd` if the G1's rules allow it
    /// (its `mode_machine` the robot's, `mode_pr` 0 or 1, joints within range, nothing set on a
    /// disabled or undriven slot); the CRC is written when sent. Raises `ArgumentError`
    /// (nothing sent, the previous command stays).
    fn set_command(&self, command: &Bound<'_, PyAny>) -> PyResult<()> {
        let cmd = command
            .cast::<PyHgLowCmd>()
            .map_err(|_| error(Kind::Argument, "a G1 takes a robowire.unitree.HgLowCmd"))?;
        client(&self.client)?.set_command(cmd.get().message()).map_err(raise)
    }

    /// Latches a command for the 29 joint slots (`JOINT_NAMES` order), each argument one number
    /// or 29 values: position `q` rad, gains `kp` (0–500 N·m/rad), `kd` (0–50 N·m·s/rad),
    /// velocity `dq` rad/s, torque `tau` N·m. A number goes to every joint the robot drives; a
    /// slot it does not drive (the 23-dof G1's waist roll/pitch and wrist pitch/yaw) must be 0.
    /// PR mode, the robot's `mode_machine`. Raises `ArgumentError` (nothing sent) for NaN,
    /// infinities, values out of a joint's range, a wrong length, an undriven slot set, or no
    /// LowState yet.
    #[pyo3(signature = (q, kp, kd, dq = None, tau = None))]
    fn set_joints(
        &self,
        q: &Bound<'_, PyAny>,
        kp: &Bound<'_, PyAny>,
        kd: &Bound<'_, PyAny>,
        dq: Option<&Bound<'_, PyAny>>,
        tau: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let c = client(&self.client)?;
        let variant = c.variant();
        let joints = JointArgs { q, kp, kd, dq, tau }
            .commands::<JOINTS>("slot order of JOINT_NAMES", |slot| variant.is_none_or(|v| v.drives(slot)))?;
        c.set_joints(&joints).map_err(raise)
    }

    /// Holds `q` (rad: one number or 29, slot order) with the gains of Unitree's G1 low-level
    /// example (`DEFAULT_KP`, `DEFAULT_KD`) on every joint the robot drives. Raises
    /// `ArgumentError` as `set_joints`.
    fn hold(&self, q: &Bound<'_, PyAny>) -> PyResult<()> {
        let q = per_joint::<JOINTS>("q", q, "slot order of JOINT_NAMES", &|_| true)?;
        client(&self.client)?.hold(&q).map_err(raise)
    }

    /// Damping (kp 0, a small kd, no targets) from the next tick on, until the next command;
    /// with the robot's `mode_machine` even before any command. Raises `ArgumentError` before
    /// the first LowState.
    fn damp(&self) -> PyResult<()> {
        client(&self.client)?.damp().map_err(raise)
    }

    /// The 29 joint positions of the latest state, rad (slot order). Raises `NoStateError`.
    fn joint_positions(&self) -> PyResult<Vec<f64>> {
        let q = client(&self.client)?.joint_positions().ok_or_else(|| error(Kind::NoState, "no LowState yet"))?;
        Ok(q.map(f64::from).to_vec())
    }

    /// Sets the `rt/arm_sdk` targets of the 17 arm and waist joints (`ARM_JOINT_SLOTS` order:
    /// left arm, right arm, then waist yaw, roll, pitch), each argument one number or 17 values
    /// (units and ranges as `set_joints`), keeping the target weight; refreshes the arm command
    /// (it is ramped out when not refreshed within 500 ms). The stream starts at weight 0 with
    /// the first call. Raises `ArgumentError` as `set_joints`.
    #[pyo3(signature = (q, kp, kd, dq = None, tau = None))]
    fn set_arm_joints(
        &self,
        q: &Bound<'_, PyAny>,
        kp: &Bound<'_, PyAny>,
        kd: &Bound<'_, PyAny>,
        dq: Option<&Bound<'_, PyAny>>,
        tau: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let c = client(&self.client)?;
        let variant = c.variant();
        let joints = JointArgs { q, kp, kd, dq, tau }.commands::<ARM_JOINTS>("order of ARM_JOINT_SLOTS", |i| {
            variant.is_none_or(|v| v.drives(ARM_SDK_JOINTS[i]))
        })?;
        c.set_arm_joints(&joints).map_err(raise)
    }

    /// Where the `rt/arm_sdk` weight goes, 0..=1 (0: the robot's controller alone, 1: the arm
    /// targets alone), moved there at 0.5 per second; refreshes the arm command. Raises
    /// `ArgumentError` outside 0..=1, for NaN, and before any `set_arm_joints`.
    fn set_arm_weight(&self, weight: f32) -> PyResult<()> {
        client(&self.client)?.set_arm_weight(weight).map_err(raise)
    }

    /// The weight of the last `rt/arm_sdk` frame sent, 0..=1.
    #[getter]
    fn arm_weight(&self) -> PyResult<f32> {
        Ok(client(&self.client)?.arm_weight())
    }

    /// The locomotion service (`sport`): `set_velocity`, `start`, `damp`, FSM ids, heights.
    #[getter]
    fn loco(&self) -> Loco {
        Loco { client: self.client.clone() }
    }

    /// The arm action service (`arm`): `execute_action`, `action_list`, `release_arm`.
    #[getter]
    fn arm(&self) -> ArmActions {
        ArmActions { client: self.client.clone() }
    }

    /// Both streams' counters and timing: the low-level keys of `robowire.go2.LowLevel.stats()`
    /// and `arm_sdk` (the topic), `arm_sdk_sent`, `arm_sdk_command_timeouts`,
    /// `arm_sdk_missed_ticks`, `arm_sdk_write_drops`, `arm_sdk_weight` (0..=1),
    /// `arm_sdk_send_lateness_us`.
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = client(&self.client)?.stats();
        let d = low_level_stats(py, &s.low_level)?;
        d.update(
            dict!(py, {
                "arm_sdk" => topic(py, &s.arm_sdk)?,
                "arm_sdk_sent" => s.arm_sdk_sent,
                "arm_sdk_command_timeouts" => s.arm_sdk_command_timeouts,
                "arm_sdk_missed_ticks" => s.arm_sdk_missed_ticks,
                "arm_sdk_write_drops" => s.arm_sdk_write_drops,
                "arm_sdk_weight" => s.arm_sdk_weight,
                "arm_sdk_send_lateness_us" => lateness(py, &s.arm_sdk_send_lateness)?,
            })
            .as_mapping(),
        )?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!("G1(open={})", self.client.is_open())
    }
}

closeable!(
    PyG1,
    client,
    capture,
    "Ramps the arm weight to 0 (at most 2 s), sends damping last, leaves the domain, then finishes its own capture. \
     Idempotent."
);

/// Adds the classes and constants to the extension module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("G1", py.get_type::<PyG1>())?;
    m.add("G1Loco", py.get_type::<Loco>())?;
    m.add("G1ArmActions", py.get_type::<ArmActions>())?;
    m.add("G1_JOINTS", JOINTS)?;
    m.add("G1_JOINT_NAMES", unitree::g1::JOINT_NAMES.to_vec())?;
    m.add("G1_DEFAULT_KP", unitree::g1::DEFAULT_GAINS.map(|g| g.kp).to_vec())?;
    m.add("G1_DEFAULT_KD", unitree::g1::DEFAULT_GAINS.map(|g| g.kd).to_vec())?;
    m.add("G1_ARM_JOINT_SLOTS", ARM_SDK_JOINTS.to_vec())?;
    m.add("G1_VX_MAX_MPS", unitree::g1::VX_MAX_MPS)?;
    m.add("G1_VY_MAX_MPS", unitree::g1::VY_MAX_MPS)?;
    m.add("G1_YAW_RATE_MAX_RADPS", unitree::g1::YAW_RATE_MAX_RADPS)?;
    Ok(())
}
