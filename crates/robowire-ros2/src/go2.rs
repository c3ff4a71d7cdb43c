//! A Unitree Go2 as a ROS 2 node: `joint_states`, `imu`, `battery_state` from LowState, and
//! `lowstate` passed through as `unitree_go/msg/LowState` (what unitree_ros2 users subscribe
//! to). The Go2 bridge only publishes: low-level commands are not a `cmd_vel`.

use std::time::{Duration, Instant};

use go2::{GO2_JOINT_NAMES, Go2, LowLevel, LowState};
use robowire_dds::qos::Qos;
use ros2_proto::geometry::{Quaternion, Vector3};
use ros2_proto::sensor::{BatteryState, Imu, JointState};

use crate::node::{Node, stamp_now};
use crate::report::DeviceReport;

/// Bridges `robot` until `stop` resolves.
pub(crate) async fn run(
    node: Node<'_>,
    robot: &LowLevel<Go2>,
    report: &DeviceReport,
    stop: impl Future<Output = ()>,
) -> Result<(), robowire_dds::DdsError> {
    let joints_writer = node.writer::<JointState>("joint_states", Qos::ROS_SENSOR_DATA)?;
    let imu_writer = node.writer::<Imu>("imu", Qos::ROS_SENSOR_DATA)?;
    let battery_writer = node.writer::<BatteryState>("battery_state", Qos::ROS_SENSOR_DATA)?;
    let lowstate_writer = node.writer::<LowState>("lowstate", Qos::ROS_SENSOR_DATA)?;
    let names: Vec<String> = GO2_JOINT_NAMES.iter().map(|n| format!("{n}_joint")).collect();
    let mut limiter = node.limiter();
    let mut last_tick = None;
    tokio::pin!(stop);
    loop {
        let next = robot.wait_state(Duration::from_millis(100), |s| Some(s.tick.get()) != last_tick);
        let state = tokio::select! {
            () = &mut stop => return Ok(()),
            state = next => state,
        };
        let Some(state) = state else { continue };
        last_tick = Some(state.tick.get());
        if !limiter.ready(Instant::now()) {
            continue;
        }
        let stamp = stamp_now();
        let motors = &state.motor_state[..12];
        joints_writer.write(JointState {
            header: node.header(stamp, "base_link"),
            name: names.clone(),
            position: motors.iter().map(|m| f64::from(m.q.get())).collect(),
            velocity: motors.iter().map(|m| f64::from(m.dq.get())).collect(),
            effort: motors.iter().map(|m| f64::from(m.tau_est.get())).collect(),
        })?;
        let imu = &state.imu_state;
        let [w, x, y, z] = imu.quaternion.map(|v| f64::from(v.get()));
        let vector =
            |v: [lowcmd_proto::F32; 3]| Vector3 { x: v[0].get().into(), y: v[1].get().into(), z: v[2].get().into() };
        imu_writer.write(Imu {
            header: node.header(stamp, "imu_link"),
            orientation: Quaternion { x, y, z, w },
            orientation_covariance: [0.0; 9],
            angular_velocity: vector(imu.gyroscope),
            angular_velocity_covariance: [0.0; 9],
            linear_acceleration: vector(imu.accelerometer),
            linear_acceleration_covariance: [0.0; 9],
        })?;
        let bms = &state.bms_state;
        battery_writer.write(BatteryState {
            voltage: state.power_v.get(),
            current: state.power_a.get(),
            percentage: f32::from(bms.soc) / 100.0,
            cell_voltage: bms.cell_vol.iter().map(|mv| f32::from(mv.get()) / 1000.0).collect(),
            ..BatteryState::unmeasured(node.header(stamp, "base_link"))
        })?;
        lowstate_writer.write(state)?;
        report.published(4);
    }
}
