//! `--live`: a simulator and the demo streamed to Foxglove's own WebSocket client and to the
//! built-in page in a headless Chromium (the node scripts of `robowire-live/tests/live`), and
//! `robowire serve` and `replay --live` as a viewer sees them. Gated like every interop test: without
//! node, npm, the npm registry or Chromium they skip with a line.

use std::io::{BufRead, BufReader};
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::process::{Child, Stdio};
use std::sync::mpsc;

use robowire_dds::netns::with_loopback_multicast;
use robowire_fixtures::interop;
use serde_json::Value;

use crate::support::{one_demo_at_a_time, robowire};

/// The node project of `robowire-live`'s tests: `client.js` (Foxglove's client), `page.js`
/// (Chromium on the page).
fn project() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../robowire-live/tests/live")
}

fn node_modules() -> Option<PathBuf> {
    interop::require(robowire_fixtures::peers::npm_project("live", &project()))
}

/// `node SCRIPT ARGS…` of the project, its stdout as JSON.
fn node(node_modules: &Path, script: &str, args: &[&str]) -> Value {
    robowire_fixtures::peers::node_json(node_modules, &project().join(script), args)
}

/// `robowire ARGS` with `--live 127.0.0.1:0`, once it said where its live view is: the process,
/// the address, and its stderr's other lines as they come.
fn start_live(args: &[&str]) -> (Child, SocketAddr, mpsc::Receiver<String>) {
    let mut child = robowire()
        .args(args)
        .args(["--live", "127.0.0.1:0"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stderr = BufReader::new(child.stderr.take().unwrap());
    let (lines, rx) = mpsc::channel();
    std::thread::spawn(move || {
        // Read to the end, wanted or not: a closed pipe would stop robowire at its next line.
        for line in stderr.lines().map_while(Result::ok) {
            let _ = lines.send(line);
        }
    });
    let addr = rx
        .iter()
        .find_map(|line| line.strip_prefix("live: Foxglove ws://").and_then(|r| r.split('/').next()?.parse().ok()))
        .unwrap_or_else(|| panic!("robowire {args:?} never said where its live view is: {:?}", child.wait()));
    (child, addr, rx)
}

/// The channel of `topic` in `client.js`'s report.
fn channel<'a>(report: &'a Value, topic: &str) -> &'a Value {
    let channels = report["channels"].as_array().unwrap();
    channels.iter().find(|c| c["topic"] == topic).unwrap_or_else(|| panic!("no channel {topic}: {report}"))
}

#[test]
fn sim_go2_live_opens_in_foxglove_s_client_with_its_json_its_cdr_and_its_frames() {
    let Some(node_modules) = node_modules() else { return };
    with_loopback_multicast(|| {
        let (mut sim, addr, _) = start_live(&["sim", "go2", "--interface", "lo"]);
        let report = node(&node_modules, "client.js", &[&format!("ws://{addr}/"), "3"]);
        let _ = sim.kill();
        let _ = sim.wait();
        let json = channel(&report, "/go2/low_level/sent/unitree_go::msg::dds_::LowState_");
        assert!(json["count"].as_u64() > Some(10) && json["errors"] == 0, "{json}");
        assert_eq!(json["first"]["motor_state"].as_array().map(Vec::len), Some(3), "cut to 3: {json}");
        let cdr = channel(&report, "/go2/low_level/sent");
        assert_eq!(
            (cdr["encoding"].as_str(), cdr["schemaName"].as_str()),
            (Some("cdr"), Some("unitree_go::msg::dds_::LowState_"))
        );
        assert!(cdr["count"].as_u64() > Some(10) && cdr["errors"] == 0, "Foxglove's CDR reader: {cdr}");
        let tf = channel(&report, "/tf");
        assert_eq!(
            (tf["schemaName"].as_str(), tf["first"]["child_frame_id"].as_str()),
            (Some("foxglove.FrameTransform"), Some("go2/base"))
        );
        // The Go2's bodies from its LowState's joints, hanging from the base.
        let joints = channel(&report, "/tf_joints");
        let hip = &joints["first"]["transforms"][0];
        assert_eq!(
            (joints["schemaName"].as_str(), hip["parent_frame_id"].as_str(), hip["child_frame_id"].as_str()),
            (Some("foxglove.FrameTransforms"), Some("go2/base"), Some("go2/FR_hip")),
            "{joints}"
        );
        assert!(channel(&report, "/robowire/live")["count"].as_u64() >= Some(1), "{report}");
    });
}

#[test]
fn the_demo_s_live_page_draws_every_device_in_chromium() {
    let Some(node_modules) = node_modules() else { return };
    let Some(_) = interop::require(robowire_fixtures::peers::chromium()) else { return };
    let shot = Path::new(env!("CARGO_TARGET_TMPDIR")).join("demo-live.png");
    let turn = one_demo_at_a_time();
    with_loopback_multicast(|| {
        let (mut demo, addr, stderr) = start_live(&["demo", "--duration", "4", "--json"]);
        let devices = "kmc,zsl1,spline,go2,g1";
        let report =
            node(&node_modules, "page.js", &[&format!("http://{addr}/"), shot.to_str().unwrap(), "60", devices]);
        let status = demo.wait().unwrap();
        assert!(status.success(), "the demo: {status}\n{}", stderr.try_iter().collect::<Vec<_>>().join("\n"));
        // The demo may have ended before the page stopped waiting: what it drew stays.
        assert_eq!(report["wasConnected"], true, "{report}");
        for device in devices.split(',') {
            let d = &report["devices"][device];
            assert!(d["nonEmptyPlots"].as_u64() > Some(0) && d["inkPixels"].as_u64() > Some(100), "{device}: {report}");
        }
    });
    drop(turn);
    eprintln!("the page's screenshot: {}", shot.display());
}

#[test]
fn serve_streams_devices_by_address_and_replay_plays_a_capture_live() {
    let Some(node_modules) = node_modules() else { return };
    // `serve` a simulator for 8 s (node starts well within), recording it too: the live view and
    // the capture side by side.
    let capture = std::env::temp_dir().join(format!("robowire-live-{}.mcap", std::process::id()));
    let (mut serve, addr, _) =
        start_live(&["serve", "sim:zsl1", "--duration", "8", "--record", capture.to_str().unwrap()]);
    let report = node(&node_modules, "client.js", &[&format!("ws://{addr}/"), "2"]);
    assert!(serve.wait().unwrap().success());
    let state = report["channels"].as_array().unwrap().iter().find(|c| {
        c["topic"].as_str().is_some_and(|t| t.starts_with("/zsl1/high_level/received/"))
            && c["count"].as_u64() > Some(0)
    });
    assert!(state.is_some(), "the ZSL-1's state live: {report}");
    // The capture played back live.
    let (mut replay, addr, _) = start_live(&["replay", capture.to_str().unwrap(), "--speed", "0.5"]);
    let report = node(&node_modules, "client.js", &[&format!("ws://{addr}/"), "2"]);
    let _ = replay.kill();
    let _ = replay.wait();
    let _ = std::fs::remove_file(&capture);
    let replayed = report["channels"].as_array().unwrap().iter().any(|c| {
        c["topic"].as_str().is_some_and(|t| t.starts_with("/zsl1/high_level/")) && c["count"].as_u64() > Some(0)
    });
    assert!(replayed, "the capture's frames live: {report}");
}

#[test]
fn every_command_that_opens_a_device_takes_live_and_live_rate() {
    let commands: &[&[&str]] = &[
        &["demo"],
        &["sim", "kmc"],
        &["sim", "zsl1"],
        &["sim", "spline"],
        &["sim", "go2"],
        &["sim", "g1"],
        &["kmc"],
        &["zsl1"],
        &["dog"],
        &["go2"],
        &["g1"],
        &["status"],
        &["watch"],
        &["ros2"],
        &["policy", "run"],
        &["serve"],
        &["replay"],
    ];
    for command in commands {
        let out = robowire().args(*command).arg("--help").output().unwrap();
        let help = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success() && help.contains("--live [<ADDR>]") && help.contains("--live-rate <HZ>"),
            "{command:?}: {help}"
        );
    }
    // A rate that is not one is refused before anything opens.
    let out = robowire().args(["sim", "zsl1", "--live", "127.0.0.1:0", "--live-rate", "NaN"]).output().unwrap();
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("live rate NaN Hz"), "{out:?}");
}
