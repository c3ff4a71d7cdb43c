//! `robowire.sim.Spline`: the ZSL-1 spline daemon on POSIX shared memory.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use robowire_sim::spline::{SplineSim, SplineSimConfig};
use zsl_proto::shm::{JointIndex, Leg, SplineStateBlock};

use crate::errors::{Kind, error};
use crate::owned::{Owned, closeable};
use crate::record::{Capture, record_arg};
use crate::runtime::seconds;
use crate::stats::{dict, lateness};

/// The spline daemon of a ZSL-1 on POSIX shared memory: a 1 kHz loop that consumes joint
/// commands from `spline_name` like the vendor's daemon, drives a PD joint model, and publishes
/// motor state there and an IMU sample on `imu_name`. By default the objects get private names
/// (`/robowire-py-<pid>-spline`, …) so that nothing touches a robot's `/spline_shm`.
#[pyclass(module = "robowire.sim", frozen)]
pub(crate) struct Spline {
    sim: Owned<SplineSim>,
    spline_name: String,
    imu_name: String,
    capture: Capture,
}

/// `[leg][joint]` (legs FR, FL, RR, RL; joints abad, hip, knee, foot) of one quantity.
pub(crate) fn per_joint(state: &SplineStateBlock, f: impl Fn(&zsl_proto::shm::JointState) -> f32) -> Vec<Vec<f32>> {
    Leg::ALL.iter().map(|&leg| JointIndex::ALL.iter().map(|&j| f(state.joint(leg, j))).collect()).collect()
}

/// The state block as a dict: `p_rad`, `v_radps`, `t_nm`, `flags`, each `[leg][joint]`.
pub(crate) fn state_dict<'py>(py: Python<'py>, state: &SplineStateBlock) -> PyResult<Bound<'py, PyDict>> {
    let flags: Vec<Vec<u32>> = Leg::ALL
        .iter()
        .map(|&leg| JointIndex::ALL.iter().map(|&j| state.joint(leg, j).flags.get()).collect())
        .collect();
    Ok(dict!(py, {
        "p_rad" => per_joint(state, |j| j.p.get()),
        "v_radps" => per_joint(state, |j| j.v.get()),
        "t_nm" => per_joint(state, |j| j.t.get()),
        "flags" => flags,
    }))
}

#[pymethods]
impl Spline {
    /// Creates both objects and starts the loop (`period_s`, default 1 ms). `record`: a path or
    /// a `robowire.Recorder` to record the daemon's side of `spline/spline` and the IMU records
    /// it publishes (`spline/imu`) into.
    #[new]
    #[pyo3(signature = (*, spline_name = None, imu_name = None, period_s = 0.001, record = None))]
    fn new(
        py: Python<'_>,
        spline_name: Option<String>,
        imu_name: Option<String>,
        period_s: f64,
        record: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let private = SplineSimConfig::private("py");
        let period = seconds("period_s", period_s)?;
        if period.is_zero() {
            return Err(error(Kind::Argument, "period_s must be above 0"));
        }
        let (links, capture) = record_arg(record, "robowire.sim.Spline")?;
        let config = SplineSimConfig {
            spline_name: spline_name.unwrap_or(private.spline_name),
            imu_name: imu_name.unwrap_or(private.imu_name),
            period,
            tap: links.as_ref().map(|r| r.link(robowire_devices::SPLINE_LINK, &zsl_proto::description::SPLINE_DAEMON)),
            imu_tap: links.as_ref().map(|r| r.link(robowire_devices::SPLINE_IMU_LINK, &zsl_proto::description::IMU)),
            ..SplineSimConfig::default()
        };
        let (spline_name, imu_name) = (config.spline_name.clone(), config.imu_name.clone());
        let sim = py.detach(|| SplineSim::spawn(config)).map_err(|e| error(Kind::Error, crate::errors::chain(&e)))?;
        Ok(Self { sim: Owned::new("spline simulator", sim), spline_name, imu_name, capture })
    }

    /// Name of the spline object (open it with `robowire.spline.SplineClient`).
    #[getter]
    fn spline_name(&self) -> &str {
        &self.spline_name
    }

    /// Name of the IMU object.
    #[getter]
    fn imu_name(&self) -> &str {
        &self.imu_name
    }

    /// Hang the daemon (no commands consumed, nothing published) while `paused`.
    #[pyo3(signature = (paused = true))]
    fn pause(&self, paused: bool) -> PyResult<()> {
        self.sim.with(|s| s.pause(paused))
    }

    /// Report fault bits (0x02…0x20) on joint `joint` (0 abad … 3 foot) of leg `leg` (0 FR …
    /// 3 RL); 0 clears.
    fn inject_fault(&self, leg: usize, joint: usize, bits: u32) -> PyResult<()> {
        let (Some(&leg), Some(&joint)) = (Leg::ALL.get(leg), JointIndex::ALL.get(joint)) else {
            return Err(error(Kind::Argument, format!("leg {leg} / joint {joint}: both must be 0..=3")));
        };
        self.sim.with(|s| s.inject_fault(leg, joint, bits))
    }

    /// The state published last.
    fn state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let state = self.sim.with(|s| s.state())?;
        state_dict(py, &state)
    }

    /// Cycles, lateness, the daemon's command bookkeeping.
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.sim.with(|s| s.stats())?;
        let d = &s.daemon;
        Ok(dict!(py, {
            "cycles" => s.cycles,
            "missed_cycles" => s.missed_cycles,
            "lateness_us" => lateness(py, &s.lateness)?,
            "imu_samples" => s.imu_samples,
            "fresh_commands" => d.fresh,
            "repeated_commands" => d.repeated,
            "cleared_commands" => d.cleared,
            "clears" => d.clears,
            "rejected_commands" => d.rejected,
            "states_published" => d.states_published,
        }))
    }

    fn __repr__(&self) -> String {
        format!("Spline(spline_name={:?}, imu_name={:?})", self.spline_name, self.imu_name)
    }
}

closeable!(
    Spline,
    sim,
    capture,
    "Stops the daemon and removes its objects, then finishes its own capture. Idempotent."
);
