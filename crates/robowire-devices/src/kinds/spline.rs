//! The ZSL-1's spline daemon (`/spline_shm`), watched: every joint's position, velocity, torque
//! and fault flags. A monitor commands nothing; the motion controller is the caller's own loop
//! (`zsl::SplineClient`).

use serde_json::{Value, json};
use zsl::spline::SplineMonitor;
use zsl::udp::Device;
use zsl::{JointFlags, JointIndex, Leg, SplineStateBlock};

use crate::facade::{Describe, Facade, Observations, floats};
use crate::observation::JointReadings;
use crate::{DeviceError, Observation, OpenOptions};

const LEGS: [(Leg, &str); 4] =
    [(Leg::FrontRight, "FR"), (Leg::FrontLeft, "FL"), (Leg::RearRight, "RR"), (Leg::RearLeft, "RL")];
const JOINTS: [(JointIndex, &str); 4] =
    [(JointIndex::Abad, "abad"), (JointIndex::Hip, "hip"), (JointIndex::Knee, "knee"), (JointIndex::Foot, "foot")];

fn each_joint() -> impl Iterator<Item = (Leg, JointIndex, String)> {
    LEGS.into_iter().flat_map(|(leg, l)| JOINTS.into_iter().map(move |(joint, j)| (leg, joint, format!("{l}_{j}"))))
}

fn observation(state: &SplineStateBlock) -> Observation {
    let mut joints = JointReadings::default();
    for (leg, joint, name) in each_joint() {
        let s = state.joint(leg, joint);
        joints.names.push(name);
        joints.position_rad.push(s.p.get().into());
        joints.velocity_radps.push(s.v.get().into());
        joints.effort_nm.push(s.t.get().into());
    }
    Observation { joints: Some(joints), ..Observation::default() }
}

impl Describe for SplineMonitor {
    fn status_json(&self) -> Option<Value> {
        let state = self.latest()?.state;
        let joints: Vec<Value> = each_joint()
            .map(|(leg, joint, name)| {
                let s = state.joint(leg, joint);
                let flags = JointFlags(s.flags.get());
                json!({
                    "joint": name, "p_rad": s.p.get(), "v_radps": s.v.get(), "t_nm": s.t.get(),
                    "flags": s.flags.get(), "enabled": flags.enabled(), "faults": flags.faults().any(),
                })
            })
            .collect();
        Some(json!({ "name": self.options().name, "joints": joints }))
    }

    fn status_text(&self) -> Option<String> {
        let state = self.latest()?.state;
        let mut lines = vec![format!("{} (read as a monitor)", self.options().name)];
        for (leg, joint, name) in each_joint() {
            let s = state.joint(leg, joint);
            let flags = JointFlags(s.flags.get());
            lines.push(format!(
                "  {name:<8} p {:+.3} rad  v {:+.3} rad/s  t {:+.2} N·m  {}{}",
                s.p.get(),
                s.v.get(),
                s.t.get(),
                if flags.enabled() { "enabled" } else { "disabled" },
                if flags.faults().any() { ", FAULT" } else { "" }
            ));
        }
        Some(lines.join("\n"))
    }

    fn status_line(&self) -> Option<String> {
        let stamped = self.latest()?;
        let p: Vec<f32> = each_joint().map(|(leg, joint, _)| stamped.state.joint(leg, joint).p.get()).collect();
        Some(format!("p rad {} | age {} ms", floats(&p), stamped.age().as_millis()))
    }

    fn stats_line(&self) -> String {
        let s = self.stats();
        format!(
            "fresh states {} | stalls {} returns {} | gap p50 {} µs p99 {} µs max {} µs",
            s.states, s.disconnects, s.reconnects, s.state_gap.p50_us, s.state_gap.p99_us, s.state_gap.max_us
        )
    }
}

impl Facade for SplineMonitor {
    fn observations(&self) -> Observations {
        Observations::new(self.every_state(), observation)
    }

    fn observe(&self) -> Option<Observation> {
        Some(observation(&self.latest()?.state))
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    /// Stops watching: a monitor commands nothing.
    fn close(self: Box<Self>) -> Result<(), DeviceError> {
        SplineMonitor::close(*self);
        Ok(())
    }
}

/// The link `/spline_shm` is recorded as, seen by the controller or a monitor
/// (`zsl_proto::description::SPLINE_CLIENT`).
pub const SPLINE_LINK: &str = "spline/spline";
/// The link `/imu_shm` is recorded as, seen by a reader (`zsl_proto::description::IMU`).
pub const SPLINE_IMU_LINK: &str = "spline/imu";

/// A monitor of the spline daemon's shared memory `name`.
pub(crate) fn open(name: &str, options: &OpenOptions) -> Result<Box<dyn Facade>, DeviceError> {
    Ok(Box::new(SplineMonitor::open(monitor_options(name, options))?))
}

/// The monitor's options: with a recorder, the states it takes recorded as [`SPLINE_LINK`].
pub(crate) fn monitor_options(name: &str, options: &OpenOptions) -> zsl::spline::SplineMonitorOptions {
    let monitor = zsl::spline::SplineMonitorOptions::new(name);
    match &options.record {
        Some(record) => monitor.with_tap(record.link(SPLINE_LINK, &zsl_proto::description::SPLINE_CLIENT)),
        None => monitor,
    }
}
