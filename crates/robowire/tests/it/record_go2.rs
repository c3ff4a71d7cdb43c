//! `--record` on the DDS links: `robowire sim go2` and `robowire go2 stand`, each recording its
//! side, read back by the `mcap` Python package with Unitree's own IDL classes: every LowCmd_,
//! LowState_, Request_ and Response_ is a `cdr` message under an `omgidl` schema, deserialises
//! with `unitree_sdk2py`'s classes and carries the CRC Unitree's `crc.py` computes; the counts
//! equal what the programs counted. Where loopback carries multicast (`robowire_dds::netns`).

use std::path::Path;
use std::process::Stdio;

use robowire_dds::netns::with_loopback_multicast;

use crate::support::{Running, read_capture, robowire};

fn temp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("robowire-record-go2-{}-{name}", std::process::id()))
}

/// The number after `label` in `line` (`lowcmd sent 1234 …`).
fn count_after(line: &str, label: &str) -> u64 {
    line.split(label).nth(1).and_then(|rest| rest.split_whitespace().next()).and_then(|n| n.parse().ok()).unwrap_or(0)
}

#[test]
fn a_recorded_go2_session_is_cdr_that_unitree_reads() {
    let Some(python) = robowire_fixtures::interop::require(robowire_fixtures::peers::unitree_python()) else {
        return;
    };
    with_loopback_multicast(|| check_go2_session(&python));
}

fn check_go2_session(python: &Path) {
    let (sim_capture, client_capture) = (temp("sim.mcap"), temp("client.mcap"));
    let (client_stderr, sim_stdout) = {
        let sim = Running::spawn(
            robowire()
                .args(["sim", "go2", "--interface", "lo", "--report-every-s", "0", "--record"])
                .arg(&sim_capture)
                .stderr(Stdio::piped()),
        );
        let stand = robowire()
            .args(["go2", "--interface", "lo", "--record"])
            .arg(&client_capture)
            .args(["stand", "--duration", "0.3", "--hold", "0.3"])
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&stand.stderr).to_string();
        assert!(stand.status.success(), "{}{stderr}", String::from_utf8_lossy(&stand.stdout));
        let log = sim.interrupt();
        assert!(log.stderr.contains("record:") && log.stderr.contains(" 0 dropped"), "{}", log.stderr);
        (stderr, log.stdout)
    };
    assert!(client_stderr.contains("record:") && client_stderr.contains(" 0 dropped"), "{client_stderr}");
    let stats_line = client_stderr.lines().find(|l| l.starts_with("lowcmd sent")).unwrap_or_default();

    let client = read_capture(python, &client_capture);
    assert_eq!(client["unitree_types"], true, "Unitree's IDL classes imported");
    let channels = client["channels"].as_object().unwrap();
    let expected = [
        ("/go2/low_level/sent", "unitree_go::msg::dds_::LowCmd_", true),
        ("/go2/low_level/received", "unitree_go::msg::dds_::LowState_", true),
        ("/go2/api/sent", "unitree_api::msg::dds_::Request_", false),
        ("/go2/api/received", "unitree_api::msg::dds_::Response_", false),
    ];
    for (topic, schema, has_crc) in expected {
        let c = channels.get(topic).unwrap_or_else(|| panic!("{topic} in {client}"));
        assert_eq!((c["encoding"].as_str(), c["schema"].as_str()), (Some("cdr"), Some(schema)), "{c}");
        assert_eq!(c["schema_encoding"], "omgidl");
        let count = c["count"].as_u64().unwrap();
        assert!(count > 0, "{topic}");
        assert_eq!(c["cdr_ok"], count, "{topic}: every message deserialises with Unitree's class");
        if has_crc {
            assert_eq!(c["crc_ok"], count, "{topic}: every message has Unitree's CRC");
        }
        assert_eq!(c["monotonic"], true);
        assert_eq!(
            c["metadata"]["protocol"],
            if topic.contains("api") { "unitree_api.client" } else { "unitree_go.low_level" }
        );
        assert_eq!(c["metadata"]["writer_guid"].as_str().map(str::len), Some(32), "{c}");
        assert!(c["schema_text"].as_str().unwrap().contains("module dds_"));
    }
    // Every LowCmd the client counted is in the capture (and the damping it sends on closing,
    // after its figures were printed); at least every LowState it counted.
    let sent = channels["/go2/low_level/sent"]["count"].as_u64().unwrap();
    assert!(sent >= count_after(stats_line, "lowcmd sent "), "{sent}: {stats_line}");
    let received = channels["/go2/low_level/received"]["count"].as_u64().unwrap();
    assert!(received >= count_after(stats_line, "lowstate received "), "{received}: {stats_line}");

    // The simulator's side: what it took and wrote.
    let sim = read_capture(python, &sim_capture);
    let channels = sim["channels"].as_object().unwrap();
    let lowcmds = &channels["/go2/low_level/received"];
    assert_eq!(lowcmds["schema"], "unitree_go::msg::dds_::LowCmd_");
    assert_eq!(lowcmds["crc_ok"], lowcmds["count"]);
    let last = sim_stdout.lines().last().unwrap_or_default();
    assert!(lowcmds["count"].as_u64().unwrap() >= count_after(last, "lowcmd accepted "), "{last}");
    assert_eq!(channels["/go2/api/received"]["schema"], "unitree_api::msg::dds_::Request_");
    assert_eq!(channels["/go2/low_level/sent"]["cdr_ok"], channels["/go2/low_level/sent"]["count"]);
    for f in [sim_capture, client_capture] {
        let _ = std::fs::remove_file(f);
    }
}
