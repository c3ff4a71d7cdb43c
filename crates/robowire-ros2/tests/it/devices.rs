//! Devices on their topics: a CycloneDDS peer drives, senses and calls services on a simulated
//! chassis and dog; unarmed, nothing moves; a Go2's and a G1's joints, IMU, battery and their
//! vendor's state passed through, read by the peer with Unitree's classes and by robowire's DDS.

use std::time::Duration;

use robowire_dds::netns::with_loopback_multicast;

use crate::{Bridge, WAIT, f, interop_python, options, peer};

/// The deadman time given to the bridge, and the time a robot needs to coast to a stop.
const DEADMAN_S: f64 = 0.5;
const SETTLE_S: f64 = 1.0;

#[test]
fn a_cyclonedds_peer_drives_senses_and_calls_services_on_two_devices() {
    let Some(python) = interop_python() else { return };
    with_loopback_multicast(|| {
        let bridge = Bridge::start(robowire_ros2::BridgeOptions {
            armed: true,
            deadman: Duration::from_secs_f64(DEADMAN_S),
            ..options(&["sim:kmc", "sim:zsl1"])
        });

        let kmc = peer(&python, "drive", "/kmc0");
        assert!(f(&kmc["max_speed"]) > 0.4, "the chassis reached the commanded 0.5 m/s: {kmc}");
        assert!(f(&kmc["moved_m"]) > 0.3, "and moved forward in odom: {kmc}");
        let still = f(&kmc["still_after_s"]);
        assert!(still <= DEADMAN_S + SETTLE_S, "stopped within the deadman time and the coast: {kmc}");
        assert_eq!(kmc["frame_id"], "kmc0/odom");
        assert_eq!(kmc["child_frame_id"], "kmc0/base_link");

        let chassis = peer(&python, "sense_chassis", "/kmc0");
        let volts = f(&chassis["battery"]["voltage"]);
        assert!((20.0..=26.0).contains(&volts), "the simulated pack: {chassis}");
        assert!(chassis["battery"]["percentage"].is_null(), "not reported by the chassis: {chassis}");
        let status = &chassis["diagnostics"]["status"][0];
        assert_eq!(status["level"], 0, "{chassis}");
        assert!(status["name"].as_str().unwrap().starts_with("kmc0/motor "), "{chassis}");
        let keys: Vec<&str> =
            status["values"].as_array().unwrap().iter().map(|kv| kv["key"].as_str().unwrap()).collect();
        assert_eq!(keys, ["position_deg", "speed_rpm", "current_a", "temperature_c", "error_code"]);

        let dog = peer(&python, "stand_and_drive", "/zsl1_0");
        assert_eq!(dog["stand_up"]["success"], true, "{dog}");
        assert_eq!(dog["stand_up"]["guid_matches"], true, "the reply carries the request's header: {dog}");
        assert_eq!(dog["stand_up"]["seq"], 1);
        assert!(f(&dog["max_speed"]) > 0.4, "the dog walked: {dog}");
        assert!(f(&dog["still_after_s"]) <= DEADMAN_S + SETTLE_S, "and stopped: {dog}");

        let seen = peer(&python, "sense", "/zsl1_0");
        let joints = &seen["joint_states"];
        let names: Vec<&str> = joints["name"].as_array().unwrap().iter().map(|n| n.as_str().unwrap()).collect();
        assert_eq!(names.len(), 12);
        assert_eq!(names[..3], ["FR_abad", "FR_hip", "FR_knee"]);
        assert_eq!(names[9..], ["RL_abad", "RL_hip", "RL_knee"]);
        let position: Vec<f64> = joints["position"].as_array().unwrap().iter().map(f).collect();
        assert_eq!(position.len(), 12);
        assert!(position.chunks(3).all(|leg| leg == &position[..3]), "four legs in one pose: {position:?}");
        assert!(position[2] < -0.5, "a folded knee: {position:?}");
        assert_eq!(joints["header"]["frame_id"], "zsl1_0/base_link");
        let imu = &seen["imu"];
        assert_eq!(f(&imu["linear_acceleration"]["z"]), f64::from(9.81f32), "gravity, the f32 the dog sent");
        assert_eq!(f(&imu["orientation"]["w"]), 1.0);
        assert_eq!(imu["header"]["frame_id"], "zsl1_0/imu_link");
        assert!(imu["header"]["stamp"]["sec"].as_i64().unwrap() > 1_600_000_000, "wall-clock stamps");
        let battery = &seen["battery_state"];
        assert!((0.0..=1.0).contains(&f(&battery["percentage"])), "{battery}");
        assert!(battery["voltage"].is_null(), "not measured by the dog: NaN, as ROS specifies: {battery}");
        let tf = &seen["tf"]["transforms"][0];
        assert_eq!(
            (&tf["header"]["frame_id"], &tf["child_frame_id"]),
            (&"zsl1_0/odom".into(), &"zsl1_0/base_link".into())
        );

        let devices = bridge.stop();
        let (kmc, dog) = (&devices[0], &devices[1]);
        assert_eq!((kmc.namespace.as_str(), dog.namespace.as_str()), ("/kmc0", "/zsl1_0"));
        for device in [kmc, dog] {
            let cmd_vel = device.counters().cmd_vel;
            assert!(cmd_vel.applied > 10, "{device:?}");
            assert_eq!(cmd_vel.deadman_stops, 1, "{device:?}");
            assert_eq!(cmd_vel.unarmed, 0);
        }
        assert_eq!(dog.counters().service_calls, 1, "the one stand_up");
    });
}

#[test]
fn unarmed_the_same_cmd_vel_moves_nothing() {
    let Some(python) = interop_python() else { return };
    with_loopback_multicast(|| {
        let bridge = Bridge::start(options(&["sim:kmc"]));
        let seen = peer(&python, "drive", "");
        assert_eq!(f(&seen["max_speed"]), 0.0, "{seen}");
        assert_eq!(f(&seen["moved_m"]), 0.0, "{seen}");
        let cmd_vel = bridge.stop()[0].counters().cmd_vel;
        assert!(cmd_vel.received > 10, "the twists arrived: {cmd_vel:?}");
        assert_eq!(cmd_vel.unarmed, cmd_vel.received);
        assert_eq!(cmd_vel.applied, 0);
    });
}

#[test]
fn a_go2_publishes_joint_states_and_passes_lowstate_through() {
    let Some(python) = interop_python() else { return };
    with_loopback_multicast(|| {
        let bridge = Bridge::start(robowire_ros2::BridgeOptions {
            interface: Some("lo".into()),
            namespace: Some("dog".into()),
            ..options(&["sim:go2"])
        });
        let seen = peer(&python, "sense_go2", "/dog");
        let names: Vec<&str> = seen["names"].as_array().unwrap().iter().map(|n| n.as_str().unwrap()).collect();
        assert_eq!(names[..3], ["FR_hip_joint", "FR_thigh_joint", "FR_calf_joint"]);
        assert_eq!(names.len(), 12);
        assert_eq!(seen["crc_ok"], true, "Unitree's CRC accepts the passed-through LowState: {seen}");
        // The same LowState's joints (f32) on both topics, as f64 on joint_states.
        let q =
            |key: &str| seen[key].as_array().unwrap().iter().map(|v| v.as_f64().unwrap() as f32).collect::<Vec<_>>();
        assert_eq!(q("position").len(), 12);
        assert!(q("position").iter().zip(q("lowstate_q")).all(|(a, b)| (a - b).abs() < 0.05), "{seen}");
        assert_eq!(seen["imu_w"].as_f64().unwrap() as f32, seen["lowstate_quaternion_w"].as_f64().unwrap() as f32);
        let devices = bridge.stop();
        assert!(devices[0].counters().published > 100);
        assert_eq!(devices[0].namespace, "/dog");
    });
}

#[test]
fn a_g1_publishes_its_joints_by_name_its_battery_and_passes_its_hg_lowstate_through() {
    use robowire_dds::qos::Qos;
    use robowire_dds::{Participant, ParticipantOptions};
    use ros2_proto::sensor::{BatteryState, Imu, JointState};
    use unitree_proto::HgLowState;

    with_loopback_multicast(|| {
        let bridge = Bridge::start(robowire_ros2::BridgeOptions {
            interface: Some("lo".into()),
            namespace: Some("g1".into()),
            ..options(&["sim:g1"])
        });
        robowire_fixtures::wait::runtime().block_on(async {
            let participant = Participant::new(ParticipantOptions::new(0, Some("lo"))).unwrap();
            let mut joints = participant.reader::<JointState>("rt/g1/joint_states", Qos::ROS_SENSOR_DATA).unwrap();
            let mut battery = participant.reader::<BatteryState>("rt/g1/battery_state", Qos::ROS_SENSOR_DATA).unwrap();
            let mut imu = participant.reader::<Imu>("rt/g1/imu", Qos::ROS_SENSOR_DATA).unwrap();
            // robowire's HG codec: a LowState whose CRC does not match is not read.
            let mut lowstate = participant.reader::<HgLowState>("rt/g1/lowstate", Qos::ROS_SENSOR_DATA).unwrap();
            let low = tokio::time::timeout(WAIT, lowstate.recv()).await.expect("rt/g1/lowstate").unwrap().value;
            assert_eq!(low.mode_machine, 5);
            let joints = tokio::time::timeout(WAIT, joints.recv()).await.expect("joint_states").unwrap().value;
            assert_eq!(joints.name, unitree::g1::JOINT_NAMES);
            assert_eq!(joints.header.frame_id, "g1/base_link");
            let q = |slot: usize| low.motor_state[slot].q.get();
            assert!(joints.position.iter().enumerate().all(|(i, p)| (*p as f32 - q(i)).abs() < 0.05), "{joints:?}");
            let battery = tokio::time::timeout(WAIT, battery.recv()).await.expect("battery_state").unwrap().value;
            assert!((0.5..=1.0).contains(&battery.percentage), "{battery:?}");
            assert_eq!(battery.cell_voltage.len(), 13, "{battery:?}");
            assert!(battery.voltage > 40.0 && battery.current < 0.0, "{battery:?}");
            let imu = tokio::time::timeout(WAIT, imu.recv()).await.expect("imu").unwrap().value;
            assert_eq!(imu.linear_acceleration.z, f64::from(9.81f32), "gravity, the f32 the robot sent");
            let type_of = |name: &str| {
                let topics = participant.discovered_topics();
                topics.iter().find(|t| t.name == name).map(|t| t.type_name.clone()).unwrap_or_default()
            };
            assert_eq!(type_of("rt/g1/lowstate"), "unitree_hg::msg::dds_::LowState_");
            assert_eq!(type_of("rt/g1/joint_states"), "sensor_msgs::msg::dds_::JointState_");
            assert_eq!(type_of("rt/g1/battery_state"), "sensor_msgs::msg::dds_::BatteryState_");
            // 40 more LowStates passed through: each came with its joint_states and imu, so the
            // bridge has published more than 100 samples, however slowly this machine ran.
            for _ in 0..40 {
                tokio::time::timeout(WAIT, lowstate.recv()).await.expect("rt/g1/lowstate").unwrap();
            }
        });
        let devices = bridge.stop();
        assert!(devices[0].counters().published > 100, "{devices:?}");
    });
}

#[test]
fn a_cyclonedds_peer_reads_a_g1_with_unitrees_hg_classes() {
    let Some(python) = interop_python() else { return };
    with_loopback_multicast(|| {
        let bridge = Bridge::start(robowire_ros2::BridgeOptions {
            interface: Some("lo".into()),
            namespace: Some("g1".into()),
            ..options(&["sim:g1"])
        });
        let seen = peer(&python, "sense_g1", "/g1");
        let names: Vec<&str> = seen["names"].as_array().unwrap().iter().map(|n| n.as_str().unwrap()).collect();
        assert_eq!(names, unitree::g1::JOINT_NAMES);
        assert_eq!(seen["crc_ok"], true, "Unitree's CRC accepts the passed-through HG LowState: {seen}");
        assert_eq!(seen["mode_machine"], 5);
        let q =
            |key: &str| seen[key].as_array().unwrap().iter().map(|v| v.as_f64().unwrap() as f32).collect::<Vec<_>>();
        assert!(q("position").iter().zip(q("lowstate_q")).all(|(a, b)| (a - b).abs() < 0.05), "{seen}");
        let battery = &seen["battery"];
        assert!((0.5..=1.0).contains(&f(&battery["percentage"])), "{battery}");
        assert_eq!(battery["cell_voltage"].as_array().map(Vec::len), Some(13), "{battery}");
        bridge.stop();
    });
}
