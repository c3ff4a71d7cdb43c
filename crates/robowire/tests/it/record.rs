//! `--record` on both ends of a ZSL-1 session (`robowire sim zsl1`, `robowire zsl1`), read back by
//! `robowire decode --mcap` (raw and decoded counts agree, log times in order, the simulator's
//! 500 Hz stream) and `robowire replay`; a truncated capture is a clear error, not a panic; and
//! `robowire replay --as-device` plays a recorded walk to a live client. (The recorder's captures
//! read by an independent reader, the `mcap` Python package: robowire-record's tests.)

use std::process::Stdio;

use serde_json::Value;

use crate::support::{Running, robowire};

fn temp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("robowire-record-{}-{name}", std::process::id()))
}

#[test]
fn a_recorded_zsl1_session_reads_back_everywhere() {
    let (sim_capture, client_capture) = (temp("sim.mcap"), temp("client.mcap"));
    let sim = Running::spawn(
        robowire()
            .args(["sim", "zsl1", "--bind", "127.0.0.23", "--report-every-s", "0", "--record"])
            .arg(&sim_capture)
            .stderr(Stdio::piped()),
    );
    let walk = robowire()
        .args(["zsl1", "--dog-ip", "127.0.0.23", "--local-ip", "127.0.0.23", "--record"])
        .arg(&client_capture)
        .args(["stand"])
        .output()
        .unwrap();
    assert!(walk.status.success(), "{}", String::from_utf8_lossy(&walk.stderr));
    let walk = robowire()
        .args([
            "zsl1",
            "--dog-ip",
            "127.0.0.23",
            "--local-ip",
            "127.0.0.23",
            "move",
            "0.5",
            "0",
            "0",
            "--duration",
            "0.5",
        ])
        .output()
        .unwrap();
    assert!(walk.status.success(), "{}", String::from_utf8_lossy(&walk.stderr));
    let log = sim.interrupt().stderr;
    assert!(log.contains("record:") && log.contains(" 0 dropped"), "{log}");

    // Each frame decoded beside its raw bytes, in order, both ways (the `mcap` Python package reads
    // such a capture in robowire-record's tests).
    let summary = robowire().args(["decode", "--json", "--mcap"]).arg(&client_capture).output().unwrap();
    assert!(summary.status.success(), "{}", String::from_utf8_lossy(&summary.stderr));
    let summary: Value = serde_json::from_slice(&summary.stdout).unwrap();
    let channels = summary["channels"].as_array().unwrap();
    for direction in ["sent", "received"] {
        let raw = channels.iter().find(|c| c["topic"] == format!("/zsl1/high_level/{direction}/raw")).unwrap();
        // One JSON channel per message type: commands one way, states the other.
        let prefix = format!("/zsl1/high_level/{direction}/zsl1.");
        let json = channels.iter().find(|c| c["topic"].as_str().unwrap().starts_with(&prefix)).unwrap();
        assert_eq!((&raw["encoding"], &json["encoding"]), (&"robowire.raw".into(), &"json".into()));
        assert!(raw["count"].as_u64().unwrap() > 0);
        assert_eq!(raw["count"], json["count"], "each raw frame decoded beside it: {summary}");
        assert_eq!((&raw["out_of_order"], &json["out_of_order"]), (&0.into(), &0.into()));
    }
    assert_eq!(summary["metadata"]["robowire_version"], env!("CARGO_PKG_VERSION"));
    assert!(summary["metadata"]["link:zsl1/high_level"].as_str().unwrap().starts_with("zsl1.high_level"));
    // The simulator sent a state for each command it got, at least: states ≥ commands seen.
    let summary = robowire().args(["decode", "--json", "--mcap"]).arg(&sim_capture).output().unwrap();
    assert!(summary.status.success(), "{}", String::from_utf8_lossy(&summary.stderr));
    let summary: Value = serde_json::from_slice(&summary.stdout).unwrap();
    let channel =
        |topic: &str| summary["channels"].as_array().unwrap().iter().find(|c| c["topic"] == topic).unwrap().clone();
    let commands = channel("/zsl1/high_level/received/raw");
    assert_eq!(commands["decode_errors"], 0);
    assert_eq!(commands["out_of_order"], 0);
    assert!(commands["rate_hz"].as_f64().unwrap() > 100.0, "the 500 Hz stream: {commands}");

    let replay = robowire().args(["replay", "--fast", "--json"]).arg(&client_capture).output().unwrap();
    assert!(replay.status.success(), "{}", String::from_utf8_lossy(&replay.stderr));
    let lines: Vec<Value> =
        String::from_utf8_lossy(&replay.stdout).lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert!(lines.iter().any(|l| l["message"] == "zsl1.HighLevelCommand" && l["value"]["mode_name"] == "Stand"));
    assert!(lines.iter().any(|l| l["direction"] == "received" && l["message"] == "zsl1.HighLevelState"));

    let bytes = std::fs::read(&sim_capture).unwrap();
    let cut = temp("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    for args in [&["decode", "--mcap"][..], &["replay", "--fast"][..]] {
        let out = robowire().args(args).arg(&cut).output().unwrap();
        assert_eq!(out.status.code(), Some(1), "a clean error, not a panic: {out:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("corrupt capture at byte") && err.contains("expected"),
            "the offset and what was expected: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
    for f in [sim_capture, client_capture, cut] {
        let _ = std::fs::remove_file(f);
    }
}

/// The distinct consecutive modes of HighLevel states.
fn modes(states: impl Iterator<Item = zsl_proto::udp::HighLevelState>) -> Vec<u32> {
    let mut modes: Vec<u32> = states.map(|s| s.control_mode.get()).collect();
    modes.dedup();
    modes
}

#[test]
fn replay_as_device_drives_a_live_client_through_the_recorded_states() {
    use zsl_proto::udp::{AnyDatagram, HighLevelState};
    let capture = temp("walk.mcap");
    let sim = Running::start(&["sim", "zsl1", "--bind", "127.0.0.26", "--report-every-s", "0"]);
    let zsl1 = |args: &[&str], record: bool| {
        let mut command = robowire();
        command.args(["zsl1", "--dog-ip", "127.0.0.26", "--local-ip", "127.0.0.26"]);
        if record {
            command.arg("--record").arg(&capture);
        }
        let out = command.args(args).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    };
    zsl1(&["stand"], false);
    // Wait for the stand-up to finish (mode 1 reported and the body up), not for a fixed time.
    let standing = || {
        let out = robowire()
            .args(["zsl1", "--dog-ip", "127.0.0.26", "--local-ip", "127.0.0.26", "status", "--json"])
            .output()
            .unwrap();
        let state: Value = serde_json::from_slice(&out.stdout).unwrap_or_default();
        state["mode"] == 1 && state["position_m"][2].as_f64().is_some_and(|z| z > 0.29)
    };
    let began = std::time::Instant::now();
    while !standing() {
        assert!(began.elapsed().as_secs() < 30, "the simulated robot never stood up");
    }
    zsl1(&["move", "0.5", "0", "0", "--duration", "0.5"], true);
    drop(sim);

    let zsl = zsl_proto::description::DESCRIPTIONS;
    let recorded: Vec<HighLevelState> = robowire_record::read_frames(&std::fs::read(&capture).unwrap(), &zsl)
        .unwrap()
        .into_iter()
        .filter_map(|f| match AnyDatagram::decode(&f.bytes) {
            Ok(AnyDatagram::HighLevelState(s)) => Some(s),
            _ => None,
        })
        .collect();
    let recorded_modes = modes(recorded.iter().copied());
    assert!(recorded_modes.contains(&18), "the recorded walk: {recorded_modes:?}");

    let replay = Running::spawn(
        robowire().args(["replay", "--as-device", "--bind", "127.0.0.27"]).arg(&capture).stderr(Stdio::piped()),
    );
    assert_eq!(replay.first_line, "127.0.0.27:43997");

    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    let (seen, states_received) = runtime.block_on(async {
        use zsl::udp::{Device, HighLevel};
        let options = zsl::udp::ClientOptions::high_level([127, 0, 0, 26].into(), 0, [127, 0, 0, 27].into());
        let client = HighLevel::open(options).unwrap();
        // Every state in order (not the coalescing latest), until as many as were recorded.
        let mut every = client.every_state();
        let mut seen = Vec::new();
        while seen.len() < recorded.len() {
            match tokio::time::timeout(std::time::Duration::from_secs(30), every.recv()).await {
                Ok(Ok(state)) => seen.push(state.state),
                other => panic!("after {} of {} states: {other:?}", seen.len(), recorded.len()),
            }
        }
        let states = client.stats().states;
        client.close();
        (seen, states)
    });
    let out = replay.wait();
    assert!(out.status.success(), "{}", out.stderr);
    assert_eq!(modes(seen.iter().copied()), recorded_modes, "the live client went through the recorded modes");
    assert_eq!(states_received, recorded.len() as u64, "every recorded state arrived");
    assert_eq!(seen.last(), recorded.last(), "ending in the recorded last state, field for field");
    let _ = std::fs::remove_file(capture);
}
