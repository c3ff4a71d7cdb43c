//! The bridge's captures: its ROS 2 topics as a rosbag2 MCAP file (`ros2` profile, `cdr` under
//! `ros2msg` definitions, nothing else), read whole by two independent ROS 2 readers, `rosbags`
//! and `mcap-ros2-support` (`tests/interop/read_ros2.py`), while a CycloneDDS peer drives a
//! simulated chassis through `cmd_vel`; the device's own links beside it in a second file.

use std::path::Path;
use std::process::Command;

use robowire_dds::netns::with_loopback_multicast;
use robowire_record::{Recorder, RecorderOptions};
use serde_json::Value;

use crate::{Bridge, interop_dir, interop_python, options, peer};

fn temp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("robowire-ros2-record-{}-{name}", std::process::id()))
}

#[test]
fn a_bridge_capture_reads_in_rosbags_and_mcap_ros2() {
    let Some(python) = interop_python() else { return };
    with_loopback_multicast(|| check(&python));
}

fn check(python: &Path) {
    let (capture, devices_capture) = (temp("bridge.mcap"), temp("bridge-devices.mcap"));
    // As `robowire ros2 --record` makes them: the ROS 2 topics alone, each in its wire encoding,
    // under the `ros2` profile; the devices' links beside them in a capture of their own.
    let ros2_options = RecorderOptions { profile: "ros2", json: false, wire_only: true, ..RecorderOptions::default() };
    let recorder = Recorder::create_with(&capture, "robowire-ros2 tests", ros2_options).unwrap();
    let devices_recorder = Recorder::create(&devices_capture, "robowire-ros2 tests").unwrap();
    let bridge = Bridge::start(robowire_ros2::BridgeOptions {
        namespace: Some("kmc0".into()),
        armed: true,
        record: Some(recorder.links()),
        record_devices: Some(devices_recorder.links()),
        ..options(&["sim:kmc"])
    });
    peer(python, "drive", "/kmc0");
    let cmd_vel_received = bridge.stop()[0].counters().cmd_vel.received;
    let summary = recorder.finish().unwrap();
    assert_eq!((summary.dropped, summary.oversize), (0, 0), "{summary:?}");
    assert_eq!(summary.not_wire, 0, "every topic in its wire encoding: {summary:?}");
    let devices_summary = devices_recorder.finish().unwrap();
    assert_eq!(devices_summary.dropped, 0, "{devices_summary:?}");

    let read = Command::new(python).arg(interop_dir().join("read_ros2.py")).arg(&capture).output().unwrap();
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
