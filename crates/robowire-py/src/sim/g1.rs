//! `robowire.sim.G1`: a Unitree G1 humanoid on DDS.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use robowire_dds::ParticipantOptions;
use robowire_sim::g1::{G1Sim, G1SimConfig};
use unitree_proto::g1::G1Variant;

use super::unitree::faults;
use crate::errors::{Kind, chain, error};
use crate::g1::variant::{variant_name, variant_of_dof};
use crate::owned::{Owned, closeable};
use crate::record::{Capture, record_arg};
use crate::runtime::seconds;
use crate::stats::{dict, lateness, topic};

/// A simulated Unitree G1 on DDS: `rt/lowstate` at 500 Hz with its `mode_machine`, `rt/lowcmd`
/// obeyed once the controller is released (and only with the robot's `mode_machine`, per motor
/// with `mode` 1), `rt/arm_sdk` blended into the controller by its weight while the controller
/// owns the motors, the motion_switcher, loco (`sport`) and arm services. Boots standing, the
/// mode `"ai"` owning the motors, loco FSM 500. Unitree's own SDK and `robowire.g1.G1` both
/// drive it. DDS discovery needs multicast: on a machine whose loopback has none, call
/// `robowire.sim.enter_loopback_namespace()` first (as root, or as the root of a user
/// namespace: `unshare --user --map-root-user python …`).
#[pyclass(module = "robowire.sim", frozen)]
pub(crate) struct G1 {
    sim: Owned<G1Sim>,
    domain: u16,
    variant: G1Variant,
    mode_machine: u8,
    capture: Capture,
}

#[pymethods]
impl G1 {
    /// Joins DDS domain `domain` on `interface` (`None`: the library's choice). `dof`: 29, 27
    /// (the 29-dof body with its waist locked), 23 or 14 (the dual-arm G1). `mode_machine`: what
    /// its LowState says and its LowCmds must carry, 0..=255 (`None`: the variant's, 5 for the
    /// 29-dof G1, 4 for the 23-dof one). `state_period_s`: the `rt/lowstate` period (at least
    /// 0.0001 s). `record`: a path or a `robowire.Recorder` to record the robot's side of
    /// `g1/low_level` (`rt/lowstate`, `rt/lowcmd`, `rt/arm_sdk`) and `g1/api` into. `physics`:
    /// the body in MuJoCo (a wheel built with the `mujoco` feature), its pelvis held (hanging)
    /// unless `free_base`; `model`: a user's MJCF instead of robowire's model of the G1.
    #[new]
    #[pyo3(signature = (interface = Some("lo"), domain = 0, *, dof = 29, mode_machine = None, state_period_s = 0.002, record = None, physics = false, model = None, free_base = false))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        interface: Option<&str>,
        domain: u16,
        dof: u8,
        mode_machine: Option<u8>,
        state_period_s: f64,
        record: Option<&Bound<'_, PyAny>>,
        physics: bool,
        model: Option<std::path::PathBuf>,
        free_base: bool,
    ) -> PyResult<Self> {
        #[cfg_attr(not(feature = "mujoco"), allow(unused_variables))]
        let physics = super::unitree::physics_arg(physics, model, !free_base)?;
        let variant = variant_of_dof(dof)?;
        let state_period = seconds("state_period_s", state_period_s)?;
        if state_period.as_micros() < 100 {
            return Err(error(Kind::Argument, "state_period_s must be at least 0.0001"));
        }
        let (links, capture) = record_arg(record, "robowire.sim.G1")?;
        let defaults = G1SimConfig::new(variant);
        let config = G1SimConfig {
            participant: ParticipantOptions::new(domain, interface),
            mode_machine: mode_machine.unwrap_or(defaults.mode_machine),
            state_period,
            low_level_tap: links.as_ref().map(|r| r.link("g1/low_level", &unitree_proto::description::HG_LOW_LEVEL)),
            services_tap: links.as_ref().map(|r| r.link("g1/api", &unitree_proto::description::API_SERVER)),
            #[cfg(feature = "mujoco")]
            physics,
            ..defaults
        };
        let mode_machine = config.mode_machine;
        let sim = py.detach(|| G1Sim::spawn(config)).map_err(|e| error(Kind::Error, chain(&e)))?;
        Ok(Self { sim: Owned::new("G1 simulator", sim), domain, variant, mode_machine, capture })
    }

    /// The DDS domain.
    #[getter]
    fn domain(&self) -> u16 {
        self.domain
    }

    /// Which G1: `"29dof"`, `"23dof"`, `"29dof_waist_locked"` or `"dual_arm"`.
    #[getter]
    fn variant(&self) -> &'static str {
        variant_name(self.variant)
    }

    /// The `mode_machine` its LowState says and its LowCmds must carry.
    #[getter]
    fn mode_machine(&self) -> u8 {
        self.mode_machine
    }

    /// The mode owning the motors (`""` once released), the loco FSM, the 29 joint positions
    /// (rad, slot order; 0 on slots the variant does not drive), what happened to the frames
    /// that arrived (`lowcmd`: `accepted`, `ignored_mode` (the controller owned the motors),
    /// `bad_mode_machine`, `bad_mode_pr`, `disabled_motors` (a `mode` 0 motor with a target, gain
    /// or torque), `bad_crc`, `malformed`; `arm_sdk`: `accepted`, `ignored_released`, `unsealed`,
    /// `malformed`, `weight` 0..=1), the LowState writer, corrupted states, requests answered,
    /// timing (µs), the body (`base`: the pelvis's `position_m`, `velocity_mps`, `rpy_rad` with
    /// physics, else `None`; `sim_time_s`, `wall_time_s`).
    fn snapshot<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.sim.with(|s| s.snapshot())?;
        let (c, a) = (&s.lowcmd, &s.arm_sdk);
        Ok(dict!(py, {
            "mode" => s.mode,
            "fsm_id" => s.fsm_id,
            "joints_rad" => s.joints_rad.to_vec(),
            "lowcmd" => dict!(py, {
                "accepted" => c.accepted,
                "ignored_mode" => c.ignored_mode,
                "bad_mode_machine" => c.bad_mode_machine,
                "bad_mode_pr" => c.bad_mode_pr,
                "disabled_motors" => c.disabled_motors,
                "bad_crc" => c.bad_crc,
                "malformed" => c.malformed,
            }),
            "arm_sdk" => dict!(py, {
                "accepted" => a.accepted,
                "ignored_released" => a.ignored_released,
                "unsealed" => a.unsealed,
                "malformed" => a.malformed,
                "weight" => a.weight,
            }),
            "lowstate" => topic(py, &s.stream.lowstate)?,
            "corrupted_states" => s.stream.corrupted_states,
            "requests" => s.stream.requests,
            "state_lateness_us" => lateness(py, &s.stream.state_lateness)?,
            "command_jitter_us" => lateness(py, &s.command_jitter)?,
            "body" => super::unitree::body(py, s.base, s.stream.sim_time_s, s.stream.wall_time_s)?,
        }))
    }

    fn __repr__(&self) -> String {
        format!(
            "G1(domain={}, variant={:?}, mode_machine={})",
            self.domain,
            variant_name(self.variant),
            self.mode_machine
        )
    }
}

faults!(G1, robowire_sim::g1::G1Fault, robowire_sim::g1::JOINTS, "the G1 has motors 0..29");

closeable!(G1, sim, capture, "Leaves the domain and stops the robot, then finishes its own capture. Idempotent.");
