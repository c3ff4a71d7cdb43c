//! `robowire ros2` against a ROS 2 peer on CycloneDDS (the `cyclonedds` Python binding 0.10.2
//! with the ROS 2 message types declared under their ROS 2 DDS names, `tests/ros2_interop/`),
//! where loopback carries multicast (`robowire_dds::netns`): the peer drives a simulated chassis
//! and dog through `cmd_vel`, sees them move on `odom` and stop after the deadman time, reads
//! `joint_states`, `imu`, `battery_state` and `tf` field for field, calls `stand_up` in
//! rmw_cyclonedds' request/reply format; unarmed, the same `cmd_vel` moves nothing. A simulated
//! G1's topics are read by that peer (Unitree's HG classes) and by robowire's own DDS readers.
//! The bridge's nodes on `ros_discovery_info` (Jazzy's and Humble's GID sizes) are read by that
//! peer and by robowire's own DDS, each GID matched to the GUID DDS discovery reports for the
//! bridge's endpoint; a Humble bridge warns once of a Jazzy peer. ros2-client (an independent
//! ROS 2 client library, no Python) calls `stand_up` in rmw_fastrtps' and rmw_cyclonedds'
//! service mappings; a request of neither shape is counted and not answered.

use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};

use robowire_dds::netns::with_loopback_multicast;
use serde_json::Value;

/// `robowire ros2 ARGS`, started and waited for (its "ready" line), and its log since.
struct Bridge(Child, Arc<Mutex<String>>);

impl Bridge {
    fn start(args: &[&str]) -> Self {
        let mut child = Command::new(env!("CARGO_BIN_EXE_robowire"))
            .arg("ros2")
            .args(args)
            .arg("--json")
            .env_remove("ROS_DISTRO")
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut stderr = BufReader::new(child.stderr.take().unwrap());
        let mut line = String::new();
        loop {
            line.clear();
            assert!(stderr.read_line(&mut line).unwrap() > 0, "robowire ros2 ended before it was ready");
            if line.starts_with("ros2: ready") {
                break;
            }
        }
        // Keep draining its log so that it never blocks on a full pipe.
        let log = Arc::new(Mutex::new(String::new()));
        let kept = log.clone();
        std::thread::spawn(move || {
            let mut line = String::new();
            while stderr.read_line(&mut line).is_ok_and(|n| n > 0) {
                kept.lock().unwrap().push_str(&std::mem::take(&mut line));
            }
        });
        Self(child, log)
    }

    /// Ctrl-C: it stops (and exits).
    fn interrupt(&self) {
        rustix::process::kill_process(rustix::process::Pid::from_child(&self.0), rustix::process::Signal::INT).unwrap();
    }

    /// What it has written on stderr since it was ready.
    fn log(&self) -> String {
        self.1.lock().unwrap().clone()
    }

    /// Ctrl-C, then its counters (the `--json` line): one object per device.
    fn stop(mut self) -> Vec<Value> {
        self.interrupt();
        let mut out = String::new();
        self.0.stdout.take().unwrap().read_to_string(&mut out).unwrap();
        assert!(self.0.wait().unwrap().success());
        serde_json::from_str(out.trim()).unwrap_or_else(|e| panic!("{e}: {out}"))
    }
}

impl Drop for Bridge {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// The peers' Python, made (with the network) before entering a namespace; `None`: skipped.
fn interop_python() -> Option<PathBuf> {
    robowire_fixtures::interop::require(robowire_fixtures::peers::unitree_python())
}

/// Runs the ROS 2 peer's `scenario` on `namespace`; its JSON.
fn peer(python: &Path, scenario: &str, namespace: &str) -> Value {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/ros2_interop");
    let out = Command::new(python).arg("ros2_peer.py").args([scenario, namespace]).current_dir(dir).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{scenario}: {}\n{stdout}\n{}", out.status, String::from_utf8_lossy(&out.stderr));
    serde_json::from_str(stdout.lines().last().unwrap_or_default()).unwrap_or_else(|e| panic!("{e}: {stdout}"))
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// The deadman time given to the bridge, and the time a robot needs to coast to a stop.
const DEADMAN_S: f64 = 0.5;
const SETTLE_S: f64 = 1.0;

#[test]
fn a_cyclonedds_peer_drives_senses_and_calls_services_on_two_devices() {
    let Some(python) = interop_python() else { return };
    with_loopback_multicast(|| {
        let bridge = Bridge::start(&["--device", "sim:kmc", "--device", "sim:zsl1", "--arm", "--deadman", "0.5"]);

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

        let counters = bridge.stop();
        let (kmc, dog) = (&counters[0], &counters[1]);
        assert_eq!((kmc["namespace"].as_str(), dog["namespace"].as_str()), (Some("/kmc0"), Some("/zsl1_0")));
        for device in [kmc, dog] {
            let cmd_vel = &device["cmd_vel"];
            assert!(cmd_vel["applied"].as_u64().unwrap() > 10, "{device}");
            assert_eq!(cmd_vel["deadman_stops"], 1, "{device}");
            assert_eq!(cmd_vel["unarmed"], 0);
        }
        assert_eq!(dog["service_calls"], 1, "the one stand_up");
    });
}

#[test]
fn unarmed_the_same_cmd_vel_moves_nothing() {
    let Some(python) = interop_python() else { return };
    with_loopback_multicast(|| {
        let bridge = Bridge::start(&["--device", "sim:kmc"]);
        let seen = peer(&python, "drive", "");
        assert_eq!(f(&seen["max_speed"]), 0.0, "{seen}");
        assert_eq!(f(&seen["moved_m"]), 0.0, "{seen}");
        let counters = bridge.stop();
        let cmd_vel = &counters[0]["cmd_vel"];
        assert!(cmd_vel["received"].as_u64().unwrap() > 10, "the twists arrived: {cmd_vel}");
        assert_eq!(cmd_vel["unarmed"], cmd_vel["received"]);
        assert_eq!(cmd_vel["applied"], 0);
    });
}

#[test]
fn a_go2_publishes_joint_states_and_passes_lowstate_through() {
    let Some(python) = interop_python() else { return };
    with_loopback_multicast(|| {
        let bridge = Bridge::start(&["--device", "sim:go2", "--interface", "lo", "--namespace", "dog"]);
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
        let counters = bridge.stop();
        assert!(counters[0]["published"].as_u64().unwrap() > 100);
        assert_eq!(counters[0]["namespace"], "/dog");
    });
}

#[test]
fn a_g1_publishes_its_joints_by_name_its_battery_and_passes_its_hg_lowstate_through() {
    use robowire_dds::qos::Qos;
    use robowire_dds::{Participant, ParticipantOptions};
    use ros2_proto::sensor::{BatteryState, Imu, JointState};
    use unitree_proto::HgLowState;

    /// Generous: a topic silent this long is a failure, not slowness.
    const WAIT: std::time::Duration = std::time::Duration::from_secs(20);
    with_loopback_multicast(|| {
        let bridge = Bridge::start(&["--device", "sim:g1", "--interface", "lo", "--namespace", "g1"]);
        let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        runtime.block_on(async {
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
        let counters = bridge.stop();
        assert!(counters[0]["published"].as_u64().unwrap() > 100, "{counters:?}");
    });
}

#[test]
fn a_cyclonedds_peer_reads_a_g1_with_unitrees_hg_classes() {
    let Some(python) = interop_python() else { return };
    with_loopback_multicast(|| {
        let bridge = Bridge::start(&["--device", "sim:g1", "--interface", "lo", "--namespace", "g1"]);
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

/// Generous: a sample or a log line not there after this long is a failure, not slowness.
const GRAPH_WAIT: std::time::Duration = std::time::Duration::from_secs(20);

/// `ros_discovery_info` reader QoS as rmw's: reliable, transient local (a late reader gets the
/// last sample).
const GRAPH_READER: robowire_dds::qos::Qos =
    robowire_dds::qos::Qos { depth: 16, ..robowire_dds::qos::Qos::ROS_TF_STATIC };

/// The topics each node must list at least (writers, readers): a chassis and a dog.
const NODE_TOPICS: [(&str, &[&str], &[&str]); 2] = [
    ("/kmc0", &["rt/kmc0/odom", "rt/kmc0/tf", "rt/kmc0/battery_state"], &["rt/kmc0/cmd_vel"]),
    (
        "/zsl1_0",
        &["rt/zsl1_0/odom", "rt/zsl1_0/joint_states", "rt/zsl1_0/imu", "rr/zsl1_0/stand_upReply"],
        &["rt/zsl1_0/cmd_vel", "rq/zsl1_0/stand_upRequest"],
    ),
];

/// What is wrong with `info` as the bridge's graph, given the endpoints DDS discovery reports:
/// `None` when it lists the two nodes, each with (at least) its topics, every GID the GUID of a
/// discovered endpoint of the bridge of that node's namespace, and every endpoint of the bridge
/// but `ros_discovery_info`'s under one node.
fn graph_mismatch<const N: usize>(
    info: &ros2_proto::rmw_dds_common::ParticipantEntitiesInfo<N>,
    endpoints: &[robowire_dds::DiscoveredEndpoint],
) -> Option<String> {
    let gid = &info.gid.0;
    if gid[12..16] != [0, 0, 1, 0xc1] || gid[16..].iter().any(|&b| b != 0) {
        return Some(format!("the participant's GID {gid:02x?}"));
    }
    let ours: Vec<_> =
        endpoints.iter().filter(|e| e.guid[..12] == gid[..12] && e.topic != "ros_discovery_info").collect();
    let nodes: Vec<(&str, &str)> =
        info.node_entities_info_seq.iter().map(|n| (n.node_namespace.as_str(), n.node_name.as_str())).collect();
    if nodes != [("/kmc0", "robowire"), ("/zsl1_0", "robowire")] {
        return Some(format!("nodes {nodes:?}"));
    }
    let mut listed = 0;
    for (node, (namespace, writers, readers)) in info.node_entities_info_seq.iter().zip(NODE_TOPICS) {
        for (gids, is_writer, expected) in
            [(&node.writer_gid_seq, true, writers), (&node.reader_gid_seq, false, readers)]
        {
            let mut topics = Vec::new();
            for g in gids {
                if g.0[16..].iter().any(|&b| b != 0) {
                    return Some(format!("GID {:02x?} is not zero-padded", g.0));
                }
                let Some(e) = ours.iter().find(|e| e.guid[..] == g.0[..16]) else {
                    return Some(format!("{namespace}: GID {:02x?} not (yet) discovered", g.0));
                };
                let under = ["rt", "rq", "rr"].iter().any(|p| e.topic.starts_with(&format!("{p}{namespace}/")));
                if e.writer != is_writer || !under {
                    return Some(format!("{namespace}: GID of {e:?}"));
                }
                topics.push(e.topic.as_str());
            }
            listed += gids.len();
            if let Some(missing) = expected.iter().find(|t| !topics.contains(t)) {
                return Some(format!("{namespace}: {missing} not listed yet ({topics:?})"));
            }
        }
    }
    (listed != ours.len()).then(|| format!("{listed} GIDs listed, the bridge has {} endpoints: {ours:?}", ours.len()))
}

/// The bridge's nodes on `ros_discovery_info` in the `distro` layout, read with robowire's own
/// DDS after the bridge started (transient local), each GID the GUID DDS discovery reports for
/// the bridge's endpoint of that node's topic; at its stop, a last sample with no node.
fn nodes_on_ros_discovery_info<const N: usize>(distro: &str)
where
    ros2_proto::rmw_dds_common::ParticipantEntitiesInfo<N>: robowire_core::cdr::CdrType,
{
    use robowire_dds::{Participant, ParticipantOptions};
    use ros2_proto::rmw_dds_common::{DISCOVERY_TOPIC, ParticipantEntitiesInfo};

    with_loopback_multicast(|| {
        let bridge = Bridge::start(&[
            "--device",
            "sim:kmc",
            "--device",
            "sim:zsl1",
            "--interface",
            "lo",
            "--ros-distro",
            distro,
        ]);
        let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        runtime.block_on(async {
            let participant = Participant::new(ParticipantOptions::new(0, Some("lo"))).unwrap();
            let mut graph = participant.reader::<ParticipantEntitiesInfo<N>>(DISCOVERY_TOPIC, GRAPH_READER).unwrap();
            let mut last = String::from("no sample");
            let settled = tokio::time::timeout(GRAPH_WAIT, async {
                loop {
                    // A new sample, or the endpoints' discovery catching up with the last one.
                    let info = tokio::time::timeout(std::time::Duration::from_millis(200), graph.recv()).await;
                    let Ok(info) = info else { continue };
                    let info = info.unwrap().value;
                    loop {
                        match graph_mismatch(&info, &participant.discovered_endpoints()) {
                            None => return info,
                            Some(why) if why.contains("not (yet) discovered") => {
                                last = why;
                                tokio::time::sleep(std::time::Duration::from_millis(20)).await;
                            }
                            Some(why) => {
                                last = why;
                                break;
                            }
                        }
                    }
                }
            })
            .await;
            let info = settled.unwrap_or_else(|_| panic!("the bridge's graph never matched: {last}"));
            assert_eq!(info.node_entities_info_seq.len(), 2);
            // Read while it stops: once its participant is gone, so is what it wrote.
            bridge.interrupt();
            let gone = tokio::time::timeout(GRAPH_WAIT, async {
                while !graph.recv().await.unwrap().value.node_entities_info_seq.is_empty() {}
            })
            .await;
            assert!(gone.is_ok(), "the bridge's last sample lists no node: {}", bridge.log());
            bridge.stop();
        });
    });
}

#[test]
fn the_bridge_lists_its_nodes_on_ros_discovery_info_jazzy() {
    nodes_on_ros_discovery_info::<16>("jazzy");
}

#[test]
fn the_bridge_lists_its_nodes_on_ros_discovery_info_humble() {
    nodes_on_ros_discovery_info::<24>("humble");
}

#[test]
fn a_humble_bridge_warns_once_of_a_jazzy_peer() {
    use robowire_dds::{Participant, ParticipantOptions};
    use ros2_proto::rmw_dds_common::{DISCOVERY_TOPIC, Gid, NodeEntitiesInfo, ParticipantEntitiesInfo};

    with_loopback_multicast(|| {
        let bridge = Bridge::start(&["--device", "sim:kmc", "--interface", "lo", "--ros-distro", "humble"]);
        let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        runtime.block_on(async {
            let participant = Participant::new(ParticipantOptions::new(0, Some("lo"))).unwrap();
            let writer = participant
                .writer::<ParticipantEntitiesInfo<16>>(DISCOVERY_TOPIC, robowire_dds::qos::Qos::ROS_TF_STATIC)
                .unwrap();
            let node = |n: &str| NodeEntitiesInfo {
                node_namespace: "/".into(),
                node_name: n.into(),
                reader_gid_seq: vec![],
                writer_gid_seq: vec![Gid::from_guid(writer.guid())],
            };
            writer
                .write(ParticipantEntitiesInfo {
                    gid: Gid::from_guid(participant.guid()),
                    node_entities_info_seq: vec![node("talker")],
                })
                .unwrap();
            let warned = tokio::time::timeout(GRAPH_WAIT, async {
                while !bridge.log().contains("16-byte GIDs (jazzy)") {
                    tokio::time::sleep(std::time::Duration::from_millis(20)).await;
                }
            })
            .await;
            assert!(warned.is_ok(), "the bridge says the peer's layout: {}", bridge.log());
            writer
                .write(ParticipantEntitiesInfo {
                    gid: Gid::from_guid(participant.guid()),
                    node_entities_info_seq: vec![node("listener")],
                })
                .unwrap();
            let _ = writer.acknowledged().await;
        });
        let log = bridge.log();
        bridge.stop();
        assert_eq!(log.matches("ros_discovery_info with 16-byte GIDs").count(), 1, "once: {log}");
        assert!(log.contains("--ros-distro jazzy"), "{log}");
    });
}

/// A CycloneDDS peer started after the bridge reads its nodes on `ros_discovery_info` (transient
/// local: the sample comes late) in the `distro` layout, and finds every GID equal to the key
/// CycloneDDS's own discovery (DCPSPublication / DCPSSubscription) reports for the bridge's
/// endpoint of that node's topic.
fn a_cyclonedds_peer_reads_the_bridges_nodes(distro: &str, gid_len: usize) {
    let Some(python) = interop_python() else { return };
    with_loopback_multicast(|| {
        let bridge = Bridge::start(&["--device", "sim:kmc", "--device", "sim:zsl1", "--ros-distro", distro]);
        let seen = peer(&python, &format!("graph_{distro}"), "");
        let hex = |v: &Value| v.as_str().unwrap_or_else(|| panic!("not a string: {v}")).to_owned();
        let gid = hex(&seen["gid"]);
        assert_eq!(gid.len(), 2 * gid_len, "{seen}");
        assert!(gid[24..32] == *"000001c1" && gid[32..].bytes().all(|b| b == b'0'), "the participant's GID: {seen}");
        let nodes = seen["nodes"].as_array().unwrap();
        let names: Vec<(&str, &str)> =
            nodes.iter().map(|n| (n["namespace"].as_str().unwrap(), n["name"].as_str().unwrap())).collect();
        assert_eq!(names, [("/kmc0", "robowire"), ("/zsl1_0", "robowire")], "{seen}");
        for (node, (namespace, writers, readers)) in nodes.iter().zip(NODE_TOPICS) {
            for (key, kind, expected) in [("writers", "writer", writers), ("readers", "reader", readers)] {
                let mut topics = Vec::new();
                for e in node[key].as_array().unwrap() {
                    let g = hex(&e["gid"]);
                    assert_eq!(g.len(), 2 * gid_len, "{e}");
                    assert!(g[32..].bytes().all(|b| b == b'0'), "zero-padded: {e}");
                    assert_eq!(e["kind"], kind, "the GID is the key of the bridge's {kind}: {e}");
                    assert_eq!(e["participant"].as_str().map(|p| &p[..24]), Some(&gid[..24]), "{e}");
                    let topic = e["topic"].as_str().unwrap();
                    assert!(
                        ["rt", "rq", "rr"].iter().any(|p| topic.starts_with(&format!("{p}{namespace}/"))),
                        "{namespace}: {e}"
                    );
                    topics.push(topic.to_owned());
                }
                for t in expected {
                    assert!(topics.iter().any(|s| s == t), "{namespace} lists its {kind} of {t}: {topics:?}");
                }
            }
        }
        bridge.stop();
    });
}

#[test]
fn a_cyclonedds_peer_reads_the_bridges_nodes_jazzy() {
    a_cyclonedds_peer_reads_the_bridges_nodes("jazzy", 16);
}

#[test]
fn a_cyclonedds_peer_reads_the_bridges_nodes_humble() {
    a_cyclonedds_peer_reads_the_bridges_nodes("humble", 24);
}

/// `std_srvs/Trigger` as ros2-client (an independent ROS 2 client library on rustdds) declares it.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
struct TriggerRequest {
    structure_needs_at_least_one_member: u8,
}
impl ros2_client::Message for TriggerRequest {}

#[derive(Debug, serde::Serialize, serde::Deserialize)]
struct TriggerResponse {
    success: bool,
    message: String,
}
impl ros2_client::Message for TriggerResponse {}

/// ros2-client calls a simulated dog's `stand_up` (one device: the root namespace) in rmw_fastrtps'
/// mapping (its `Enhanced`: the bare request, the reply named by its related sample identity) and
/// in rmw_cyclonedds' (the 16-byte header before the request, echoed): the bridge answers both.
/// A bridge per mapping: rustdds hands a new reply reader the replies written before it, and
/// ros2-client fails a call on a reply of the other mapping's shape instead of skipping it.
#[test]
fn a_ros2_client_calls_stand_up_in_both_middlewares_mappings() {
    use ros2_client::{Context, Name, NodeName, NodeOptions, QosProfile, ServiceMapping, ServiceTypeName};
    use std::net::{IpAddr, Ipv4Addr};

    with_loopback_multicast(|| {
        for (middleware, mapping) in
            [("rmw_fastrtps", ServiceMapping::Enhanced), ("rmw_cyclonedds", ServiceMapping::Cyclone)]
        {
            let bridge = Bridge::start(&["--device", "sim:zsl1", "--interface", "lo"]);
            let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
            let reply = runtime.block_on(async {
                let participant = ros2_client::dds::rustdds::DomainParticipantBuilder::new(0)
                    .with_only_networks([IpAddr::V4(Ipv4Addr::LOCALHOST)])
                    .build()
                    .unwrap();
                let context = Context::from_domain_participant(participant).unwrap();
                let mut node =
                    context.new_node(NodeName::new("/", "trigger_caller").unwrap(), NodeOptions::new()).unwrap();
                // Reliable, as the bridge's request reader (ros2-client's default QoS is best effort).
                let qos = QosProfile::publisher_default();
                let (name, type_name) =
                    (Name::new("/", "stand_up").unwrap(), ServiceTypeName::new("std_srvs", "Trigger"));
                let client = node
                    .create_client::<TriggerRequest, TriggerResponse>(mapping, &name, &type_name, qos.clone(), qos)
                    .unwrap();
                tokio::spawn(node.spinner().unwrap().spin());
                let found = tokio::time::timeout(GRAPH_WAIT, client.wait_for_service(&node)).await;
                assert!(found.is_ok(), "{middleware}: the service's reader and writer matched");
                let call = client.async_call_service(TriggerRequest { structure_needs_at_least_one_member: 0 });
                tokio::time::timeout(GRAPH_WAIT, call)
                    .await
                    .unwrap_or_else(|_| panic!("{middleware}: no answer: {}", bridge.log()))
                    .unwrap_or_else(|e| panic!("{middleware}: {e:?}"))
            });
            assert!(reply.success, "{middleware}: {reply:?}");
            assert!(reply.message.starts_with("stand_up sent"), "{middleware}: {reply:?}");
            let counters = bridge.stop();
            assert_eq!(counters[0]["service_calls"], 1, "{middleware}: {:?}", counters[0]);
            assert_eq!(counters[0]["malformed_requests"], 0, "{middleware}");
        }
    });
}

/// A Trigger request of neither mapping's shape (too long for the bare request, too short for
/// rmw_cyclonedds' header and request) is counted and not answered; then a request as Fast DDS
/// sends it (bare, its related sample identity naming the client's reply reader with an unknown
/// sequence number) is answered with a reply naming that reader and the request's sequence number.
#[test]
fn a_request_of_neither_shape_is_counted_and_a_fast_dds_request_answered() {
    use robowire_core::cdr::{CdrEncoding, CdrType};
    use robowire_dds::{Participant, ParticipantOptions, RawSample, SampleIdentity};
    use ros2_proto::srv::{TriggerRequest, TriggerRequestBody, TriggerResponseBody};

    with_loopback_multicast(|| {
        let bridge = Bridge::start(&["--device", "sim:zsl1", "--interface", "lo"]);
        let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        runtime.block_on(async {
            let participant = Participant::new(ParticipantOptions::new(0, Some("lo"))).unwrap();
            let qos = robowire_dds::qos::Qos::ROS_DEFAULT;
            let bad = participant.raw_writer("rq/stand_upRequest", TriggerRequest::TYPE_NAME, qos).unwrap();
            let requests = participant.writer::<TriggerRequestBody>("rq/stand_upRequest", qos).unwrap();
            let mut replies = participant.reader::<TriggerResponseBody>("rr/stand_upReply", qos).unwrap();
            let matched = tokio::time::timeout(GRAPH_WAIT, async {
                while bad.matched_readers() == 0 || requests.matched_readers() == 0 {
                    tokio::time::sleep(std::time::Duration::from_millis(20)).await;
                }
            })
            .await;
            assert!(matched.is_ok(), "the bridge's request reader matched");
            for len in [12, 0] {
                bad.write(RawSample { encoding: CdrEncoding::Xcdr1, body: vec![0; len] }).unwrap();
            }
            let acknowledged = tokio::time::timeout(GRAPH_WAIT, bad.acknowledged()).await;
            assert!(matches!(acknowledged, Ok(Ok(true))), "the bridge has both bad requests");
            // Asked again (a new request each time) if no reply comes (the bridge waits at most
            // 100 ms for its reply writer to match the reader named).
            let reply_to = SampleIdentity { writer: replies.guid(), sequence: SampleIdentity::SEQUENCE_UNKNOWN };
            let mut sent = Vec::new();
            let reply = tokio::time::timeout(GRAPH_WAIT, async {
                loop {
                    sent.push(requests.write_related(TriggerRequestBody::default(), reply_to).unwrap());
                    let reply = tokio::time::timeout(std::time::Duration::from_millis(200), replies.recv()).await;
                    if let Ok(reply) = reply {
                        break reply.unwrap();
                    }
                }
            })
            .await
            .expect("the Fast DDS request is answered");
            assert!(reply.value.success && reply.value.message.starts_with("stand_up sent"), "{reply:?}");
            let named = reply.related.expect("the reply names its request");
            assert_eq!(named.writer, replies.guid(), "the client's reply reader");
            assert!(
                sent.iter().any(|s| s.sequence == named.sequence),
                "a request's sequence number: {named:?} {sent:?}"
            );
        });
        let counters = bridge.stop();
        assert_eq!(counters[0]["malformed_requests"], 2, "{:?}", counters[0]);
        assert!(counters[0]["service_calls"].as_u64().unwrap() >= 1);
    });
}
