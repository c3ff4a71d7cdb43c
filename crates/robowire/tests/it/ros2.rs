//! `robowire ros2` as users run it: its flags, its `ready` line, its counters as JSON on stdout,
//! what it says on stderr (a Humble bridge warns once of a Jazzy peer, naming the flag that
//! fixes it), `--duration`, and `--record FILE` (the ROS 2 topics in FILE, the devices' links in
//! FILE-devices beside it). The bridge itself (its topics, services, graph and captures, against
//! CycloneDDS, ros2-client and robowire's own DDS) is tested in-process with its crate,
//! `robowire-ros2` (`tests/it/`).

use std::io::{BufRead, BufReader, Read};
use std::process::{Child, Stdio};
use std::sync::{Arc, Mutex};

use robowire_dds::netns::with_loopback_multicast;
use serde_json::Value;

use crate::support::robowire;

/// `robowire ros2 ARGS`, started and waited for (its "ready" line), and its log since.
struct Bridge(Child, Arc<Mutex<String>>);

impl Bridge {
    fn start(args: &[&str]) -> Self {
        let mut child = robowire()
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

/// Generous: a log line not there after this long is a failure, not slowness.
const WAIT: std::time::Duration = std::time::Duration::from_secs(20);

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
            let warned = tokio::time::timeout(WAIT, async {
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

fn temp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("robowire-ros2-{}-{name}", std::process::id()))
}

/// `--duration` ends the bridge by itself; `--json` prints each device's counters under its
/// address and namespace; `--record FILE` writes the ROS 2 topics into FILE (in their wire
/// encoding only) and the devices' own links into FILE-devices beside it, one `record:` line each.
#[test]
fn ros2_stops_after_its_duration_prints_its_counters_and_records_two_captures() {
    with_loopback_multicast(|| {
        let capture = temp("bridge.mcap");
        let devices_capture = temp("bridge-devices.mcap");
        let out = robowire()
            .args(["ros2", "--device", "sim:kmc", "--namespace", "kmc0", "--interface", "lo", "--duration", "1"])
            .args(["--json", "--record"])
            .arg(&capture)
            .env_remove("ROS_DISTRO")
            .output()
            .unwrap();
        let log = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{log}");
        assert!(log.contains("ros2: sim:kmc as /kmc0 on domain 0 (node /kmc0/robowire)"), "{log}");
        assert!(log.contains("ros2: ready (not armed: publishing only; ros_discovery_info for jazzy)"), "{log}");
        assert_eq!(log.matches("record:").count(), 2, "two captures: {log}");
        assert!(!log.contains("not in their wire encoding"), "{log}");
        let counters: Value = serde_json::from_slice(&out.stdout).unwrap();
        let kmc = &counters[0];
        assert_eq!((&kmc["device"], &kmc["namespace"]), (&"sim:kmc".into(), &"/kmc0".into()), "{counters}");
        assert!(kmc["published"].as_u64().unwrap() > 0, "{kmc}");
        assert_eq!((&kmc["service_calls"], &kmc["malformed_requests"]), (&0.into(), &0.into()), "{kmc}");
        assert_eq!(kmc["cmd_vel"]["received"], 0, "no peer: {kmc}");

        let topics = std::fs::read(&capture).unwrap();
        let topics = robowire_record::summarize(&topics, &ros2_proto::description::DESCRIPTIONS).unwrap();
        let odom = topics.channels.iter().find(|c| c.topic == "/kmc0/odom").expect("the ROS 2 topics");
        assert_eq!((odom.encoding.as_str(), odom.decode_errors), ("cdr", 0));
        let descriptions = [&kmc_proto::description::DESCRIPTIONS[..], &[&robowire_core::json::SKIPPED_BYTES]].concat();
        let frames = robowire_record::read_frames(&std::fs::read(&devices_capture).unwrap(), &descriptions).unwrap();
        assert!(frames.iter().any(|f| f.link == "kmc0/kmc/serial"), "the serial link beside the ROS topics");
        for f in [capture, devices_capture] {
            let _ = std::fs::remove_file(f);
        }
    });
}
