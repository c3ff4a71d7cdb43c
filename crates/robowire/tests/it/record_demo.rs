//! The demo's capture (`robowire demo --record`: every simulated device in one file) read back by
//! an independent reader, the `mcap` Python package with Unitree's IDL classes
//! (`robowire-record/tests/interop/read_capture.py`): every channel has a schema, every JSON message
//! parses, every Unitree `cdr` message deserialises with Unitree's class and carries Unitree's CRC
//! (but the bit flips the demo injects), log times are monotonic per channel, and the counts are
//! the demo's own. Then `robowire plot` draws it, and refuses a truncated copy.

use serde_json::Value;

use crate::support::{one_demo_at_a_time, read_capture, robowire};

fn temp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("robowire-record-demo-{}-{name}", std::process::id()))
}

/// Messages on the channel `topic`.
fn count(channels: &serde_json::Map<String, Value>, topic: &str) -> u64 {
    channels.get(topic).and_then(|c| c["count"].as_u64()).unwrap_or_else(|| panic!("no channel {topic}"))
}

#[test]
fn the_demo_capture_reads_back_with_the_demo_counts() {
    let Some(python) = robowire_fixtures::interop::require(robowire_fixtures::peers::unitree_python()) else {
        return;
    };
    let capture = temp("demo.mcap");
    let turn = one_demo_at_a_time();
    let demo = robowire().args(["demo", "--duration", "1", "--json", "--record"]).arg(&capture).output().unwrap();
    drop(turn);
    let stderr = String::from_utf8_lossy(&demo.stderr);
    assert!(demo.status.success(), "{stderr}");
    assert!(stderr.contains(" 0 dropped") && stderr.contains(" 0 without JSON"), "{stderr}");
    let report: Value = serde_json::from_slice(&demo.stdout).unwrap();
    let counters = |device: &str, name: &str| {
        let device = report["devices"].as_array().unwrap().iter().find(|d| d["device"] == device).unwrap();
        device["counters"][name].as_u64().unwrap_or_else(|| panic!("{name} of {device}"))
    };

    let seen = read_capture(&python, &capture);
    let channels = seen["channels"].as_object().unwrap();
    for (topic, c) in channels {
        assert!(c["schema"].is_string() && c["schema_encoding"].is_string(), "{topic} has a schema: {c}");
        assert_eq!(c["monotonic"], true, "{topic}");
        match c["encoding"].as_str().unwrap() {
            "json" => assert_eq!(c["json_ok"], c["count"], "{topic}: every JSON message parses"),
            "cdr" => assert_eq!(c["cdr_ok"], c["count"], "{topic}: every message deserialises with Unitree's class"),
            "robowire.raw" => assert_eq!(c["schema_encoding"], "robowire.layout", "{topic}"),
            other => panic!("{topic}: encoding {other}"),
        }
    }
    for link in ["kmc", "zsl1", "go2", "g1/low_level", "g1/arm_sdk"] {
        assert!(channels.keys().any(|t| t.starts_with(&format!("/{link}/"))), "{link} recorded: {seen}");
    }

    // The counts are the demo's own. A scenario reads its client's counters just before it closes
    // the client, and the capture goes on until the link is closed (a stop burst, damping, the
    // states that arrive meanwhile): every counted frame is in the capture, and at most the
    // frames of those last 100 ms (50 at 500 Hz) besides. What a simulator counted after the
    // client closed is exact.
    let recorded_since = |topic: &str, counted: u64| {
        let recorded = count(channels, topic);
        assert!((counted..=counted + 50).contains(&recorded), "{topic}: {recorded} recorded, {counted} counted");
    };
    recorded_since("/kmc/serial/received/raw", counters("kmc", "host frames"));
    assert_eq!(count(channels, "/kmc/serial/sent/raw"), counters("kmc", "chassis frames"));
    let skipped: u64 = channels
        .iter()
        .filter(|(t, _)| t.starts_with("/kmc/serial_skipped/received/robowire.SkippedBytes"))
        .map(|(_, c)| c["count"].as_u64().unwrap())
        .sum();
    assert!(skipped >= 1, "the injected line noise is recorded as skipped bytes");
    recorded_since("/zsl1/high_level/received/raw", counters("zsl1", "states"));
    recorded_since("/zsl1/high_level/sent/raw", counters("zsl1", "sim commands"));
    let lowstates = &channels["/go2/low_level/received"];
    let lowcmds = &channels["/go2/low_level/sent"];
    recorded_since("/go2/low_level/sent", counters("lowcmd", "LowCmd sent"));
    assert_eq!(lowcmds["crc_ok"], lowcmds["count"], "every LowCmd sent carries Unitree's CRC");
    let flipped = lowstates["count"].as_u64().unwrap() - lowstates["crc_ok"].as_u64().unwrap();
    assert_eq!(flipped, counters("lowcmd", "CRC errors"), "the bit flips, and only they, fail Unitree's CRC");
    recorded_since("/go2/low_level/received", counters("lowcmd", "LowState in") + flipped);

    // Drawn: a page per device, the commanded and observed series named.
    let svg = temp("demo.svg");
    let plot = robowire().arg("plot").arg(&capture).arg("--out").arg(&svg).output().unwrap();
    assert!(plot.status.success(), "{}", String::from_utf8_lossy(&plot.stderr));
    let text = std::fs::read_to_string(&svg).unwrap();
    for expected in
        ["kmc (kmc/serial", "zsl1 (zsl1/high_level", "go2 (go2/api, go2/low_level", "commanded vx", "calf target"]
    {
        assert!(text.contains(expected), "{expected} in the plot");
    }
    let bytes = std::fs::read(&capture).unwrap();
    let cut = temp("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 3]).unwrap();
    let out = robowire().arg("plot").arg(&cut).arg("--out").arg(&svg).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("corrupt capture at byte") && !err.contains("panicked"), "{err}");
    for f in [capture, svg, cut] {
        let _ = std::fs::remove_file(f);
    }
}
