//! `robowire.sim.Chassis`: the KMC chassis on a pseudo-terminal.

use std::path::PathBuf;
use std::time::Duration;

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use robowire_sim::kmc::{ChassisSim, ChassisSimConfig, Fault};

use crate::errors::{Kind, error};
use crate::owned::{Owned, closeable};
use crate::pyjson;
use crate::record::{Capture, record_arg};
use crate::runtime::seconds;
use crate::stats::dict;

/// A simulated KMC chassis behind a pseudo-terminal: open `path` with `robowire.kmc.Driver` (or
/// any serial client) as if it were `/dev/ttyUSB0`. It answers 0xB3 and 0xAF reads, models the
/// speed (first order), odometry, heading and battery, and stops the wheels when commands stop
/// for `command_watchdog_s`.
///
/// ```python
/// with robowire.sim.Chassis() as chassis, robowire.kmc.Driver(chassis.path) as driver:
///     driver.set_command(0.5, 0.0)
/// ```
#[pyclass(module = "robowire.sim", frozen)]
pub(crate) struct Chassis {
    sim: Owned<ChassisSim>,
    capture: Capture,
}

fn text(path: PathBuf) -> String {
    path.to_string_lossy().into_owned()
}

#[pymethods]
impl Chassis {
    /// Opens a pty and starts the chassis at rest. `link`: a symlink kept pointing at the
    /// current pty (across `replug()`); `command_watchdog_s=None` disables the chassis's own
    /// watchdog. `record`: a path or a `robowire.Recorder` to record the chassis's side of the
    /// line into (`kmc/serial`, and `kmc/serial_skipped`: the bytes it skipped).
    #[new]
    #[pyo3(signature = (*, speed_time_constant_s = 0.2, battery_initial_volts = 25.2, battery_drain_volts_per_s = 0.0005, command_watchdog_s = Some(1.0), link = None, seed = 0x5eed_cafe, record = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        speed_time_constant_s: f64,
        battery_initial_volts: f32,
        battery_drain_volts_per_s: f32,
        command_watchdog_s: Option<f64>,
        link: Option<PathBuf>,
        seed: u64,
        record: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        for (name, v) in
            [("battery_initial_volts", battery_initial_volts), ("battery_drain_volts_per_s", battery_drain_volts_per_s)]
        {
            if !(v.is_finite() && v >= 0.0) {
                return Err(error(Kind::Argument, format!("{name} = {v} must be finite and not negative")));
            }
        }
        let (links, capture) = record_arg(record, "robowire.sim.Chassis")?;
        let config = ChassisSimConfig {
            speed_time_constant: seconds("speed_time_constant_s", speed_time_constant_s)?,
            battery_initial_volts,
            battery_drain_volts_per_s,
            command_watchdog: command_watchdog_s.map(|s| seconds("command_watchdog_s", s)).transpose()?,
            link,
            seed,
            taps: links.map(|r| robowire_devices::kmc_taps(&r, &kmc_proto::description::CHASSIS)).unwrap_or_default(),
        };
        if config.speed_time_constant.is_zero() || config.command_watchdog.is_some_and(|w| w < Duration::from_millis(1))
        {
            return Err(error(Kind::Argument, "speed_time_constant_s and command_watchdog_s must be at least 1 ms"));
        }
        let sim = py
            .detach(|| ChassisSim::spawn(config))
            .map_err(|e| error(Kind::Port, format!("chassis simulator: {e}")))?;
        Ok(Self { sim: Owned::new("chassis simulator", sim), capture })
    }

    /// The path to open: the symlink if one was asked for, else the pty.
    #[getter]
    fn path(&self) -> PyResult<String> {
        self.sim.with(|s| text(s.path()))
    }

    /// The current pty's device path.
    #[getter]
    fn pty_path(&self) -> PyResult<String> {
        self.sim.with(|s| text(s.pty_path()))
    }

    /// Send `count` random non-frame bytes before the next response.
    fn inject_garbage(&self, count: usize) -> PyResult<()> {
        self.sim.with(|s| s.inject(Fault::Garbage { bytes: count }))
    }

    /// Swallow the next `count` responses.
    fn drop_responses(&self, count: u32) -> PyResult<()> {
        self.sim.with(|s| s.inject(Fault::DropResponses { count }))
    }

    /// Hang the line up, like an unplugged adapter: the client's reads fail.
    fn hang_up(&self) -> PyResult<()> {
        self.sim.with(|s| s.inject(Fault::HangUp))
    }

    /// After `hang_up()`: plug a new pty in (the symlink follows); returns its path.
    fn replug(&self) -> PyResult<String> {
        self.sim.with(|s| s.replug())?.map(text).map_err(|e| error(Kind::Port, format!("replug: {e}")))
    }

    /// The modelled chassis: commanded and actual speed, odometer, heading, battery.
    fn state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.sim.with(|s| s.state())?;
        Ok(dict!(py, {
            "commanded_velocity_mps" => s.commanded_velocity_mps,
            "commanded_curvature_per_m" => s.commanded_curvature_per_m,
            "speed_mps" => s.speed_mps,
            "odometer_m" => s.odometer_m,
            "heading_rad" => s.heading_rad,
            "battery_volts" => s.battery_volts,
            "speed_erpm" => s.speed_erpm.to_vec(),
            "servo_pulse_us" => s.servo_pulse_us.to_vec(),
        }))
    }

    /// What the chassis received and sent.
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.sim.with(|s| s.stats())?;
        Ok(dict!(py, {
            "control_frames" => s.control_frames,
            "speed_requests" => s.speed_requests,
            "af_reads" => s.af_reads,
            "af_writes" => s.af_writes,
            "resets" => s.resets,
            "responses_sent" => s.responses_sent,
            "responses_dropped" => s.responses_dropped,
            "unanswered_reads" => s.unanswered_reads,
            "garbage_bytes_sent" => s.garbage_bytes_sent,
            "watchdog_stops" => s.watchdog_stops,
            "hang_ups" => s.hang_ups,
        }))
    }

    /// The frames received (the last 16384), oldest first, as `robowire decode kmc --json`
    /// prints them: `{"frame": "pc_control", "velocity_mps": 0.5, "curvature_per_m": 0.4}`.
    fn received<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let frames = self.sim.with(|s| s.received())?;
        let list = PyList::empty(py);
        for r in frames {
            list.append(pyjson::to_py(py, &r.frame)?)?;
        }
        Ok(list)
    }
}

closeable!(
    Chassis,
    sim,
    capture,
    "Stops the simulator; the pty (and its symlink) go away; then finishes its own capture. Idempotent."
);
