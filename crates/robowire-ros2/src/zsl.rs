//! A ZSL-1 / ZSL-1W (HighLevel over UDP) as a ROS 2 node: `cmd_vel` → `move`, `odom`, `tf`,
//! `imu`, `joint_states`, `battery_state` at the state's rate, services `stand_up`, `lie_down`,
//! `passive`.

use std::time::Instant;

use robowire_dds::qos::Qos;
use ros2_proto::builtin::Time;
use ros2_proto::geometry::PoseWithCovariance;
use ros2_proto::geometry::{Point, Pose, Quaternion, Transform, TransformStamped, Twist, TwistWithCovariance, Vector3};
use ros2_proto::nav::Odometry;
use ros2_proto::sensor::{BatteryState, Imu, JointState};
use ros2_proto::tf::TfMessage;
use zsl::udp::{CallError, HighLevel, Model, RobotState};

use crate::node::{CmdVel, Node, stamp_now};
use crate::report::DeviceReport;
use crate::service::TriggerService;

/// Joint names, `[leg][joint]` order of the state: FR, FL, RR, RL × abad, hip, knee (+ foot).
fn joint_names(model: Model) -> Vec<String> {
    let joints: &[&str] =
        if model == Model::Zsl1W { &["abad", "hip", "knee", "foot"] } else { &["abad", "hip", "knee"] };
    ["FR", "FL", "RR", "RL"].iter().flat_map(|leg| joints.iter().map(move |j| format!("{leg}_{j}"))).collect()
}

/// The topics of one dog.
struct Topics {
    odom: robowire_dds::Writer<Odometry>,
    tf: robowire_dds::Writer<TfMessage>,
    imu: robowire_dds::Writer<Imu>,
    joints: robowire_dds::Writer<JointState>,
    battery: robowire_dds::Writer<BatteryState>,
}

/// Bridges `dog` until `stop` resolves.
pub(crate) async fn run(
    node: Node<'_>,
    dog: &HighLevel,
    model: Model,
    report: &DeviceReport,
    stop: impl Future<Output = ()>,
) -> Result<(), robowire_dds::DdsError> {
    let topics = Topics {
        odom: node.writer("odom", Qos::ROS_DEFAULT)?,
        tf: node.writer("tf", Qos::ROS_DEFAULT)?,
        imu: node.writer("imu", Qos::ROS_SENSOR_DATA)?,
        joints: node.writer("joint_states", Qos::ROS_SENSOR_DATA)?,
        battery: node.writer("battery_state", Qos::ROS_SENSOR_DATA)?,
    };
    let mut cmd_vel = node.reader::<Twist>("cmd_vel", Qos::ROS_DEFAULT)?;
    let ns = node.options.namespace.clone();
    let mut services = [
        TriggerService::new(node.participant, &ns, "stand_up")?,
        TriggerService::new(node.participant, &ns, "lie_down")?,
        TriggerService::new(node.participant, &ns, "passive")?,
    ];
    let mut cmd_vel_guard = CmdVel::new(&node.options);
    let mut updates = dog.state_updates();
    let mut limiter = node.limiter();
    let names = joint_names(model);
    tokio::pin!(stop);
    loop {
        let deadman = cmd_vel_guard.guard.deadline().map(tokio::time::Instant::from_std);
        tokio::select! {
            () = &mut stop => return Ok(()),
            changed = updates.changed() => {
                if changed.is_err() {
                    return Ok(());
                }
                let state = updates.borrow_and_update().as_ref().map(RobotState::from);
                if let Some(state) = state && limiter.ready(Instant::now()) {
                    publish(&node, &topics, &names, model, &state, stamp_now())?;
                    report.published(5);
                }
            }
            sample = cmd_vel.recv() => {
                let sample = sample?;
                let now = Instant::now();
                if let Some((vx_mps, vy_mps, yaw_rate_radps)) = cmd_vel_guard.receive(now, &sample) {
                    // Not yet acknowledged is still queued: the vendor's 0 for the first ten.
                    let result = match dog.move_velocity(vx_mps, vy_mps, yaw_rate_radps).await {
                        Err(CallError::NotAcknowledged { .. }) => Ok(()),
                        other => other,
                    };
                    cmd_vel_guard.outcome(now, result);
                }
                report.set_guard(cmd_vel_guard.guard.counters());
            }
            () = async { tokio::time::sleep_until(deadman.unwrap_or_else(tokio::time::Instant::now)).await }, if deadman.is_some() => {
                if cmd_vel_guard.guard.on_tick(Instant::now()) {
                    let _ = dog.move_velocity(0.0, 0.0, 0.0).await;
                    eprintln!("{ns}/cmd_vel: no twist for {:?}, stopped", node.options.deadman);
                }
                report.set_guard(cmd_vel_guard.guard.counters());
            }
            (i, request) = next_request(&mut services) => {
                let request = request?.value;
                let service = &services[i];
                let outcome = match service.name {
                    "stand_up" => dog.stand_up().await,
                    "lie_down" => dog.lie_down().await,
                    _ => dog.passive().await,
                };
                let (success, message) = match outcome {
                    Ok(()) | Err(CallError::NotAcknowledged { .. }) => (true, format!("{} sent", service.name)),
                    Err(e) => {
                        let code = e.return_code();
                        (false, format!("{code:?} (0x{:x}): {e}", code.raw()))
                    }
                };
                service.reply(&request, success, message)?;
                report.service_call();
            }
        }
    }
}

/// The first request of any of the services.
async fn next_request(
    services: &mut [TriggerService; 3],
) -> (usize, Result<robowire_dds::Sample<ros2_proto::srv::TriggerRequest>, robowire_dds::DdsError>) {
    let [a, b, c] = services;
    tokio::select! {
        r = a.requests.recv() => (0, r),
        r = b.requests.recv() => (1, r),
        r = c.requests.recv() => (2, r),
    }
}

fn vector(v: [f32; 3]) -> Vector3 {
    Vector3 { x: v[0].into(), y: v[1].into(), z: v[2].into() }
}

fn quaternion(wxyz: [f32; 4]) -> Quaternion {
    Quaternion { x: wxyz[1].into(), y: wxyz[2].into(), z: wxyz[3].into(), w: wxyz[0].into() }
}

fn publish(
    node: &Node<'_>,
    topics: &Topics,
    names: &[String],
    model: Model,
    state: &RobotState,
    stamp: Time,
) -> Result<(), robowire_dds::DdsError> {
    let body = &state.body;
    let p = body.position_m;
    let orientation = quaternion(body.imu.quaternion_wxyz);
    let pose = Pose { position: Point { x: p[0].into(), y: p[1].into(), z: p[2].into() }, orientation };
    let twist = Twist { linear: vector(body.body_velocity_mps), angular: vector(body.imu.gyro_radps) };
    topics.odom.write(Odometry {
        header: node.header(stamp, "odom"),
        child_frame_id: node.frame("base_link"),
        pose: PoseWithCovariance { pose, ..PoseWithCovariance::default() },
        twist: TwistWithCovariance { twist, ..TwistWithCovariance::default() },
    })?;
    topics.tf.write(TfMessage {
        transforms: vec![TransformStamped {
            header: node.header(stamp, "odom"),
            child_frame_id: node.frame("base_link"),
            transform: Transform {
                translation: Vector3 { x: pose.position.x, y: pose.position.y, z: pose.position.z },
                rotation: orientation,
            },
        }],
    })?;
    topics.imu.write(Imu {
        header: node.header(stamp, "imu_link"),
        orientation,
        orientation_covariance: [0.0; 9],
        angular_velocity: vector(body.imu.gyro_radps),
        angular_velocity_covariance: [0.0; 9],
        linear_acceleration: vector(body.imu.acc_mps2),
        linear_acceleration_covariance: [0.0; 9],
    })?;
    let joints = &state.joints;
    let per_leg = if model == Model::Zsl1W { 4 } else { 3 };
    let column = |a: &zsl::udp::JointArrays| -> Vec<f64> {
        (0..4)
            .flat_map(|leg| [a.abad[leg], a.hip[leg], a.knee[leg], a.foot[leg]].into_iter().take(per_leg))
            .map(f64::from)
            .collect()
    };
    topics.joints.write(JointState {
        header: node.header(stamp, "base_link"),
        name: names.to_vec(),
        position: column(&joints.position_rad),
        velocity: column(&joints.velocity_radps),
        effort: column(&joints.torque_nm),
    })?;
    topics.battery.write(BatteryState {
        percentage: body.battery_percent as f32 / 100.0,
        ..BatteryState::unmeasured(node.header(stamp, "base_link"))
    })?;
    Ok(())
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
