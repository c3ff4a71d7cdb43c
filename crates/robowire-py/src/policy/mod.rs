//! `robowire.policy`: a trained locomotion policy (ONNX, with unitree_rl_gym's deploy config) on
//! a G1 or a Go2 by address, or on their physics simulators, through `robowire_policy` as
//! `robowire policy run` drives it: the same checks, sequence and safety.

mod config;

use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use robowire_devices::policy::{DeviceRun, check, policy_link, start_on};
use robowire_devices::{AnyDevice, DeviceAddress, OpenOptions};
use robowire_policy::{CommandSlot, Ended, ModelError, OnnxPolicy, PolicyConfig, RunOptions, StartError};

use crate::errors::{Kind, chain, error, service_error};
use crate::owned::Owned;
use crate::record::{Capture, record_arg};
use crate::runtime::{self, timeout};
use crate::stats::dict;
use config::PyPolicyConfig;

/// A `ModelError` as an exception: `ArgumentError` where the model disagrees with the config.
fn model_error(e: &ModelError) -> PyErr {
    match e {
        ModelError::Shape { .. } | ModelError::Observation { .. } => error(Kind::Argument, chain(e)),
        _ => error(Kind::Error, chain(e)),
    }
}

/// A `StartError` as an exception.
fn start_error(e: &StartError) -> PyErr {
    match e {
        StartError::MsgType { .. } | StartError::NoBody(_) => error(Kind::Argument, chain(e)),
        StartError::NoState => error(Kind::NoState, chain(e)),
        StartError::Release(_) => service_error(chain(e), "motion_switcher", 0, -1),
        _ => error(Kind::Error, chain(e)),
    }
}

/// `(vx, vy, wz)`, each finite, else `ArgumentError`.
fn command(name: &str, [vx, vy, wz]: [f32; 3]) -> PyResult<[f32; 3]> {
    if [vx, vy, wz].iter().all(|v| v.is_finite()) {
        Ok([vx, vy, wz])
    } else {
        Err(error(Kind::Argument, format!("{name} = ({vx}, {vy}, {wz}): every value must be finite")))
    }
}

/// A policy running on a robot, started by `robowire.policy.run`.
///
/// ```python
/// with robowire.policy.run("g1_walk.yaml", "sim:g1", physics=True, cmd=(0.5, 0, 0)) as walk:
///     print(walk.wait(timeout_s=20.0), walk.last_step["step"])
/// ```
#[pyclass(name = "Run", module = "robowire.policy", frozen)]
pub(crate) struct PyRun {
    run: Owned<Arc<DeviceRun>>,
    device: Owned<Arc<AnyDevice>>,
    command: Arc<CommandSlot>,
    address: String,
    /// How it ended, once seen.
    ended: Mutex<Option<Ended>>,
    capture: Capture,
}

impl PyRun {
    fn run(&self) -> PyResult<Arc<DeviceRun>> {
        self.run.with(|r| r.clone())
    }

    /// Waits up to `timeout` (`None`: until it ends) for the end; its name, `None` if still
    /// running. The end is kept for `reason` and for calls after `close()`.
    fn wait_end(&self, py: Python<'_>, timeout: Option<std::time::Duration>) -> PyResult<Option<&'static str>> {
        if let Some(ended) = &*robowire_rt::lock(&self.ended) {
            return Ok(Some(ended.name()));
        }
        let run = self.run()?;
        let Some(ended) = runtime::wait(py, timeout, async move { run.ended().await })? else { return Ok(None) };
        let name = ended.name();
        *robowire_rt::lock(&self.ended) = Some(ended);
        Ok(Some(name))
    }
}

#[pymethods]
impl PyRun {
    /// The device's address.
    #[getter]
    fn address(&self) -> &str {
        &self.address
    }

    /// The velocity asked: (vx m/s, vy m/s, wz rad/s), before clamping to `max_cmd`.
    #[getter]
    fn command(&self) -> (f32, f32, f32) {
        let [vx, vy, wz] = self.command.get();
        (vx, vy, wz)
    }

    /// Asks (`vx` m/s, `vy` m/s, `wz` rad/s) from the next policy step on, clamped to the config's
    /// `max_cmd` there. A value that is not finite raises `ArgumentError` (nothing changes).
    fn set_command(&self, vx: f32, vy: f32, wz: f32) -> PyResult<()> {
        self.run()?;
        self.command.set(command("set_command", [vx, vy, wz])?);
        Ok(())
    }

    /// `"standing"` (moving to the default pose), `"holding"` (holding it), `"walking"` (the policy
    /// runs) or `"damped"` (ended, or closed).
    #[getter]
    fn phase(&self) -> &'static str {
        self.run().map_or("damped", |r| r.phase().name())
    }

    /// The last policy step as a dict (`step` from 1, `obs`, `actions`, `command` after clamping,
    /// `inference_s`, `clamped`: targets clamped into their joint's range so far); `None` before
    /// the first. `ClosedError` after `close()`.
    #[getter]
    fn last_step<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let step = self.run()?.last_step();
        if step.step == 0 {
            return Ok(None);
        }
        Ok(Some(dict!(py, {
            "step" => step.step,
            "obs" => step.obs,
            "actions" => step.action,
            "command" => step.command.to_vec(),
            "inference_s" => step.inference.as_secs_f64(),
            "clamped" => step.clamped,
        })))
    }

    /// Waits up to `timeout_s` (`None`: until it ends) with the GIL released, Ctrl-C
    /// interrupting; how it ended: `"duration"` (`duration_s` ran out), `"stopped"`, `"fault"`
    /// (a stale state, a tilt, an action that is not finite) or `"refused"` (the robot's rules
    /// refused a target), the robot damped in every case; `None` if it still runs.
    #[pyo3(signature = (timeout_s = None))]
    fn wait(&self, py: Python<'_>, timeout_s: Option<f64>) -> PyResult<Option<&'static str>> {
        let timeout = timeout("timeout_s", timeout_s)?;
        self.wait_end(py, timeout)
    }

    /// Why it ended, one line (`"the duration ran out"`, `"tilted 1.10 rad in roll, …"`); `None`
    /// while it runs.
    #[getter]
    fn reason(&self, py: Python<'_>) -> PyResult<Option<String>> {
        self.wait_end(py, Some(std::time::Duration::ZERO))?;
        Ok(robowire_rt::lock(&self.ended).as_ref().map(Ended::to_string))
    }

    /// Damps the robot at the next policy tick and waits for it; how the run ended (`"stopped"`,
    /// or its earlier end). The device stays open (damped) until `close()`.
    fn stop(&self, py: Python<'_>) -> PyResult<&'static str> {
        self.run()?.stop();
        self.wait_end(py, None)?.ok_or_else(|| error(Kind::Error, "the run did not end"))
    }

    /// Stops the run (damping), closes the device (its own safe action, then its simulator), then
    /// finishes the capture of `record=PATH`. Idempotent.
    fn close(&self, py: Python<'_>) -> PyResult<()> {
        let stopped = match self.run.is_open() {
            true => self.stop(py).map(drop),
            false => Ok(()),
        };
        // The run's thread joins, and lets the device go.
        let run = self.run.take();
        py.detach(move || drop(run));
        let closed = crate::device::close(py, &self.device);
        let finished = self.capture.finish(py);
        stopped.and(closed).and(finished)
    }

    fn __enter__(slf: Py<Self>) -> Py<Self> {
        slf
    }

    #[pyo3(signature = (*_exc))]
    fn __exit__(&self, py: Python<'_>, _exc: &Bound<'_, PyTuple>) -> PyResult<()> {
        self.close(py)
    }

    fn __repr__(&self) -> String {
        format!("Run({:?}, {})", self.address, self.phase())
    }
}

/// Starts the policy of `config` (a path or a `PolicyConfig`) on the robot at `device`
/// (`g1:IFACE`, `go2:IFACE`, or `sim:g1`/`sim:go2` with `physics=True`, started here, its base
/// free on the floor), as `robowire policy run` does: waits for its state, releases its
/// controller, moves to the default pose in 2 s, holds it 1 s, then runs the policy every
/// `control_dt` until `duration_s` (`None`: until stopped) or a fault. Refusals (a kinematic
/// simulator, a robot of the other family, a config or model that disagree) raise
/// `ArgumentError` before anything is sent; no state within 3 s raises `NoStateError`.
/// `record`: a path or a `robowire.Recorder`, for the device's links and the policy's steps
/// (`g1/policy`, `go2/policy`); `domain` and `model` as for `robowire.open`.
#[pyfunction]
#[pyo3(name = "run_policy", signature = (config, device, *, cmd = (0.0, 0.0, 0.0), duration_s = None, stand = true, record = None, domain = 0, physics = false, model = None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn run(
    py: Python<'_>,
    config: &Bound<'_, PyAny>,
    device: &str,
    cmd: (f32, f32, f32),
    duration_s: Option<f64>,
    stand: bool,
    record: Option<&Bound<'_, PyAny>>,
    domain: u16,
    physics: bool,
    model: Option<PathBuf>,
) -> PyResult<PyRun> {
    let config = match config.cast::<PyPolicyConfig>() {
        Ok(config) => config.get().config.clone(),
        Err(_) => PyPolicyConfig::read(py, config.extract()?)?.config,
    };
    let address: DeviceAddress =
        device.parse().map_err(|e: robowire_devices::AddressError| error(Kind::Argument, e))?;
    check(&config, &address, physics).map_err(|e| error(Kind::Argument, e))?;
    let asked = command("cmd", [cmd.0, cmd.1, cmd.2])?;
    let duration = timeout("duration_s", duration_s)?;
    let policy = py
        .detach(|| OnnxPolicy::load(&config.policy_path, config.num_obs, config.num_actions))
        .map_err(|e| model_error(&e))?;
    // A policy walks a simulated robot on the floor.
    let sim_physics = crate::device::sim_physics(physics, model, physics)?;
    let (links, capture) = record_arg(record, &format!("robowire.policy.run({device:?})"))?;
    let open = OpenOptions { domain, record: links, sim_physics, ..OpenOptions::default() };
    let slot = CommandSlot::new(asked);
    let options = RunOptions { command: slot.clone(), duration, stand, ..RunOptions::default() };
    let (opened, run) = match open_and_start(py, &address, &open, config, policy, options) {
        Ok(started) => started,
        // The capture holds what the device said before it closed.
        Err(e) => return capture.finish(py).and(Err(e)),
    };
    Ok(PyRun {
        run: Owned::new("policy run", Arc::new(run)),
        device: Owned::new("device", opened),
        command: slot,
        address: address.to_string(),
        ended: Mutex::new(None),
        capture,
    })
}

/// Opens the device at `address` and starts the policy on it, its steps recorded beside the
/// device's links (`open.record`). On an error the device is closed again (its safe action, its
/// simulator stopped).
fn open_and_start(
    py: Python<'_>,
    address: &DeviceAddress,
    open: &OpenOptions,
    config: PolicyConfig,
    policy: OnnxPolicy,
    mut options: RunOptions,
) -> PyResult<(Arc<AnyDevice>, DeviceRun)> {
    let opened = Arc::new(py.detach(|| robowire_devices::open(address, open)).map_err(crate::device::raise)?);
    options.tap = open.record.as_ref().map(|links| policy_link(&opened, links));
    let holder = opened.clone();
    match runtime::wait(py, None, async move { start_on(holder, &config, policy, options).await }) {
        Ok(Some(Ok(run))) => Ok((opened, run)),
        failed => {
            py.detach(move || drop(opened));
            Err(match failed {
                Ok(Some(Err(e))) => start_error(&e),
                Err(interrupted) => interrupted,
                _ => error(Kind::Error, "the start did not end"),
            })
        }
    }
}

/// Adds the classes and the function to the extension module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyPolicyConfig>()?;
    m.add_class::<PyRun>()?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    Ok(())
}
