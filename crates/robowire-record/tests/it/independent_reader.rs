//! A capture read back by an independent MCAP reader, the `mcap` Python package (in
//! `robowire_fixtures::peers`' environment; skipped with a line where it is missing): each
//! direction of a link has its raw channel (`robowire.raw` under the protocol's layout) and a JSON
//! channel per message type beside it, every JSON channel has a JSON schema that parses, every
//! JSON message parses, log times are monotonic per channel, raw and decoded counts agree, and
//! the `robowire` metadata record names the version and the link's description.

use std::path::{Path, PathBuf};
use std::process::Command;

use robowire_record::{Direction, Recorder};
use serde_json::Value;
use zsl_proto::description::HIGH_LEVEL;
use zsl_proto::udp::{HIGH_LEVEL_STATE_HEADER, HighLevelCommand, HighLevelState, Model};

/// What `tests/interop/read_capture.py` makes of `capture`, read with `python`.
fn read_with_python(python: &Path, capture: &Path) -> Value {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/interop/read_capture.py");
    let read = Command::new(python).arg(script).arg(capture).output().unwrap();
    assert!(read.status.success(), "{}", String::from_utf8_lossy(&read.stderr));
    serde_json::from_slice(&read.stdout).unwrap()
}

/// A ZSL-1 HighLevel session as a client records it: commands sent, a state received after each.
fn record_session(path: &PathBuf) {
    let recorder = Recorder::create(path, "robowire-record tests").unwrap();
    let tap = recorder.link("zsl1/high_level", &HIGH_LEVEL);
    let state = HighLevelState { header: HIGH_LEVEL_STATE_HEADER, ..HighLevelState::default() }.encode();
    for i in 0..100 {
        let command =
            if i < 10 { HighLevelCommand::stand_up() } else { HighLevelCommand::move_velocity(0.5, 0.0, 0.1) };
        tap.record(Direction::Sent, &command.encode(Model::Zsl1));
        tap.record(Direction::Received, &state);
    }
    let summary = recorder.finish().unwrap();
    assert_eq!((summary.frames, summary.dropped, summary.decode_errors, summary.json_skipped), (200, 0, 0, 0));
}

#[test]
fn a_recorded_session_reads_back_in_the_mcap_package() {
    let Some(python) = robowire_fixtures::interop::require(robowire_fixtures::peers::unitree_python()) else {
        return;
    };
    let capture = std::env::temp_dir().join(format!("robowire-record-reader-{}.mcap", std::process::id()));
    record_session(&capture);
    let seen = read_with_python(&python, &capture);
    let channels = seen["channels"].as_object().unwrap();
    for direction in ["sent", "received"] {
        let raw = &channels[&format!("/zsl1/high_level/{direction}/raw")];
        // One JSON channel per message type: commands one way, states the other.
        let prefix = format!("/zsl1/high_level/{direction}/zsl1.");
        let json = channels.iter().find(|(t, _)| t.starts_with(&prefix)).map(|(_, c)| c).unwrap();
        assert_eq!(raw["encoding"], "robowire.raw");
        assert_eq!(raw["schema_encoding"], "robowire.layout");
        assert_eq!(raw["metadata"]["protocol"], "zsl1.high_level");
        assert_eq!(json["schema_encoding"], "jsonschema", "{json}");
        assert_eq!(json["schema_parses"], true);
        assert_eq!(json["json_ok"], json["count"], "every JSON message parses");
        assert_eq!(raw["count"], json["count"], "each raw frame decoded beside it: {seen}");
        assert_eq!(raw["count"], 100);
        assert_eq!((raw["monotonic"].as_bool(), json["monotonic"].as_bool()), (Some(true), Some(true)));
    }
    let metadata = &seen["metadata"]["robowire"];
    assert_eq!(metadata["robowire_version"], env!("CARGO_PKG_VERSION"));
    assert!(metadata["link:zsl1/high_level"].as_str().unwrap().starts_with("zsl1.high_level"));
    let _ = std::fs::remove_file(capture);
}
