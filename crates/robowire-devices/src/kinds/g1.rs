//! A Unitree G1 through `unitree::g1`: the joints its variant drives, by their URDF names; the
//! pelvis IMU; the battery from `rt/lf/bmsstate`; the HG LowState itself to pass through. It is
//! driven through its locomotion service (`SetVelocity`, each velocity held [`DRIVE_HOLDS_S`],
//! sent without waiting for the answer); it has no services here.

use serde_json::Value;
use unitree::g1::{Device, G1, G1Options, G1Variant, HgBmsState, HgLowState, JOINT_NAMES, JOINTS, Velocity};

/// How long the G1's controller holds a velocity of [`Facade::drive`], s: a bridge refreshes it
/// with every twist, and its deadman asks zero sooner.
pub(crate) const DRIVE_HOLDS_S: f32 = 1.0;

use super::unitree::{imu, low_level_stats, lowstate_passthrough};
use crate::facade::{Describe, Facade, Observations, floats};
use crate::observation::{BatteryReading, JointReadings};
use crate::{DeviceError, Observation, OpenOptions};

/// The slots `variant` drives, in slot order.
fn driven(variant: G1Variant) -> impl Iterator<Item = usize> {
    (0..JOINTS).filter(move |&slot| variant.drives(slot))
}

/// A battery state in SI units: charge from `soc` (%), voltage from the first pack voltage (mV;
/// `None` when 0), current (mA, negative discharging), the cells that report a voltage (mV).
pub(crate) fn battery_reading(bms: &HgBmsState) -> BatteryReading {
    let pack_mv = bms.bmsvoltage[0].get();
    BatteryReading {
        voltage_v: (pack_mv != 0).then(|| pack_mv as f32 / 1000.0),
        current_a: Some(bms.current.get() as f32 / 1000.0),
        charge_fraction: Some(f32::from(bms.soc) / 100.0),
        cells_v: bms
            .cell_vol
            .iter()
            .map(|mv| mv.get())
            .filter(|&mv| mv != 0)
            .map(|mv| f32::from(mv) / 1000.0)
            .collect(),
    }
}

/// A LowState of a G1 of `variant`, device-neutral, with `battery` and the LowState to pass
/// through.
pub(crate) fn observation(state: &HgLowState, variant: G1Variant, battery: Option<&HgBmsState>) -> Observation {
    let motors = || driven(variant).map(|slot| &state.motor_state[slot]);
    let s = &state.imu_state;
    Observation {
        joints: Some(JointReadings {
            names: driven(variant).map(|slot| JOINT_NAMES[slot].to_owned()).collect(),
            position_rad: motors().map(|m| f64::from(m.q.get())).collect(),
            velocity_radps: motors().map(|m| f64::from(m.dq.get())).collect(),
            effort_nm: motors().map(|m| f64::from(m.tau_est.get())).collect(),
        }),
        imu: Some(imu(s.quaternion, s.gyroscope, s.accelerometer)),
        battery: battery.map(battery_reading),
        passthrough: lowstate_passthrough(state),
        ..Observation::default()
    }
}

/// The state as one line: tick, `mode_machine` and the variant, `mode_pr`, the pelvis attitude,
/// the charge.
fn line(state: &HgLowState, options: &G1Options, battery: Option<&HgBmsState>) -> String {
    let rpy = state.imu_state.rpy.map(|v| v.get());
    let charge = battery.map_or_else(|| "no battery state".into(), |b| format!("soc {} %", b.soc));
    format!(
        "tick {:>8} | mode_machine {} ({:?}) mode_pr {} | rpy {} | {charge}",
        state.tick.get(),
        state.mode_machine,
        options.variant_of(state.mode_machine),
        state.mode_pr,
        floats(&rpy)
    )
}

/// The state as lines: [`line`], each driven joint by name, the battery.
fn text(state: &HgLowState, options: &G1Options, battery: Option<&HgBmsState>) -> String {
    let mut lines = vec![line(state, options, battery)];
    for slot in driven(options.variant_of(state.mode_machine)) {
        let m = &state.motor_state[slot];
        lines.push(format!(
            "  {:<26} q {:+.3} rad  dq {:+.3} rad/s  tau {:+.2} N·m  mode {}  {}/{} °C",
            JOINT_NAMES[slot],
            m.q.get(),
            m.dq.get(),
            m.tau_est.get(),
            m.mode,
            m.temperature[0].get(),
            m.temperature[1].get()
        ));
    }
    if let Some(b) = battery {
        let reading = battery_reading(b);
        lines.push(format!(
            "  battery: soc {} % soh {} % | {} V {:+.2} A | cells {} V",
            b.soc,
            b.soh,
            reading.voltage_v.map_or("?".into(), |v| format!("{v:.2}")),
            reading.current_a.unwrap_or(f32::NAN),
            floats(&reading.cells_v)
        ));
    }
    lines.join("\n")
}

impl Describe for G1 {
    /// The LowState with the IDL field names (as `robowire decode lowstate --json`).
    fn status_json(&self) -> Option<Value> {
        serde_json::to_value(self.latest()?.state).ok()
    }

    fn status_text(&self) -> Option<String> {
        Some(text(&self.latest()?.state, self.options(), self.battery().as_ref()))
    }

    fn status_line(&self) -> Option<String> {
        let stamped = self.latest()?;
        let line = line(&stamped.state, self.options(), self.battery().as_ref());
        Some(format!("{line} | age {} ms", stamped.age().as_millis()))
    }

    fn stats_line(&self) -> String {
        let s = self.stats();
        let asks = self.loco().velocity_asks();
        let refusal = asks.last_refusal.map_or(String::new(), |why| format!(" (last: {why})"));
        format!(
            "{} | arm_sdk sent {} weight {:.2} | bmsstate received {} | velocity asked {} refused {}{refusal}",
            low_level_stats(&s.low_level),
            s.arm_sdk_sent,
            s.arm_sdk_weight,
            s.bmsstate.samples,
            asks.sent,
            asks.refused
        )
    }
}

impl Facade for G1 {
    fn observe(&self) -> Option<Observation> {
        let state = self.latest()?.state;
        Some(observation(&state, self.options().variant_of(state.mode_machine), self.battery().as_ref()))
    }

    fn observations(&self) -> Observations {
        let (options, battery) = (self.options().clone(), self.battery_handle());
        Observations::new(self.every_state(), move |state: &HgLowState| {
            observation(state, options.variant_of(state.mode_machine), battery.latest().as_ref())
        })
    }

    /// `SetVelocity` for [`DRIVE_HOLDS_S`], checked now, the robot's answer counted in the
    /// stats line (refused while no walking FSM runs: `LOCO_STATE_UNAVAILABLE`).
    fn drive(&self, vx_mps: f32, vy_mps: f32, yaw_rate_radps: f32) -> Result<(), DeviceError> {
        let velocity = Velocity { vx_mps, vy_mps, yaw_radps: yaw_rate_radps, duration_s: DRIVE_HOLDS_S };
        Ok(self.loco().ask_velocity(velocity)?)
    }

    fn can_drive(&self) -> bool {
        true
    }

    fn stop_motion(&self) -> Result<(), DeviceError> {
        self.drive(0.0, 0.0, 0.0)
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    /// The arm weight ramped out, damping (if anything was sent), then closed.
    fn close(self: Box<Self>) -> Result<(), DeviceError> {
        G1::close(*self);
        Ok(())
    }
}

/// A G1 on `interface`, through `unitree::g1`.
pub(crate) fn open(interface: &str, options: &OpenOptions) -> Result<Box<dyn Facade>, DeviceError> {
    Ok(Box::new(G1::open(client_options(Some(interface), options))?))
}

/// A G1 client's options: the HG low level, recorded as `g1/low_level`, `g1/api` and
/// `g1/arm_sdk`.
pub(crate) fn client_options(interface: Option<&str>, options: &OpenOptions) -> G1Options {
    let defaults = G1Options::on(interface, options.domain);
    let state_timeout = options.state_timeout.unwrap_or(defaults.low_level.state_timeout);
    let low_level = unitree::LowLevelOptions { state_timeout, ..defaults.low_level };
    G1Options { low_level, ..defaults }.recorded(options.record.as_ref())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(mode_machine: u8) -> HgLowState {
        let mut state = HgLowState::default();
        state.mode_machine = mode_machine;
        for (i, m) in state.motor_state.iter_mut().enumerate() {
            m.q = (0.01 * i as f32).into();
        }
        state.imu_state.quaternion = [1.0, 0.0, 0.0, 0.0].map(Into::into);
        state
    }

    #[test]
    fn the_joints_the_variant_drives_by_name_the_imu_the_battery_and_the_lowstate() {
        let mut bms = HgBmsState::default();
        (bms.soc, bms.current, bms.bmsvoltage[0]) = (87, (-3200).into(), 52_100.into());
        bms.cell_vol[..13].fill(4008.into());
        let seen = observation(&state(5), G1Variant::Dof29, Some(&bms));
        let joints = seen.joints.unwrap();
        assert_eq!(joints.names, JOINT_NAMES);
        assert_eq!(joints.position_rad.len(), 29);
        assert_eq!(joints.position_rad[28] as f32, 0.01 * 28.0);
        assert_eq!(seen.imu.unwrap().orientation_xyzw, [0.0, 0.0, 0.0, 1.0]);
        let battery = seen.battery.unwrap();
        assert_eq!(
            (battery.charge_fraction, battery.voltage_v, battery.current_a),
            (Some(0.87), Some(52.1), Some(-3.2))
        );
        assert_eq!(battery.cells_v, [4.008; 13], "the cells that report a voltage");
        let raw = seen.passthrough.unwrap();
        assert_eq!((raw.topic, raw.type_name), ("lowstate", "unitree_hg::msg::dds_::LowState_"));

        // A 23-dof G1 (mode_machine 4): no waist roll/pitch, no wrist pitch/yaw; no battery yet.
        let seen = observation(&state(4), G1Variant::Dof23, None);
        let joints = seen.joints.unwrap();
        assert_eq!(joints.names.len(), 23);
        assert!(!joints.names.iter().any(|n| n == "waist_roll_joint" || n == "left_wrist_yaw_joint"));
        assert_eq!(joints.names[13], "left_shoulder_pitch_joint");
        assert_eq!(joints.position_rad[13] as f32, 0.01 * 15.0, "slot 15's");
        assert_eq!(seen.battery, None);
    }

    #[test]
    fn status_names_the_variant_and_the_joints() {
        let options = G1Options::default();
        let one = line(&state(4), &options, None);
        assert!(one.contains("mode_machine 4 (Dof23) mode_pr 0") && one.ends_with("no battery state"), "{one}");
        let all = text(&state(6), &options, None);
        assert!(all.contains("(Dof29WaistLocked)") && all.contains("  right_wrist_yaw_joint"), "{all}");
        assert!(!all.contains("waist_roll_joint"), "{all}");
        assert_eq!(all.lines().count(), 1 + 27);
    }
}
