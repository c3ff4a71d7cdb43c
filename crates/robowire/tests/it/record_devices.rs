//! `--record` on the serial and shared-memory links: `robowire sim kmc` and `robowire kmc … drive`
//! each record their end of one line, and the two captures agree byte for byte (robowire's own
//! reader); `robowire demo --only spline` records its SplineClient and ImuReader. Each capture is
//! then read back by the `mcap` Python package (where its environment is: every JSON message
//! parses, log times are monotonic per channel, every channel has messages).

use std::path::{Path, PathBuf};
use std::process::Stdio;

use robowire_core::Direction;
use robowire_core::json::{LinkDescription, SKIPPED_BYTES};
use serde_json::Value;

use crate::support::{Running, one_demo_at_a_time, read_capture, robowire};

fn temp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("robowire-record-devices-{}-{name}", std::process::id()))
}

/// The channels of `capture` as the `mcap` package reads them: each has messages, monotonic
/// log times, and every JSON message parses. The topics, sorted.
fn check_with_python(python: &Path, capture: &Path) -> Vec<String> {
    let seen = read_capture(python, capture);
    let channels = seen["channels"].as_object().unwrap();
    for (topic, c) in channels {
        assert!(c["count"].as_u64().unwrap() > 0, "{topic}");
        assert_eq!(c["monotonic"], true, "{topic}");
        if c["encoding"] == "json" {
            assert_eq!((&c["json_ok"], &c["schema_parses"]), (&c["count"], &Value::Bool(true)), "{topic}: {c}");
        }
    }
    let mut topics: Vec<String> = channels.keys().cloned().collect();
    topics.sort();
    topics
}

/// The frames of `link` going `direction` in `capture`, read by robowire's reader.
fn frames(
    capture: &Path,
    descriptions: &[&'static dyn LinkDescription],
    link: &str,
    direction: Direction,
) -> Vec<Vec<u8>> {
    let bytes = std::fs::read(capture).unwrap();
    let frames = robowire_record::read_frames(&bytes, descriptions).unwrap();
    frames.into_iter().filter(|f| f.link == link && f.direction == direction).map(|f| f.bytes.to_vec()).collect()
}

#[test]
fn both_ends_of_a_kmc_line_record_the_same_frames() {
    let (sim_capture, client_capture, one_shot_capture) = (temp("sim.mcap"), temp("client.mcap"), temp("speed.mcap"));
    let sim = Running::spawn(
        robowire().args(["sim", "kmc", "--report-every-s", "0", "--record"]).arg(&sim_capture).stderr(Stdio::piped()),
    );
    let port = sim.first_line.clone();
    // A one-shot command first: nothing of it is left on the line for the driver after it.
    let speed =
        robowire().args(["kmc", "--port", &port, "--record"]).arg(&one_shot_capture).arg("speed").output().unwrap();
    assert!(speed.status.success(), "{}", String::from_utf8_lossy(&speed.stderr));
    let drive = robowire()
        .args(["kmc", "--port", &port, "--record"])
        .arg(&client_capture)
        .args(["drive", "--velocity", "0.3", "--yaw-rate", "0.1", "--duration", "0.5"])
        .output()
        .unwrap();
    let client_log = String::from_utf8_lossy(&drive.stderr).to_string();
    assert!(drive.status.success(), "{}{client_log}", String::from_utf8_lossy(&drive.stdout));
    assert!(client_log.contains("record:") && client_log.contains(" 0 dropped"), "{client_log}");
    let sim_log = sim.interrupt().stderr;
    assert!(sim_log.contains("record:") && sim_log.contains(" 0 dropped"), "{sim_log}");

    let host: &[&'static dyn LinkDescription] = &[&kmc_proto::description::HOST, &SKIPPED_BYTES];
    let chassis: &[&'static dyn LinkDescription] = &[&kmc_proto::description::CHASSIS, &SKIPPED_BYTES];
    let client_sent = frames(&client_capture, host, "kmc/serial", Direction::Sent);
    let client_received = frames(&client_capture, host, "kmc/serial", Direction::Received);
    let sim_received = frames(&sim_capture, chassis, "kmc/serial", Direction::Received);
    let sim_sent = frames(&sim_capture, chassis, "kmc/serial", Direction::Sent);
    // 0xA5 commands at 50 Hz for 0.5 s, the stop burst, the polls; the answers to the polls.
    assert!(client_sent.len() > 20 && !client_received.is_empty(), "{} {}", client_sent.len(), client_received.len());
    // The `speed` request and its answer; then what the driver wrote, the chassis decoded, in
    // order, byte for byte (up to what was still on the line when it stopped); what the chassis
    // wrote, the driver decoded (up to the answers it closed without reading).
    let speed_sent = frames(&one_shot_capture, host, "kmc/serial", Direction::Sent);
    let speed_received = frames(&one_shot_capture, host, "kmc/serial", Direction::Received);
    assert_eq!((&speed_sent[..], &speed_received[..]), (&sim_received[..1], &sim_sent[..1]));
    assert!(sim_received.len() > 20 && client_sent.starts_with(&sim_received[1..]));
    assert!(sim_sent[1..].starts_with(&client_received));
    for frame in &client_sent {
        let json = kmc_proto::description::HOST.decode(Direction::Sent, frame).unwrap();
        assert!(["kmc.PcControl", "kmc.AfRequest", "kmc.VehicleSpeedRequest"].contains(&json.schema), "{json:?}");
    }

    let reader = robowire_fixtures::interop::require_part("MCAP reader", robowire_fixtures::peers::unitree_python());
    if let Some(python) = reader {
        let topics = check_with_python(&python, &client_capture);
        assert!(topics.contains(&"/kmc/serial/sent/kmc.PcControl".into()), "{topics:?}");
        assert!(topics.contains(&"/kmc/serial/received/raw".into()), "{topics:?}");
        let topics = check_with_python(&python, &sim_capture);
        assert!(topics.contains(&"/kmc/serial/received/kmc.PcControl".into()), "{topics:?}");
        assert!(topics.contains(&"/kmc/serial/sent/raw".into()), "{topics:?}");
    }
    for f in [sim_capture, client_capture, one_shot_capture] {
        let _ = std::fs::remove_file(f);
    }
}

#[test]
fn the_spline_demo_records_its_client_and_imu_reader() {
    let capture = temp("spline.mcap");
    let turn = one_demo_at_a_time();
    let demo =
        robowire().args(["demo", "--only", "spline", "--duration", "1", "--record"]).arg(&capture).output().unwrap();
    drop(turn);
    let log = String::from_utf8_lossy(&demo.stderr).to_string();
    assert!(demo.status.success(), "{}{log}", String::from_utf8_lossy(&demo.stdout));
    assert!(log.contains("record:") && log.contains(" 0 dropped"), "{log}");

    let zsl = &zsl_proto::description::DESCRIPTIONS;
    let commands = frames(&capture, zsl, "spline/spline", Direction::Sent);
    let states = frames(&capture, zsl, "spline/spline", Direction::Received);
    let imu = frames(&capture, zsl, "spline/imu", Direction::Received);
    assert!(commands.len() > 100 && states.len() > 100 && !imu.is_empty());
    assert!(commands.iter().all(|c| c.len() == 336) && states.iter().all(|s| s.len() == 256));
    let last = zsl_proto::description::SPLINE_CLIENT.decode(Direction::Sent, commands.last().unwrap()).unwrap();
    assert_eq!(last.value["FR"]["knee"]["kp"], 60.0, "the demo's gains");

    let Some(python) = robowire_fixtures::interop::require(robowire_fixtures::peers::unitree_python()) else {
        let _ = std::fs::remove_file(capture);
        return;
    };
    let topics = check_with_python(&python, &capture);
    assert_eq!(
        topics,
        [
            "/spline/imu/received/raw",
            "/spline/imu/received/zsl1.ImuSample",
            "/spline/spline/received/raw",
            "/spline/spline/received/zsl1.SplineState",
            "/spline/spline/sent/raw",
            "/spline/spline/sent/zsl1.SplineCommand",
        ]
    );
    let _ = std::fs::remove_file(capture);
}
