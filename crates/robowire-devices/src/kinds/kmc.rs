//! A KMC chassis: speed, battery and motor reports, odometry from the speed and the commanded
//! curvature; driven by velocity and yaw rate.

use std::time::Duration;

use kmc::{ChassisState, Device, Driver};
use serde_json::{Value, json};

use crate::facade::{Describe, Facade, Observations};
use crate::observation::{BatteryReading, MotorReport, Odometry, yaw_quaternion};
use crate::{DeviceError, Observation, OpenOptions};

fn odometry_json(state: &ChassisState) -> Value {
    let o = &state.odometry;
    json!({
        "x_m": o.x_m, "y_m": o.y_m, "heading_rad": o.heading_rad,
        "speed_mps": o.speed_mps, "yaw_rate_radps": o.yaw_rate_radps,
    })
}

fn motor_json(motor: &kmc::AllState) -> Value {
    json!({
        "motor_id": motor.motor_id, "id": motor.id, "position_deg": motor.position_deg,
        "speed_rpm": motor.speed_rpm, "current_a": motor.current_a,
        "temperature_c": motor.temperature_c, "error_code": motor.error_code,
    })
}

fn motor_report(motor: &kmc::AllState) -> MotorReport {
    let ok = motor.error_code == 0;
    let value = |key: &str, value: String| (key.to_owned(), value);
    MotorReport {
        name: format!("motor {}", motor.motor_id),
        hardware_id: format!("kmc motor {}", motor.motor_id),
        ok,
        message: if ok { "ok".into() } else { format!("error code {}", motor.error_code) },
        values: vec![
            value("position_deg", motor.position_deg.to_string()),
            value("speed_rpm", motor.speed_rpm.to_string()),
            value("current_a", motor.current_a.to_string()),
            value("temperature_c", motor.temperature_c.to_string()),
            value("error_code", motor.error_code.to_string()),
        ],
    }
}

/// What the frame that made `state` reported: odometry with a speed report, the battery with a
/// battery report, a motor's health with an all-state report.
fn observation(state: &ChassisState) -> Observation {
    let mut observation = Observation::default();
    match state.last_frame {
        Some(kmc::ChassisFrame::VehicleSpeed(_)) => {
            let o = &state.odometry;
            observation.odometry = Some(Odometry {
                position_m: [o.x_m, o.y_m, 0.0],
                orientation_xyzw: yaw_quaternion(o.heading_rad),
                linear_mps: [o.speed_mps, 0.0, 0.0],
                angular_radps: [0.0, 0.0, o.yaw_rate_radps],
            });
        }
        Some(kmc::ChassisFrame::BatteryVoltage(battery)) => {
            observation.battery = Some(BatteryReading { voltage_v: Some(battery.volts), ..BatteryReading::default() });
        }
        Some(kmc::ChassisFrame::AllState(motor)) => observation.motors.push(motor_report(&motor)),
        Some(kmc::ChassisFrame::Af(_)) | None => {}
    }
    observation
}

impl Describe for Driver {
    fn status_json(&self) -> Option<Value> {
        let state = self.latest()?.state;
        Some(json!({
            "port": self.port().display().to_string(),
            "link": format!("{:?}", self.link_state()),
            "speed_mps": state.speed_mps,
            "battery_v": state.battery.map(|b| b.volts),
            "motors": state.motors.iter().flatten().map(motor_json).collect::<Vec<_>>(),
            "odometry": odometry_json(&state),
        }))
    }

    fn status_text(&self) -> Option<String> {
        let state = self.latest()?.state;
        let o = &state.odometry;
        let mut text = format!(
            "link           {:?} on {}\nspeed          {} m/s\nbattery        {}\nodometry       x {:+.3} m  y {:+.3} m  heading {:+.3} rad",
            self.link_state(),
            self.port().display(),
            state.speed_mps.map_or("-".into(), |v| format!("{v:+.3}")),
            state.battery.map_or("-".into(), |b| format!("{:.2} V (motor {})", b.volts, b.motor_id)),
            o.x_m,
            o.y_m,
            o.heading_rad
        );
        for motor in state.motors.iter().flatten() {
            text.push_str(&format!(
                "\nmotor {}        {:.1} rpm  {:.2} A  {:.1} °C  error 0x{:08x}",
                motor.motor_id, motor.speed_rpm, motor.current_a, motor.temperature_c, motor.error_code
            ));
        }
        Some(text)
    }

    fn status_line(&self) -> Option<String> {
        let stamped = self.latest()?;
        let (state, o) = (&stamped.state, &stamped.state.odometry);
        Some(format!(
            "speed {} m/s | x {:+6.2} m y {:+6.2} m heading {:+5.2} rad | battery {} | age {} ms",
            state.speed_mps.map_or(" -    ".into(), |v| format!("{v:+.3}")),
            o.x_m,
            o.y_m,
            o.heading_rad,
            state.battery.map_or("-".into(), |b| format!("{:.2} V", b.volts)),
            stamped.age().as_millis()
        ))
    }

    fn stats_line(&self) -> String {
        let s = self.stats();
        format!(
            "sent: control {} (timeout stops {}), speed requests {}, battery {}, all-state {} | received {} | \
             skipped bytes {}, rejected candidates {} | disconnects {} silences {} | lateness p50 {} µs p99 {} µs",
            s.control_frames_sent,
            s.timeout_frames_sent,
            s.speed_requests_sent,
            s.battery_requests_sent,
            s.all_state_requests_sent,
            s.frames_received,
            s.link.decoder.skipped_bytes,
            s.link.decoder.rejected_candidates,
            s.disconnects,
            s.state_timeouts,
            s.control_lateness.p50_us,
            s.control_lateness.p99_us
        )
    }
}

impl Facade for Driver {
    fn observe(&self) -> Option<Observation> {
        Some(observation(&self.latest()?.state))
    }

    fn observations(&self) -> Observations {
        Observations::new(self.every_state(), observation)
    }

    /// The chassis drives forward and turns; it cannot move sideways (`vy` is ignored).
    fn drive(&self, vx_mps: f32, _vy_mps: f32, yaw_rate_radps: f32) -> Result<(), DeviceError> {
        Ok(self.set_command(vx_mps, yaw_rate_radps)?)
    }

    fn can_drive(&self) -> bool {
        true
    }

    fn stop_motion(&self) -> Result<(), DeviceError> {
        Ok(self.set_command(0.0, 0.0)?)
    }

    fn set_drive_timeout(&self, timeout: Duration) -> Result<(), DeviceError> {
        Ok(self.set_command_timeout(timeout)?)
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn close(self: Box<Self>) -> Result<(), DeviceError> {
        Ok(Driver::close(*self)?)
    }
}

/// The KMC chassis's driver on the serial port `path`.
pub(crate) fn open(path: &std::path::Path, options: &OpenOptions) -> Result<Box<dyn Facade>, DeviceError> {
    Ok(Box::new(Driver::open(path, driver_options(options))?))
}

/// The driver's options: the polls, the state timeout, with a recorder its serial link's taps.
pub(crate) fn driver_options(options: &OpenOptions) -> kmc::DriverOptions {
    let defaults = kmc::DriverOptions::default();
    let record = options.record.as_ref();
    kmc::DriverOptions {
        poll_battery: options.kmc_polls,
        poll_allstate: options.kmc_polls,
        state_timeout: options.state_timeout.unwrap_or(defaults.state_timeout),
        taps: record.map(|r| kmc_taps(r, &kmc_proto::description::HOST)).unwrap_or_default(),
        ..defaults
    }
}

/// The taps of a KMC serial line recorded with `record`: its frames as `kmc/serial`, described by
/// `side` (`kmc_proto::description::HOST` at the host, `CHASSIS` at a chassis), and the bytes the
/// decoder skipped as `kmc/serial_skipped` (`robowire_core::json::SKIPPED_BYTES`).
pub fn kmc_taps(
    record: &robowire_tap::RecordLinks,
    side: &'static robowire_core::json::LinkProtocol,
) -> robowire_serial::SerialTaps {
    robowire_serial::SerialTaps {
        frames: Some(record.link("kmc/serial", side)),
        skipped: Some(record.link("kmc/serial_skipped", &robowire_core::json::SKIPPED_BYTES)),
    }
}
