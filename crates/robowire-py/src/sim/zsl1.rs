//! `robowire.sim.Zsl1` (`robowire.sim.Dog`, its old name, kept one release): the ZSL-1 / ZSL-1W
//! on its two UDP ports.

use std::net::{IpAddr, SocketAddr};

use pyo3::prelude::*;
use pyo3::types::PyDict;
use robowire_sim::zsl1::{Activity, PortStats, Zsl1Fault, Zsl1Sim, Zsl1SimConfig};
use zsl_proto::udp::{Model, ReturnCode};

use crate::errors::{Kind, error};
use crate::owned::{Owned, closeable};
use crate::record::{Capture, record_arg};
use crate::runtime::seconds;
use crate::stats::{dict, lateness};

/// A simulated ZSL-1 (or ZSL-1W) on UDP: HighLevel commands on `high_level_addr`, LowLevel on
/// `low_level_addr`, state to whoever commands it, every `state_period_s`. It starts lying
/// down. The vendor's ports (43997, 43900) are the default, so that `initRobot(..., ip)`
/// finds it; pick another `ip` in 127.0.0.0/8 to run several side by side.
///
/// ```python
/// with robowire.sim.Zsl1(ip="127.0.0.2") as sim:
///     robot = robowire.zsl1.HighLevel()
///     robot.initRobot("127.0.0.1", 43988, sim.ip)
/// ```
#[pyclass(module = "robowire.sim", frozen)]
pub(crate) struct Zsl1 {
    sim: Owned<Zsl1Sim>,
    ip: String,
    high_level: SocketAddr,
    low_level: SocketAddr,
    capture: Capture,
}

fn model(name: &str) -> PyResult<Model> {
    match name {
        "zsl1" => Ok(Model::Zsl1),
        "zsl1w" => Ok(Model::Zsl1W),
        other => Err(error(Kind::Argument, format!("model = {other:?}: \"zsl1\" or \"zsl1w\""))),
    }
}

fn addr(a: SocketAddr) -> (String, u16) {
    (a.ip().to_string(), a.port())
}

fn activity(a: Activity) -> String {
    match a {
        Activity::Lying => "lying".into(),
        Activity::Passive => "passive".into(),
        Activity::StandingUp => "standing_up".into(),
        Activity::Standing => "standing".into(),
        Activity::Walking => "walking".into(),
        Activity::LyingDown => "lying_down".into(),
        Activity::Trick(action) => format!("trick:{}", format!("{action:?}").to_lowercase()),
        Activity::TwoLegStand => "two_leg_stand".into(),
        Activity::Attitude => "attitude".into(),
        Activity::LowLevel => "low_level".into(),
    }
}

fn port<'py>(py: Python<'py>, p: &PortStats) -> PyResult<Bound<'py, PyDict>> {
    Ok(dict!(py, {
        "commands" => p.commands,
        "invalid" => p.invalid,
        "states_sent" => p.states_sent,
        "garbage_sent" => p.garbage_sent,
        "client" => p.client.map(addr),
        "command_jitter_us" => lateness(py, &p.command_jitter)?,
    }))
}

#[pymethods]
impl Zsl1 {
    /// Binds both ports on `ip` and starts the robot lying down. `model` `"zsl1"` or `"zsl1w"`;
    /// port 0 picks a free one. Raises `BindError` if a port is taken. `record`: a path or a
    /// `robowire.Recorder` to record both ports' datagrams into (`zsl1/high_level`,
    /// `zsl1/low_level`).
    #[new]
    #[pyo3(signature = (model = "zsl1", *, ip = "127.0.0.1", high_level_port = 43997, low_level_port = 43900, state_period_s = 0.002, record = None))]
    fn new(
        py: Python<'_>,
        model: &str,
        ip: &str,
        high_level_port: u16,
        low_level_port: u16,
        state_period_s: f64,
        record: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let bind: IpAddr =
            ip.parse().map_err(|_| error(Kind::Argument, format!("ip = {ip:?} is not an IP address")))?;
        let state_period = seconds("state_period_s", state_period_s)?;
        if state_period.is_zero() {
            return Err(error(Kind::Argument, "state_period_s must be above 0"));
        }
        let model = self::model(model)?;
        let (links, capture) = record_arg(record, "robowire.sim.Zsl1")?;
        let config = Zsl1SimConfig {
            bind,
            high_level_port,
            low_level_port,
            model,
            state_period,
            high_level_tap: links.as_ref().map(|r| r.link("zsl1/high_level", &zsl_proto::description::HIGH_LEVEL)),
            low_level_tap: links.as_ref().map(|r| r.link("zsl1/low_level", &zsl_proto::description::LOW_LEVEL)),
            ..Zsl1SimConfig::default()
        };
        let sim = py.detach(|| Zsl1Sim::spawn(config)).map_err(|e| error(Kind::Bind, e))?;
        let (high_level, low_level) = (sim.high_level_addr(), sim.low_level_addr());
        Ok(Self { sim: Owned::new("ZSL-1 simulator", sim), ip: bind.to_string(), high_level, low_level, capture })
    }

    /// The IP both ports are bound on (the `dog_ip` of `initRobot`).
    #[getter]
    fn ip(&self) -> &str {
        &self.ip
    }

    /// `(ip, port)` of the HighLevel port.
    #[getter]
    fn high_level_addr(&self) -> (String, u16) {
        addr(self.high_level)
    }

    /// `(ip, port)` of the LowLevel port.
    #[getter]
    fn low_level_addr(&self) -> (String, u16) {
        addr(self.low_level)
    }

    /// Report `code` as the robot's error word (0x3009 angle limit, 0x3010 motor disabled,
    /// 0x3011 motor fault, 0x3012 motor data lost): every HighLevel call returns it.
    fn inject_error_word(&self, code: u32) -> PyResult<()> {
        if code == 0 {
            return Err(error(Kind::Argument, "error word 0 is no fault; use clear_faults()"));
        }
        self.sim.with(|s| s.inject(Zsl1Fault::ErrorWord(ReturnCode::from_raw(code))))
    }

    /// Raise the "SDK mismatch" flag: a HighLevel client stops streaming for good.
    fn inject_sdk_mismatch(&self) -> PyResult<()> {
        self.sim.with(|s| s.inject(Zsl1Fault::SdkMismatch))
    }

    /// Send no state at all (the client's watchdog reports the robot lost after 3 s).
    fn inject_silence(&self) -> PyResult<()> {
        self.sim.with(|s| s.inject(Zsl1Fault::Silence))
    }

    /// Send 600-byte junk datagrams instead of state.
    fn inject_garbage(&self) -> PyResult<()> {
        self.sim.with(|s| s.inject(Zsl1Fault::Garbage))
    }

    /// Clear every fault.
    fn clear_faults(&self) -> PyResult<()> {
        self.sim.with(|s| s.clear_faults())
    }

    /// Set the battery level, % (0–100).
    fn set_battery_percent(&self, percent: f32) -> PyResult<()> {
        if !(0.0..=100.0).contains(&percent) {
            return Err(error(Kind::Argument, format!("battery {percent} % is outside 0..=100")));
        }
        self.sim.with(|s| s.set_battery_percent(percent))
    }

    /// The robot and its ports now: mode, activity, pose, battery, faults, counters.
    fn snapshot<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.sim.with(|s| s.snapshot())?;
        let robot = &s.robot;
        let faults = robot.faults();
        Ok(dict!(py, {
            "model" => if robot.model() == Model::Zsl1 { "zsl1" } else { "zsl1w" },
            "mode" => robot.mode().raw(),
            "activity" => activity(robot.activity()),
            "position_m" => robot.position_m().to_vec(),
            "yaw_rad" => robot.yaw_rad(),
            "velocity_mps" => robot.velocity_mps().to_vec(),
            "yaw_rate_radps" => robot.yaw_rate_radps(),
            "distance_m" => robot.distance_m(),
            "tricks_done" => robot.tricks_done(),
            "battery_percent" => robot.battery_percent(),
            "faults" => dict!(py, {
                "error_word" => faults.error_word.map(ReturnCode::raw),
                "sdk_mismatch" => faults.sdk_mismatch,
                "silence" => faults.silence,
                "garbage" => faults.garbage,
            }),
            "high_level" => port(py, &s.high_level)?,
            "low_level" => port(py, &s.low_level)?,
            "cycles" => s.cycles,
            "missed_cycles" => s.missed_cycles,
            "state_lateness_us" => lateness(py, &s.state_lateness)?,
        }))
    }

    fn __repr__(&self) -> String {
        let state = if self.sim.is_open() { "running" } else { "closed" };
        format!("Zsl1(ip={:?}, high_level={}, low_level={}, {state})", self.ip, self.high_level, self.low_level)
    }
}

closeable!(Zsl1, sim, capture, "Stops the simulator and frees its ports, then finishes its own capture. Idempotent.");
