//! `robowire ros2 --record`: the ROS 2 topics as a rosbag2 MCAP file (`ros2` profile, `cdr`
//! under `ros2msg` definitions, nothing else) read whole by two independent ROS 2 readers,
//! `rosbags` and `mcap-ros2-support` (`tests/record_interop/read_ros2.py`), while a CycloneDDS peer
//! drives a simulated chassis through `cmd_vel`; the devices' own links beside it in a second file.
//! Where loopback carries multicast (`robowire_dds::netns`).

mod support;

use std::io::{BufRead, BufReader, Read};
use std::path::Path;
use std::process::{Command, Stdio};

use robowire_dds::netns::with_loopback_multicast;
use serde_json::Value;

fn temp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("robowire-record-ros2-{}-{name}", std::process::id()))
}

#[test]
fn a_bridge_capture_reads_in_rosbags_and_mcap_ros2() {
    let Some(python) = robowire_fixtures::interop::require(robowire_fixtures::peers::unitree_python()) else {
        return;
    };
    with_loopback_multicast(|| check(&python));
}

fn check(python: &Path) {
    let capture = temp("bridge.mcap");
    let devices_capture = temp("bridge-devices.mcap");
    let mut bridge = Command::new(env!("CARGO_BIN_EXE_robowire"))
        .args(["ros2", "--device", "sim:kmc", "--namespace", "kmc0", "--arm", "--json", "--record"])
        .arg(&capture)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stderr = BufReader::new(bridge.stderr.take().unwrap());
    let mut line = String::new();
    while !line.starts_with("ros2: ready") {
        line.clear();
        assert!(stderr.read_line(&mut line).unwrap() > 0, "robowire ros2 ended before it was ready");
    }
    let log = std::thread::spawn(move || {
        let mut rest = String::new();
        let _ = stderr.read_to_string(&mut rest);
        rest
    });
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/ros2_interop");
    let drive = Command::new(python).arg("ros2_peer.py").args(["drive", "/kmc0"]).current_dir(dir).output().unwrap();
    assert!(drive.status.success(), "{}", String::from_utf8_lossy(&drive.stderr));
    rustix::process::kill_process(rustix::process::Pid::from_child(&bridge), rustix::process::Signal::INT).unwrap();
    let mut out = String::new();
    bridge.stdout.take().unwrap().read_to_string(&mut out).unwrap();
    assert!(bridge.wait().unwrap().success());
    let log = log.join().unwrap();
    assert_eq!(log.matches("record:").count(), 2, "two captures: {log}");
    assert!(!log.contains("not in their wire encoding"), "{log}");
    let counters: Value = serde_json::from_str(out.trim()).unwrap();
    let cmd_vel_received = counters[0]["cmd_vel"]["received"].as_u64().unwrap();

    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/record_interop/read_ros2.py");
    let read = Command::new(python).arg(&script).arg(&capture).output().unwrap();
    assert!(read.status.success(), "{}", String::from_utf8_lossy(&read.stderr));
    let seen: Value = serde_json::from_slice(&read.stdout).unwrap();
    assert_eq!(seen["profile"], "ros2");
    assert_eq!(seen["encodings"], serde_json::json!(["cdr"]), "nothing but ROS 2 messages: {seen}");
    for (topic, kind) in [
        ("/kmc0/cmd_vel", "geometry_msgs/msg/Twist"),
        ("/kmc0/odom", "nav_msgs/msg/Odometry"),
        ("/kmc0/tf", "tf2_msgs/msg/TFMessage"),
        ("/kmc0/battery_state", "sensor_msgs/msg/BatteryState"),
        ("/kmc0/diagnostics", "diagnostic_msgs/msg/DiagnosticArray"),
    ] {
        let (bag, mcap) = (&seen["rosbags"][topic], &seen["mcap_ros2"][topic]);
        assert_eq!((bag["type"].as_str(), mcap["type"].as_str()), (Some(kind), Some(kind)), "{topic}: {seen}");
        assert!(bag["count"].as_u64().unwrap() > 0, "{topic}");
        assert_eq!(bag["count"], mcap["count"], "{topic}: both readers decode every message");
    }
    assert_eq!(seen["rosbags"]["/kmc0/cmd_vel"]["count"].as_u64(), Some(cmd_vel_received), "every cmd_vel taken");
    assert_eq!(seen["max_x"]["/kmc0/cmd_vel"], 0.5, "the peer's 0.5 m/s, decoded: {seen}");
    assert!(seen["max_x"]["/kmc0/odom"].as_f64().unwrap() > 0.4, "and the chassis moving in odom: {seen}");

    // The chassis's own serial link, beside, under the device's namespace.
    let bytes = std::fs::read(&devices_capture).unwrap();
    let descriptions = [&kmc_proto::description::DESCRIPTIONS[..], &[&robowire_core::json::SKIPPED_BYTES]].concat();
    let frames = robowire_record::read_frames(&bytes, &descriptions).unwrap();
    assert!(frames.iter().any(|f| f.link == "kmc0/kmc/serial"), "the serial link beside the ROS topics");
    for f in [capture, devices_capture] {
        let _ = std::fs::remove_file(f);
    }
}
