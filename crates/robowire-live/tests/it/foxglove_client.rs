//! Foxglove's own WebSocket client (`@foxglove/ws-protocol` over `ws`, Foxglove's IDL parser and
//! CDR reader, `tests/live/client.js`) and a headless Chromium on the built-in page
//! (`tests/live/page.js`, puppeteer-core on Debian's `chromium`). Gated like every interop test:
//! without node, npm, the npm registry or Chromium they skip with a line; `ROBOWIRE_INTEROP=1`
//! makes that a failure.

use std::path::{Path, PathBuf};
use std::time::Duration;

use robowire_fixtures::interop;
use serde_json::Value;

use crate::feed::{Feed, live};

/// The node project: `package.json`, its lock and the scripts.
pub(crate) fn project() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/live")
}

/// `node SCRIPT ARGS…` of the project, its stdout as JSON.
pub(crate) fn node(node_modules: &Path, script: &str, args: &[&str]) -> Value {
    robowire_fixtures::peers::node_json(node_modules, &project().join(script), args)
}

/// The channel of `topic` in `client.js`'s report.
pub(crate) fn channel<'a>(report: &'a Value, topic: &str) -> &'a Value {
    let channels = report["channels"].as_array().unwrap();
    channels.iter().find(|c| c["topic"] == topic).unwrap_or_else(|| panic!("no channel {topic}: {report}"))
}

#[test]
fn foxglove_s_client_decodes_every_channel_the_json_and_the_cdr_by_the_advertised_schemas() {
    let Some(node_modules) = interop::require(robowire_fixtures::peers::npm_project("live", &project())) else {
        return;
    };
    let live = live(50.0);
    let _feed = Feed::start(&live, Duration::from_millis(2));
    let url = format!("ws://{}/", live.addr());
    let report = node(&node_modules, "client.js", &[&url, "3"]);
    for c in report["channels"].as_array().unwrap() {
        assert!(c["count"].as_u64() > Some(0), "{c}");
        assert_eq!(c["errors"], 0, "{c}");
    }
    let cdr = channel(&report, "/go2/low_level/received");
    assert_eq!((cdr["encoding"].as_str(), cdr["schemaEncoding"].as_str()), (Some("cdr"), Some("omgidl")));
    assert_eq!(cdr["first"]["imu_state"]["quaternion"][0], 1.0, "Foxglove's CDR reader: {cdr}");
    let json = channel(&report, "/go2/low_level/received/unitree_go::msg::dds_::LowState_");
    assert_eq!(json["first"]["imu_state"]["quaternion"][0], 1.0, "{json}");
    assert_eq!(channel(&report, "/tf")["first"]["child_frame_id"], "go2/base");
    let joints = channel(&report, "/tf_joints");
    assert_eq!(joints["schemaName"], "foxglove.FrameTransforms");
    assert_eq!(joints["first"]["transforms"][0]["child_frame_id"], "go2/FR_hip", "{joints}");
    assert_eq!(channel(&report, "/robowire/log")["schemaName"], "foxglove.Log");
    let malformed = node(&node_modules, "client.js", &[&url, "0", "--malformed"]);
    for case in malformed["malformed"].as_array().unwrap() {
        assert_eq!((case["opened"].as_bool(), case["closed"].as_bool()), (Some(true), Some(true)), "{case}");
    }
}

#[test]
fn the_built_in_page_draws_every_device_s_plots_in_chromium() {
    let Some(node_modules) = interop::require(robowire_fixtures::peers::npm_project("live", &project())) else {
        return;
    };
    let Some(_) = interop::require(robowire_fixtures::peers::chromium()) else { return };
    let live = live(50.0);
    let _feed = Feed::start(&live, Duration::from_millis(2));
    let shot = Path::new(env!("CARGO_TARGET_TMPDIR")).join("live-page.png");
    let url = format!("http://{}/", live.addr());
    let report = node(&node_modules, "page.js", &[&url, shot.to_str().unwrap(), "30", "go2,kmc"]);
    assert_eq!(report["connected"], true, "{report}");
    for device in ["go2", "kmc"] {
        let d = &report["devices"][device];
        assert!(d["nonEmptyPlots"].as_u64() > Some(0) && d["inkPixels"].as_u64() > Some(100), "{device}: {report}");
    }
    assert!(std::fs::metadata(&shot).is_ok_and(|m| m.len() > 1000), "the screenshot {}", shot.display());
}
