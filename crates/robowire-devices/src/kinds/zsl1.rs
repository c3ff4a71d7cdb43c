//! A ZSL-1 / ZSL-1W through its HighLevel interface: odometry, IMU, joints and battery from the
//! 500 Hz state; driven with `move`; `stand_up`, `lie_down`, `passive` as services.

use serde_json::Value;
use zsl::udp::{Device, HighLevel, Model, RobotState};

use crate::facade::{Describe, Facade, Observations, floats};
use crate::observation::{BatteryReading, ImuReading, JointReadings, Odometry, wide, xyzw};
use crate::{DeviceError, Observation, OpenOptions};

/// Joint names, `[leg][joint]` order of the state: FR, FL, RR, RL × abad, hip, knee (+ foot).
pub(crate) fn joint_names(model: Model) -> Vec<String> {
    let joints: &[&str] =
        if model == Model::Zsl1W { &["abad", "hip", "knee", "foot"] } else { &["abad", "hip", "knee"] };
    ["FR", "FL", "RR", "RL"].iter().flat_map(|leg| joints.iter().map(move |j| format!("{leg}_{j}"))).collect()
}

/// The robot's error word as text: `none`, or the code and its name.
fn error_text(s: &RobotState) -> String {
    s.body.error.map_or_else(|| "none".into(), |e| format!("0x{:04x} ({e:?})", e.raw()))
}

/// One line of state: mode, position, velocity, yaw, battery, error.
pub fn state_line(s: &RobotState) -> String {
    let b = &s.body;
    format!(
        "mode {:>2} | pos {:+6.2} {:+6.2} {:+5.2} m | v {:+5.2} {:+5.2} m/s | yaw {:+5.2} rad | battery {:>3} % | error {}",
        b.mode.raw(),
        b.position_m[0],
        b.position_m[1],
        b.position_m[2],
        b.body_velocity_mps[0],
        b.body_velocity_mps[1],
        b.imu.rpy_rad[2],
        b.battery_percent,
        error_text(s)
    )
}

fn status_text(s: &RobotState) -> String {
    let b = &s.body;
    let mut lines = vec![
        format!("mode           {} ({:?})", b.mode.raw(), b.mode),
        format!("battery        {} %", b.battery_percent),
        format!("error          {}", error_text(s)),
        format!("sdk mismatch   {}", if s.sdk_mismatch { "yes" } else { "no" }),
        format!("position m     {}", floats(&b.position_m)),
        format!("body vel m/s   {}", floats(&b.body_velocity_mps)),
        format!("rpy rad        {}", floats(&b.imu.rpy_rad)),
        format!("quaternion     {}", floats(&b.imu.quaternion_wxyz)),
        format!("gyro rad/s     {}", floats(&b.imu.gyro_radps)),
    ];
    let joints = &s.joints.position_rad;
    for (name, legs) in [("abad", joints.abad), ("hip", joints.hip), ("knee", joints.knee), ("foot", joints.foot)] {
        lines.push(format!("{name:<5} rad FR FL RR RL  {}", floats(&legs)));
    }
    lines.join("\n")
}

fn observation(state: &RobotState, model: Model) -> Observation {
    let body = &state.body;
    let orientation = xyzw(body.imu.quaternion_wxyz);
    let joints = &state.joints;
    let per_leg = if model == Model::Zsl1W { 4 } else { 3 };
    let column = |a: &zsl::udp::JointArrays| -> Vec<f64> {
        (0..4)
            .flat_map(|leg| [a.abad[leg], a.hip[leg], a.knee[leg], a.foot[leg]].into_iter().take(per_leg))
            .map(f64::from)
            .collect()
    };
    Observation {
        odometry: Some(Odometry {
            position_m: wide(body.position_m),
            orientation_xyzw: orientation,
            linear_mps: wide(body.body_velocity_mps),
            angular_radps: wide(body.imu.gyro_radps),
        }),
        imu: Some(ImuReading {
            orientation_xyzw: orientation,
            gyro_radps: wide(body.imu.gyro_radps),
            acc_mps2: wide(body.imu.acc_mps2),
        }),
        joints: Some(JointReadings {
            names: joint_names(model),
            position_rad: column(&joints.position_rad),
            velocity_radps: column(&joints.velocity_radps),
            effort_nm: column(&joints.torque_nm),
        }),
        battery: Some(BatteryReading {
            charge_fraction: Some(body.battery_percent as f32 / 100.0),
            ..BatteryReading::default()
        }),
        motors: Vec::new(),
        passthrough: None,
    }
}

/// What a latched call's outcome says, for a service caller.
fn said(name: &str, outcome: Result<zsl::udp::Latched, zsl::udp::CallError>) -> Result<String, DeviceError> {
    let latched = outcome?;
    Ok(if latched.acknowledged() {
        format!("{name} sent; the robot reports mode {:?}", latched.reported)
    } else {
        format!(
            "{name} sent (return code 0x{:04x}); the robot still reports mode {:?}",
            latched.return_code.raw(),
            latched.reported
        )
    })
}

impl Describe for HighLevel {
    /// The datagram's JSON, as `robowire decode zsl --json` prints it.
    fn status_json(&self) -> Option<Value> {
        serde_json::to_value(self.latest()?.state).ok()
    }

    fn status_text(&self) -> Option<String> {
        Some(status_text(&(&self.latest()?.state).into()))
    }

    fn status_line(&self) -> Option<String> {
        let stamped = self.latest()?;
        Some(format!("{} | age {} ms", state_line(&(&stamped.state).into()), stamped.age().as_millis()))
    }

    fn stats_line(&self) -> String {
        let s = self.stats();
        format!(
            "link: sent {} received {} decode errors {} foreign dropped {} | short states {} header anomalies {} disconnects {}",
            s.link.sent,
            s.link.received,
            s.link.decode_errors,
            s.link.foreign_dropped,
            s.short_states,
            s.header_anomalies,
            s.disconnects
        )
    }
}

impl Facade for HighLevel {
    fn observe(&self) -> Option<Observation> {
        Some(observation(&(&self.latest()?.state).into(), self.options().model))
    }

    fn observations(&self) -> Observations {
        let model = self.options().model;
        Observations::new(self.every_state(), move |state| observation(&state.into(), model))
    }

    fn drive(&self, vx_mps: f32, vy_mps: f32, yaw_rate_radps: f32) -> Result<(), DeviceError> {
        self.move_velocity(vx_mps, vy_mps, yaw_rate_radps)?;
        Ok(())
    }

    fn can_drive(&self) -> bool {
        true
    }

    fn stop_motion(&self) -> Result<(), DeviceError> {
        self.move_velocity(0.0, 0.0, 0.0)?;
        Ok(())
    }

    fn services(&self) -> &'static [&'static str] {
        &["stand_up", "lie_down", "passive"]
    }

    fn call(&self, service: &str) -> Result<String, DeviceError> {
        match service {
            "stand_up" => said(service, self.stand_up()),
            "lie_down" => said(service, self.lie_down()),
            "passive" => said(service, self.passive()),
            _ => Err(DeviceError::NoSuchService { service: service.into() }),
        }
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn close(self: Box<Self>) -> Result<(), DeviceError> {
        HighLevel::close(*self);
        Ok(())
    }
}

/// A ZSL-1 (or ZSL-1W, by `model`) at `ip`, its state expected at `options.zsl_local`.
pub(crate) fn open(ip: std::net::IpAddr, model: Model, options: &OpenOptions) -> Result<Box<dyn Facade>, DeviceError> {
    let client = zsl::udp::ClientOptions::high_level(options.zsl_local.ip(), options.zsl_local.port(), ip);
    Ok(Box::new(HighLevel::open(client_options(client, model, options))?))
}

/// The client's options: the model, the watchdog, with a recorder its link `zsl1/high_level`.
pub(crate) fn client_options(
    client: zsl::udp::ClientOptions,
    model: Model,
    options: &OpenOptions,
) -> zsl::udp::ClientOptions {
    let watchdog = options.state_timeout.unwrap_or(client.watchdog);
    let client = client.with_model(model).with_watchdog(watchdog);
    match &options.record {
        Some(record) => client.with_tap(record.link("zsl1/high_level", &zsl_proto::description::HIGH_LEVEL)),
        None => client,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joints_are_named_leg_major() {
        let names = joint_names(Model::Zsl1);
        assert_eq!(names.len(), 12);
        assert_eq!(names[..4], ["FR_abad", "FR_hip", "FR_knee", "FL_abad"]);
        assert_eq!(joint_names(Model::Zsl1W).len(), 16);
    }
}
