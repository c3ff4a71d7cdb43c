//! The one device loop: any device as a ROS 2 node. What the device observes becomes the
//! standard messages (`odom` + `tf`, `imu`, `joint_states`, `battery_state`, `diagnostics`,
//! and the vendor's own state message passed through); `cmd_vel` drives a device that is driven
//! by a velocity, through the guard; the device's named services are `std_srvs/Trigger`
//! services, each request acted on once. Nothing here knows which device it is.

use std::sync::{Arc, Mutex};
use std::time::Instant;

use tokio::sync::Notify;

use robowire_dds::qos::Qos;
use robowire_dds::{DdsError, RawSample, Writer};
use robowire_devices::{AnyDevice, BatteryReading, ImuReading, JointReadings, MotorReport, Observation, Odometry};
use ros2_proto::builtin::Time;
use ros2_proto::diagnostic::{DiagnosticArray, DiagnosticStatus, KeyValue};
use ros2_proto::geometry::{
    Point, Pose, PoseWithCovariance, Quaternion, Transform, TransformStamped, Twist, TwistWithCovariance, Vector3,
};
use ros2_proto::nav::Odometry as OdometryMsg;
use ros2_proto::sensor::{BatteryState, Imu, JointState};
use ros2_proto::tf::TfMessage;

use crate::error::BridgeError;
use crate::node::{CmdVel, Node, RateLimiter, stamp_now};
use crate::report::DeviceReport;
use crate::service::{Caller, TriggerService};

/// A topic's writer, made when the device first reports what it carries, and its rate cap.
struct Topic<T: robowire_core::cdr::CdrType + 'static> {
    writer: Option<Writer<T>>,
    limiter: RateLimiter,
}

impl<T: robowire_core::cdr::CdrType + 'static> Topic<T> {
    fn new(node: &Node<'_>) -> Self {
        Self { writer: None, limiter: node.limiter() }
    }

    /// Writes `message()` if the rate cap lets it through; the samples written.
    fn publish(
        &mut self,
        node: &Node<'_>,
        name: &str,
        qos: Qos,
        now: Instant,
        message: impl FnOnce() -> T,
    ) -> Result<u64, DdsError> {
        if !self.limiter.ready(now) {
            return Ok(0);
        }
        let writer = match &mut self.writer {
            Some(writer) => writer,
            none => none.insert(node.writer(name, qos)?),
        };
        writer.write(message())?;
        Ok(1)
    }
}

/// The topics of one device.
struct Topics {
    odom: Topic<OdometryMsg>,
    tf: Topic<TfMessage>,
    imu: Topic<Imu>,
    joints: Topic<JointState>,
    battery: Topic<BatteryState>,
    diagnostics: Topic<DiagnosticArray>,
    passthrough: Option<(Writer<RawSample>, RateLimiter)>,
}

/// A driven device's `cmd_vel`: its guard, shared by the reader's listener (on the participant's
/// receive thread: the twist reaches the device with no task to wake) and the deadman timer (in
/// the device loop). The lock is held across the device call, so a deadman stop and a new twist
/// never interleave.
struct Drive {
    cmd_vel: Mutex<CmdVel>,
    device: Arc<AnyDevice>,
    report: Arc<DeviceReport>,
    /// Told when a twist makes a command live, so that the loop arms its deadman timer.
    live: Notify,
}

impl Drive {
    /// A twist from the network, on the listener's thread.
    fn on_twist(&self, sample: &robowire_dds::Sample<Twist>) {
        let now = Instant::now();
        let mut cmd_vel = robowire_rt::lock(&self.cmd_vel);
        let idle = cmd_vel.guard.deadline().is_none();
        if let Some((vx_mps, vy_mps, yaw_rate_radps)) = cmd_vel.receive(now, sample) {
            cmd_vel.outcome(now, self.device.drive(vx_mps, vy_mps, yaw_rate_radps));
        }
        self.report.set_guard(cmd_vel.guard.counters());
        if idle && cmd_vel.guard.deadline().is_some() {
            self.live.notify_one();
        }
    }

    /// When the live command goes stale, if one is live.
    fn deadline(&self) -> Option<Instant> {
        robowire_rt::lock(&self.cmd_vel).guard.deadline()
    }

    /// The deadman timer fired: stops the device if the command is stale by now.
    fn on_deadline(&self, namespace: &str, deadman: std::time::Duration) {
        let mut cmd_vel = robowire_rt::lock(&self.cmd_vel);
        if cmd_vel.guard.on_tick(Instant::now()) {
            if let Err(e) = self.device.stop_motion() {
                eprintln!("{namespace}/cmd_vel: the deadman stop was refused: {}", robowire_devices::error_chain(&e));
            }
            eprintln!("{namespace}/cmd_vel: no twist for {deadman:?}, stopped");
        }
        self.report.set_guard(cmd_vel.guard.counters());
    }
}

/// Bridges `device` until `stop` resolves.
pub(crate) async fn run(
    node: Node<'_>,
    device: Arc<AnyDevice>,
    report: Arc<DeviceReport>,
    stop: impl Future<Output = ()>,
) -> Result<(), BridgeError> {
    let mut topics = Topics {
        odom: Topic::new(&node),
        tf: Topic::new(&node),
        imu: Topic::new(&node),
        joints: Topic::new(&node),
        battery: Topic::new(&node),
        diagnostics: Topic::new(&node),
        passthrough: None,
    };
    let drive = if device.can_drive() {
        // The guard's deadman stops the robot; the device's own command timeout is set to it, so
        // that nothing needs to refresh a live command.
        let refused = |source| BridgeError::Device { address: device.address().clone(), source };
        device.set_drive_timeout(node.options.deadman).map_err(refused)?;
        let reader = node.reader::<Twist>("cmd_vel", Qos::ROS_DEFAULT)?;
        let drive = Arc::new(Drive {
            cmd_vel: Mutex::new(CmdVel::new(&node.options)),
            device: device.clone(),
            report: report.clone(),
            live: Notify::new(),
        });
        let listener = reader.listen({
            let drive = drive.clone();
            move |sample| drive.on_twist(&sample)
        });
        Some((drive, listener))
    } else {
        None
    };
    let ns = node.options.namespace.clone();
    let mut services: Vec<TriggerService> =
        device.services().iter().map(|name| TriggerService::new(&node, name)).collect::<Result<_, _>>()?;
    for service in &services {
        report.watch_requests(service.requests_stats());
    }
    let mut observations = device.observations();
    tokio::pin!(stop);
    loop {
        let deadman = drive.as_ref().and_then(|(d, _)| d.deadline()).map(tokio::time::Instant::from_std);
        tokio::select! {
            () = &mut stop => return Ok(()),
            observation = observations.next() => {
                let Some(observation) = observation else { return Ok(()) };
                let published = publish(&node, &mut topics, &observation, stamp_now())?;
                report.published(published);
            }
            () = made_live(drive.as_ref().map(|(d, _)| &**d)), if deadman.is_none() => {}
            () = async { tokio::time::sleep_until(deadman.unwrap_or_else(tokio::time::Instant::now)).await }, if deadman.is_some() => {
                if let Some((drive, _)) = &drive {
                    drive.on_deadline(&ns, node.options.deadman);
                }
            }
            (i, request) = next_request(&mut services), if !services.is_empty() => {
                let caller = Caller::of(&request?);
                let service = &mut services[i];
                if let Some(sent) = service.answer_again(caller) {
                    sent.await?;
                } else {
                    let (success, message) = match device.call(service.name) {
                        Ok(said) => (true, said),
                        Err(e) => (false, robowire_devices::error_chain(&e)),
                    };
                    service.reply(caller, success, message).await?;
                    report.service_call();
                }
            }
        }
    }
}

/// A twist made a command live (never, for a device not driven).
async fn made_live(drive: Option<&Drive>) {
    match drive {
        Some(drive) => drive.live.notified().await,
        None => std::future::pending().await,
    }
}

/// The first request of any of the services (at least one).
async fn next_request(
    services: &mut [TriggerService],
) -> (usize, Result<robowire_dds::Sample<ros2_proto::srv::AnyTriggerRequest>, DdsError>) {
    let waits = services.iter_mut().map(|s| Box::pin(s.requests.recv()));
    let (result, i, _) = futures::future::select_all(waits).await;
    (i, result)
}

fn vector(v: [f64; 3]) -> Vector3 {
    Vector3 { x: v[0], y: v[1], z: v[2] }
}

fn quaternion(xyzw: [f64; 4]) -> Quaternion {
    Quaternion { x: xyzw[0], y: xyzw[1], z: xyzw[2], w: xyzw[3] }
}

/// Publishes every part of `observation`; the samples written.
fn publish(node: &Node<'_>, topics: &mut Topics, observation: &Observation, stamp: Time) -> Result<u64, DdsError> {
    let now = Instant::now();
    let mut published = 0;
    if let Some(o) = &observation.odometry {
        published += topics.odom.publish(node, "odom", Qos::ROS_DEFAULT, now, || odometry(node, o, stamp))?;
        published += topics.tf.publish(node, "tf", Qos::ROS_DEFAULT, now, || transform(node, o, stamp))?;
    }
    if let Some(imu) = &observation.imu {
        published += topics.imu.publish(node, "imu", Qos::ROS_SENSOR_DATA, now, || imu_message(node, imu, stamp))?;
    }
    if let Some(joints) = &observation.joints {
        let message = || joint_state(node, joints, stamp);
        published += topics.joints.publish(node, "joint_states", Qos::ROS_SENSOR_DATA, now, message)?;
    }
    if let Some(battery) = &observation.battery {
        let message = || battery_state(node, battery, stamp);
        published += topics.battery.publish(node, "battery_state", Qos::ROS_SENSOR_DATA, now, message)?;
    }
    if !observation.motors.is_empty() {
        let message = || diagnostics(node, &observation.motors, stamp);
        published += topics.diagnostics.publish(node, "diagnostics", Qos::ROS_DEFAULT, now, message)?;
    }
    if let Some(raw) = &observation.passthrough {
        let (writer, limiter) = match &mut topics.passthrough {
            Some(made) => made,
            none => none.insert((
                node.listed_writer(node.participant.raw_writer(
                    &ros2_proto::topic(&node.options.namespace, raw.topic),
                    raw.type_name,
                    Qos::ROS_SENSOR_DATA,
                )?)?,
                node.limiter(),
            )),
        };
        if limiter.ready(now) {
            writer.write(RawSample { encoding: robowire_core::cdr::CdrEncoding::Xcdr1, body: raw.body.clone() })?;
            published += 1;
        }
    }
    Ok(published)
}

fn odometry(node: &Node<'_>, o: &Odometry, stamp: Time) -> OdometryMsg {
    let p = o.position_m;
    let pose = Pose { position: Point { x: p[0], y: p[1], z: p[2] }, orientation: quaternion(o.orientation_xyzw) };
    let twist = Twist { linear: vector(o.linear_mps), angular: vector(o.angular_radps) };
    OdometryMsg {
        header: node.header(stamp, "odom"),
        child_frame_id: node.frame("base_link"),
        pose: PoseWithCovariance { pose, ..PoseWithCovariance::default() },
        twist: TwistWithCovariance { twist, ..TwistWithCovariance::default() },
    }
}

fn transform(node: &Node<'_>, o: &Odometry, stamp: Time) -> TfMessage {
    TfMessage {
        transforms: vec![TransformStamped {
            header: node.header(stamp, "odom"),
            child_frame_id: node.frame("base_link"),
            transform: Transform { translation: vector(o.position_m), rotation: quaternion(o.orientation_xyzw) },
        }],
    }
}

fn imu_message(node: &Node<'_>, imu: &ImuReading, stamp: Time) -> Imu {
    Imu {
        header: node.header(stamp, "imu_link"),
        orientation: quaternion(imu.orientation_xyzw),
        orientation_covariance: [0.0; 9],
        angular_velocity: vector(imu.gyro_radps),
        angular_velocity_covariance: [0.0; 9],
        linear_acceleration: vector(imu.acc_mps2),
        linear_acceleration_covariance: [0.0; 9],
    }
}

fn joint_state(node: &Node<'_>, joints: &JointReadings, stamp: Time) -> JointState {
    JointState {
        header: node.header(stamp, "base_link"),
        name: joints.names.clone(),
        position: joints.position_rad.clone(),
        velocity: joints.velocity_radps.clone(),
        effort: joints.effort_nm.clone(),
    }
}

/// What the device does not measure is NaN, as `sensor_msgs/BatteryState` specifies.
fn battery_state(node: &Node<'_>, battery: &BatteryReading, stamp: Time) -> BatteryState {
    let unmeasured = BatteryState::unmeasured(node.header(stamp, "base_link"));
    BatteryState {
        voltage: battery.voltage_v.unwrap_or(unmeasured.voltage),
        current: battery.current_a.unwrap_or(unmeasured.current),
        percentage: battery.charge_fraction.unwrap_or(unmeasured.percentage),
        cell_voltage: battery.cells_v.clone(),
        ..unmeasured
    }
}

fn diagnostics(node: &Node<'_>, motors: &[MotorReport], stamp: Time) -> DiagnosticArray {
    DiagnosticArray {
        header: node.header(stamp, "base_link"),
        status: motors
            .iter()
            .map(|m| DiagnosticStatus {
                level: if m.ok { DiagnosticStatus::OK } else { DiagnosticStatus::ERROR },
                name: format!("{}{}", node.frame(""), m.name),
                message: m.message.clone(),
                hardware_id: m.hardware_id.clone(),
                values: m
                    .values
                    .iter()
                    .map(|(key, value)| KeyValue { key: key.clone(), value: value.clone() })
                    .collect(),
            })
            .collect(),
    }
}
