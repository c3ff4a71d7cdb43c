//! `robowire.sim.Go2`: a Unitree Go2 on DDS.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use robowire_dds::ParticipantOptions;
use robowire_sim::go2::{Go2Sim, Go2SimConfig};

use super::unitree::faults;
use crate::errors::{Kind, chain, error};
use crate::owned::{Owned, closeable};
use crate::record::{Capture, record_arg};
use crate::runtime::seconds;
use crate::stats::{dict, lateness, topic};

/// A simulated Unitree Go2 on DDS: `rt/lowstate` at 500 Hz, `rt/lowcmd` obeyed once the sport
/// mode is released, the motion_switcher and sport services. Unitree's own SDK and
/// `robowire.go2.LowLevel` both drive it. DDS discovery needs multicast: on a machine whose
/// loopback has none, call `robowire.sim.enter_loopback_namespace()` first (as root, or as the
/// root of a user namespace: `unshare --user --map-root-user python …`).
#[pyclass(module = "robowire.sim", frozen)]
pub(crate) struct Go2 {
    sim: Owned<Go2Sim>,
    domain: u16,
    capture: Capture,
}

#[pymethods]
impl Go2 {
    /// Joins DDS domain `domain` on `interface` (`None`: the library's choice) and boots lying
    /// down with its sport mode owning the motors. `record`: a path or a `robowire.Recorder`
    /// to record the robot's side of `go2/low_level` and `go2/api` into. `physics`: the body in
    /// MuJoCo (a wheel built with the `mujoco` feature), lying on its floor; `model`: a user's
    /// MJCF instead of robowire's model of the Go2.
    #[new]
    #[pyo3(signature = (*, domain = 0, interface = None, state_period_s = 0.002, record = None, physics = false, model = None))]
    fn new(
        py: Python<'_>,
        domain: u16,
        interface: Option<&str>,
        state_period_s: f64,
        record: Option<&Bound<'_, PyAny>>,
        physics: bool,
        model: Option<std::path::PathBuf>,
    ) -> PyResult<Self> {
        #[cfg_attr(not(feature = "mujoco"), allow(unused_variables))]
        let physics = super::unitree::physics_arg(physics, model, false)?;
        let state_period = seconds("state_period_s", state_period_s)?;
        if state_period.as_micros() < 100 {
            return Err(error(Kind::Argument, "state_period_s must be at least 0.0001"));
        }
        let (links, capture) = record_arg(record, "robowire.sim.Go2")?;
        let config = Go2SimConfig {
            participant: ParticipantOptions::new(domain, interface),
            state_period,
            low_level_tap: links.as_ref().map(|r| r.link("go2/low_level", &unitree_proto::description::GO2_LOW_LEVEL)),
            services_tap: links.as_ref().map(|r| r.link("go2/api", &unitree_proto::description::API_SERVER)),
            #[cfg(feature = "mujoco")]
            physics,
            ..Go2SimConfig::default()
        };
        let sim = py.detach(|| Go2Sim::spawn(config)).map_err(|e| error(Kind::Error, chain(&e)))?;
        Ok(Self { sim: Owned::new("Go2 simulator", sim), domain, capture })
    }

    /// The DDS domain.
    #[getter]
    fn domain(&self) -> u16 {
        self.domain
    }

    /// Sport mode, joint positions, LowCmd and LowState counters, timing, the body (`base`: the
    /// base's `position_m`, `velocity_mps`, `rpy_rad` with physics, else `None`; `sim_time_s`,
    /// `wall_time_s`).
    fn snapshot<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.sim.with(|s| s.snapshot())?;
        let c = &s.lowcmd;
        Ok(dict!(py, {
            "sport_mode" => s.sport_mode,
            "joints_rad" => s.joints_rad.to_vec(),
            "lowcmd" => dict!(py, {
                "accepted" => c.accepted,
                "ignored_sport_mode" => c.ignored_sport_mode,
                "bad_head" => c.bad_head,
                "bad_crc" => c.bad_crc,
                "malformed" => c.malformed,
            }),
            "lowstate" => topic(py, &s.lowstate)?,
            "corrupted_states" => s.corrupted_states,
            "requests" => s.requests,
            "state_lateness_us" => lateness(py, &s.state_lateness)?,
            "command_jitter_us" => lateness(py, &s.command_jitter)?,
            "body" => super::unitree::body(py, s.base, s.sim_time_s, s.wall_time_s)?,
        }))
    }

    fn __repr__(&self) -> String {
        format!("Go2(domain={})", self.domain)
    }
}

faults!(Go2, robowire_sim::go2::Go2Fault, robowire_sim::go2::JOINTS, "the Go2 has motors 0..12");

closeable!(Go2, sim, capture, "Leaves the domain and stops the robot, then finishes its own capture. Idempotent.");

/// Whether loopback carries multicast here (DDS discovery on one machine needs it).
#[pyfunction]
pub(crate) fn loopback_has_multicast() -> bool {
    robowire_dds::netns::loopback_has_multicast()
}

/// Moves this thread (and every thread and process it starts later) into a private network
/// namespace whose loopback carries multicast, so DDS participants on this machine find each
/// other and nothing leaves it. Call it before anything starts robowire's threads. Needs root, or
/// the root of a user namespace (`unshare --user --map-root-user`, which a normal user may run),
/// and iproute2.
#[pyfunction]
pub(crate) fn enter_loopback_namespace() -> PyResult<()> {
    robowire_dds::netns::enter_loopback_namespace().map_err(|e| error(Kind::Error, chain(&e)))
}
