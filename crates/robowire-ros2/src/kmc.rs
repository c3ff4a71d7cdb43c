//! A KMC chassis as a ROS 2 node: `cmd_vel` → `set_command(v, ω)`, `odom` and `tf` from the
//! speed reports and the commanded curvature, `battery_state`, per-motor all-state as
//! `diagnostics`.

use std::time::{Duration, Instant};

use kmc::{ChassisFrame, Driver};
use robowire_dds::qos::Qos;
use ros2_proto::diagnostic::{DiagnosticArray, DiagnosticStatus, KeyValue};
use ros2_proto::geometry::{
    Point, Pose, PoseWithCovariance, Quaternion, Transform, TransformStamped, Twist, TwistWithCovariance, Vector3,
};
use ros2_proto::nav::Odometry;
use ros2_proto::sensor::BatteryState;
use ros2_proto::tf::TfMessage;

use crate::node::{CmdVel, Node, stamp_now};
use crate::odom::PlanarOdometry;
use crate::report::DeviceReport;

/// How often the driver's received frames are drained.
const DRAIN_PERIOD: Duration = Duration::from_millis(2);
/// How often a live command is re-set between twists (the driver stops after 300 ms without).
const COMMAND_REFRESH: Duration = Duration::from_millis(100);

/// Bridges `driver` (started) until `stop` resolves.
pub(crate) async fn run(
    node: Node<'_>,
    driver: &Driver,
    report: &DeviceReport,
    stop: impl Future<Output = ()>,
) -> Result<(), robowire_dds::DdsError> {
    let odom_writer = node.writer::<Odometry>("odom", Qos::ROS_DEFAULT)?;
    let tf_writer = node.writer::<TfMessage>("tf", Qos::ROS_DEFAULT)?;
    let battery_writer = node.writer::<BatteryState>("battery_state", Qos::ROS_SENSOR_DATA)?;
    let diagnostics_writer = node.writer::<DiagnosticArray>("diagnostics", Qos::ROS_DEFAULT)?;
    let mut cmd_vel = node.reader::<Twist>("cmd_vel", Qos::ROS_DEFAULT)?;
    let ns = node.options.namespace.clone();
    let mut cmd_vel_guard = CmdVel::new(&node.options);
    let mut odom = PlanarOdometry::default();
    let mut curvature_per_m = 0.0f64;
    // The live command, refreshed inside the driver's 300 ms command timeout until the deadman.
    let mut live: Option<(f32, f32, Instant)> = None;
    let mut limiter = node.limiter();
    let epoch = Instant::now();
    let mut drain = tokio::time::interval(DRAIN_PERIOD);
    drain.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Skip);
    tokio::pin!(stop);
    loop {
        tokio::select! {
            () = &mut stop => return Ok(()),
            _ = drain.tick() => {
                let now = Instant::now();
                if cmd_vel_guard.guard.on_tick(now) {
                    let _ = driver.set_command(0.0, 0.0);
                    curvature_per_m = 0.0;
                    live = None;
                    eprintln!("{ns}/cmd_vel: no twist for {:?}, stopped", node.options.deadman);
                }
                if let Some((v, w, at)) = live && now.saturating_duration_since(at) >= COMMAND_REFRESH {
                    let _ = driver.set_command(v, w);
                    live = Some((v, w, now));
                }
                while let Some(frame) = driver.try_pop_message() {
                    let stamp = stamp_now();
                    match frame {
                        ChassisFrame::VehicleSpeed(speed) => {
                            odom.on_speed(now.duration_since(epoch).as_secs_f64(), speed.speed_mps.into(), curvature_per_m);
                            if limiter.ready(now) {
                                publish_odom(&node, &odom_writer, &tf_writer, &odom, stamp)?;
                                report.published(2);
                            }
                        }
                        ChassisFrame::BatteryVoltage(battery) => {
                            battery_writer.write(battery_state(&node, stamp, battery.volts))?;
                            report.published(1);
                        }
                        ChassisFrame::AllState(state) => {
                            diagnostics_writer.write(diagnostics(&node, stamp, &state))?;
                            report.published(1);
                        }
                        ChassisFrame::Af(_) => {}
                    }
                }
                report.set_guard(cmd_vel_guard.guard.counters());
            }
            sample = cmd_vel.recv() => {
                let sample = sample?;
                let now = Instant::now();
                if let Some((vx_mps, _, yaw_rate_radps)) = cmd_vel_guard.receive(now, &sample) {
                    if cmd_vel_guard.outcome(now, driver.set_command(vx_mps, yaw_rate_radps)) {
                        live = Some((vx_mps, yaw_rate_radps, now));
                        curvature_per_m = if vx_mps.abs() > 1e-3 { f64::from(yaw_rate_radps / vx_mps) } else { 0.0 };
                    } else {
                        live = None;
                    }
                }
                report.set_guard(cmd_vel_guard.guard.counters());
            }
        }
    }
}

fn publish_odom(
    node: &Node<'_>,
    odom_writer: &robowire_dds::Writer<Odometry>,
    tf_writer: &robowire_dds::Writer<TfMessage>,
    odom: &PlanarOdometry,
    stamp: ros2_proto::builtin::Time,
) -> Result<(), robowire_dds::DdsError> {
    let orientation = Quaternion::from_rpy(0.0, 0.0, odom.heading_rad);
    let pose = Pose { position: Point { x: odom.x_m, y: odom.y_m, z: 0.0 }, orientation };
    let twist = Twist {
        linear: Vector3 { x: odom.speed_mps, y: 0.0, z: 0.0 },
        angular: Vector3 { x: 0.0, y: 0.0, z: odom.yaw_rate_radps },
    };
    odom_writer.write(Odometry {
        header: node.header(stamp, "odom"),
        child_frame_id: node.frame("base_link"),
        pose: PoseWithCovariance { pose, ..PoseWithCovariance::default() },
        twist: TwistWithCovariance { twist, ..TwistWithCovariance::default() },
    })?;
    tf_writer.write(TfMessage {
        transforms: vec![TransformStamped {
            header: node.header(stamp, "odom"),
            child_frame_id: node.frame("base_link"),
            transform: Transform { translation: Vector3 { x: odom.x_m, y: odom.y_m, z: 0.0 }, rotation: orientation },
        }],
    })
}

fn battery_state(node: &Node<'_>, stamp: ros2_proto::builtin::Time, volts: f32) -> BatteryState {
    BatteryState { voltage: volts, ..BatteryState::unmeasured(node.header(stamp, "base_link")) }
}

fn diagnostics(node: &Node<'_>, stamp: ros2_proto::builtin::Time, state: &kmc::AllState) -> DiagnosticArray {
    let value = |key: &str, value: String| KeyValue { key: key.into(), value };
    let level = if state.error_code == 0 { DiagnosticStatus::OK } else { DiagnosticStatus::ERROR };
    DiagnosticArray {
        header: node.header(stamp, "base_link"),
        status: vec![DiagnosticStatus {
            level,
            name: format!("{}motor {}", node.frame(""), state.motor_id),
            message: if level == DiagnosticStatus::OK {
                "ok".into()
            } else {
                format!("error code {}", state.error_code)
            },
            hardware_id: format!("kmc motor {}", state.motor_id),
            values: vec![
                value("position_deg", state.position_deg.to_string()),
                value("speed_rpm", state.speed_rpm.to_string()),
                value("current_a", state.current_a.to_string()),
                value("temperature_c", state.temperature_c.to_string()),
                value("error_code", state.error_code.to_string()),
            ],
        }],
    }
}
