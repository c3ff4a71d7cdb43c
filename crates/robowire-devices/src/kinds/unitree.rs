//! A Unitree robot's low-level interface over DDS (Go2, HG): joints, IMU, battery and the
//! LowState itself from `rt/lowstate`. It is commanded joint by joint, not by a velocity: it is
//! not driven, and has no services here (releasing the sport mode is `unitree::LowLevel`'s).

use robowire_core::cdr::CdrType;
use serde_json::Value;
use unitree::{Device, Go2, Hg, HgLowState, LowLevel, LowState, Robot};
use unitree_proto::F32;

use crate::facade::{Describe, Facade, Observations, floats};
use crate::observation::{BatteryReading, ImuReading, JointReadings, Passthrough, wide, xyzw};
use crate::{DeviceError, Observation, OpenOptions};

/// What differs between the Unitree families for a device view.
pub(crate) trait Family: Robot<State: serde::Serialize> {
    /// The name its links are recorded under (`go2/low_level`).
    const RECORDED_AS: &'static str;
    /// Its low-level link's description.
    const LOW_LEVEL: &'static dyn robowire_core::json::LinkDescription;
    /// The state as a few lines.
    fn text(state: &Self::State) -> String;
    /// The state as one line.
    fn line(state: &Self::State) -> String;
    /// The state, device-neutral (without the passthrough).
    fn observe(state: &Self::State) -> Observation;
}

fn pose(q: &[f32]) -> String {
    q.chunks(3).map(|leg| format!("[{}]", floats(leg))).collect::<Vec<_>>().join(" ")
}

/// An IMU reading from a Unitree IMU state's fields (quaternion w, x, y, z).
pub(crate) fn imu(quaternion: [F32; 4], gyroscope: [F32; 3], accelerometer: [F32; 3]) -> ImuReading {
    ImuReading {
        orientation_xyzw: xyzw(quaternion.map(|v| v.get())),
        gyro_radps: wide(gyroscope.map(|v| v.get())),
        acc_mps2: wide(accelerometer.map(|v| v.get())),
    }
}

impl Family for Go2 {
    const RECORDED_AS: &'static str = "go2";
    const LOW_LEVEL: &'static dyn robowire_core::json::LinkDescription = &unitree_proto::description::GO2_LOW_LEVEL;

    fn text(state: &LowState) -> String {
        let mut lines = vec![Self::line(state)];
        for (i, name) in unitree::GO2_JOINT_NAMES.iter().enumerate() {
            let m = &state.motor_state[i];
            lines.push(format!(
                "  {name:<9} q {:+.3} rad  dq {:+.3} rad/s  tau {:+.2} N·m  mode {}  {} °C",
                m.q.get(),
                m.dq.get(),
                m.tau_est.get(),
                m.mode,
                m.temperature
            ));
        }
        lines.push(format!("  foot force FR FL RR RL: {:?}", state.foot_force.map(|f| f.get())));
        lines.join("\n")
    }

    fn line(state: &LowState) -> String {
        let q: [f32; 12] = std::array::from_fn(|i| state.motor_state[i].q.get());
        let rpy = state.imu_state.rpy.map(|v| v.get());
        format!(
            "tick {:>8} | q {} | rpy {} | {:.1} V {:.1} A soc {} %",
            state.tick.get(),
            pose(&q),
            floats(&rpy),
            state.power_v.get(),
            state.power_a.get(),
            state.bms_state.soc
        )
    }

    fn observe(state: &LowState) -> Observation {
        let motors = &state.motor_state[..12];
        let s = &state.imu_state;
        let bms = &state.bms_state;
        Observation {
            joints: Some(JointReadings {
                names: unitree::GO2_JOINT_NAMES.iter().map(|n| format!("{n}_joint")).collect(),
                position_rad: motors.iter().map(|m| f64::from(m.q.get())).collect(),
                velocity_radps: motors.iter().map(|m| f64::from(m.dq.get())).collect(),
                effort_nm: motors.iter().map(|m| f64::from(m.tau_est.get())).collect(),
            }),
            imu: Some(imu(s.quaternion, s.gyroscope, s.accelerometer)),
            battery: Some(BatteryReading {
                voltage_v: Some(state.power_v.get()),
                current_a: Some(state.power_a.get()),
                charge_fraction: Some(f32::from(bms.soc) / 100.0),
                cells_v: bms.cell_vol.iter().map(|mv| f32::from(mv.get()) / 1000.0).collect(),
            }),
            ..Observation::default()
        }
    }
}

impl Family for Hg {
    const RECORDED_AS: &'static str = "hg";
    const LOW_LEVEL: &'static dyn robowire_core::json::LinkDescription = &unitree_proto::description::HG_LOW_LEVEL;

    fn text(state: &HgLowState) -> String {
        let q: Vec<f32> = state.motor_state.iter().map(|m| m.q.get()).collect();
        format!("{}\n  q rad (35 slots): {}", Self::line(state), floats(&q))
    }

    fn line(state: &HgLowState) -> String {
        let rpy = state.imu_state.rpy.map(|v| v.get());
        format!(
            "tick {:>8} | mode_pr {} mode_machine {} | rpy {}",
            state.tick.get(),
            state.mode_pr,
            state.mode_machine,
            floats(&rpy)
        )
    }

    /// The 35 motor slots as `motor_0` … (the HG family has no joint-name table here).
    fn observe(state: &HgLowState) -> Observation {
        let motors = &state.motor_state;
        let s = &state.imu_state;
        Observation {
            joints: Some(JointReadings {
                names: (0..motors.len()).map(|i| format!("motor_{i}")).collect(),
                position_rad: motors.iter().map(|m| f64::from(m.q.get())).collect(),
                velocity_radps: motors.iter().map(|m| f64::from(m.dq.get())).collect(),
                effort_nm: motors.iter().map(|m| f64::from(m.tau_est.get())).collect(),
            }),
            imu: Some(imu(s.quaternion, s.gyroscope, s.accelerometer)),
            ..Observation::default()
        }
    }
}

/// The state, device-neutral, with the LowState itself to pass through.
fn observation<R: Family>(state: &R::State) -> Observation {
    Observation { passthrough: lowstate_passthrough(state), ..R::observe(state) }
}

/// A LowState (any Unitree family) as the `lowstate` passthrough: its DDS type name and body.
pub(crate) fn lowstate_passthrough<S: CdrType>(state: &S) -> Option<Passthrough> {
    let mut body = vec![0u8; state.body_len()];
    let n = state.encode_body(&mut body).ok()?;
    body.truncate(n);
    Some(Passthrough { topic: "lowstate", type_name: S::TYPE_NAME, body })
}

/// The low-level client's counters as one line.
pub(crate) fn low_level_stats(s: &unitree::LowLevelStats) -> String {
    format!(
        "lowcmd sent {} (damping {}) | lowstate received {} decode errors {} CRC errors {} lost by tick {} | \
         send lateness p50 {} µs p99 {} µs",
        s.commands_sent,
        s.damping_sent,
        s.lowstate.samples,
        s.lowstate.decode_errors,
        s.lowstate.checksum_errors,
        s.lost_by_tick,
        s.send_lateness.p50_us,
        s.send_lateness.p99_us
    )
}

impl<R: Family> Describe for LowLevel<R> {
    /// The LowState with the IDL field names (as `robowire decode lowstate --json`).
    fn status_json(&self) -> Option<Value> {
        serde_json::to_value(self.latest()?.state).ok()
    }

    fn status_text(&self) -> Option<String> {
        Some(R::text(&self.latest()?.state))
    }

    fn status_line(&self) -> Option<String> {
        let stamped = self.latest()?;
        Some(format!("{} | age {} ms", R::line(&stamped.state), stamped.age().as_millis()))
    }

    fn stats_line(&self) -> String {
        low_level_stats(&self.stats())
    }
}

impl<R: Family> Facade for LowLevel<R> {
    fn observe(&self) -> Option<Observation> {
        Some(observation::<R>(&self.latest()?.state))
    }

    fn observations(&self) -> Observations {
        Observations::new(self.every_state(), observation::<R>)
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    /// Damping (if anything was sent), then closed.
    fn close(self: Box<Self>) -> Result<(), DeviceError> {
        LowLevel::close(*self);
        Ok(())
    }
}

/// A Unitree robot of family `R` on `interface`, through its low-level client.
pub(crate) fn open<R: Family>(interface: &str, options: &OpenOptions) -> Result<Box<dyn Facade>, DeviceError> {
    Ok(Box::new(LowLevel::<R>::open(low_level_options::<R>(Some(interface), options))?))
}

/// A low-level client's options for family `R`, recorded under its name (`go2/low_level`).
pub(crate) fn low_level_options<R: Family>(interface: Option<&str>, options: &OpenOptions) -> unitree::LowLevelOptions {
    recorded_options(interface, options, R::RECORDED_AS, R::LOW_LEVEL)
}

/// A Unitree low-level client's options: the domain, the state timeout, and with a recorder its
/// links `{recorded_as}/low_level` (described by `low_level`) and `{recorded_as}/api`.
pub(crate) fn recorded_options(
    interface: Option<&str>,
    options: &OpenOptions,
    recorded_as: &str,
    low_level: &'static dyn robowire_core::json::LinkDescription,
) -> unitree::LowLevelOptions {
    let defaults = unitree::LowLevelOptions::on(interface, options.domain);
    unitree::LowLevelOptions { state_timeout: options.state_timeout.unwrap_or(defaults.state_timeout), ..defaults }
        .recorded(options.record.as_ref(), recorded_as, low_level)
}
