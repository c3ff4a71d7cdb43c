//! The simulated Go2 against CycloneDDS itself (the `cyclonedds` Python binding 0.10.2 with
//! Unitree's IDL classes and CRC, in CPython 3.10; see `robowire_fixtures::peers`), where
//! loopback carries multicast (`robowire_dds::netns`): our LowState decodes field for field on
//! CycloneDDS with a CRC that Unitree's code checks; Unitree's motion_switcher client gets its answers; LowCmds published by
//! CycloneDDS with Unitree's CRC drive the joints, and one with a wrong CRC is dropped.

use std::path::{Path, PathBuf};
use std::process::Command;

use robowire_dds::ParticipantOptions;
use robowire_dds::netns::with_loopback_multicast;
use robowire_fixtures::wait::one_at_a_time;
use robowire_sim::go2::{Go2Sim, Go2SimConfig, LYING_POSE_RAD, STAND_POSE_RAD};
use serde_json::Value;

/// The peers' Python, made (with the network) before entering a namespace; `None`: skipped.
fn interop_python() -> Option<PathBuf> {
    robowire_fixtures::interop::require(robowire_fixtures::peers::unitree_python())
}

/// Runs `script` (in `tests/interop/`) with `python` in the current namespace; its JSON.
fn python(python: &Path, script: &str) -> Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/interop").join(script);
    let out = Command::new(python).arg(&path).arg("lo").output().expect("running Python");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{script}: {}\n{stdout}\n{}", out.status, String::from_utf8_lossy(&out.stderr));
    serde_json::from_str(stdout.lines().last().unwrap_or_default()).unwrap_or_else(|e| panic!("{e}: {stdout}"))
}

fn sim() -> Go2Sim {
    Go2Sim::spawn(Go2SimConfig { participant: ParticipantOptions::new(0, Some("lo")), ..Go2SimConfig::default() })
        .expect("simulator")
}

fn f32s(value: &Value) -> Vec<f32> {
    value.as_array().unwrap().iter().map(|v| v.as_f64().unwrap() as f32).collect()
}

#[test]
fn cyclonedds_reads_our_lowstate_field_for_field_with_a_crc_unitree_accepts() {
    let _turn = one_at_a_time();
    let Some(py) = interop_python() else { return };
    with_loopback_multicast(|| {
        let _sim = sim();
        let state = python(&py, "cyclone_reads_lowstate.py");
        assert_eq!(state["crc"], state["unitree_crc"], "Unitree's CRC of the decoded sample: {state}");
        assert_eq!(state["head"], serde_json::json!([0xFE, 0xEF]));
        assert_eq!(f32s(&state["q"]), LYING_POSE_RAD, "the lying pose, as f32, bit for bit");
        assert!(state["mode"].as_array().unwrap().iter().all(|m| m == 1));
        assert_eq!(f32s(&state["quaternion"]), [1.0, 0.0, 0.0, 0.0]);
        assert_eq!(f32s(&state["accelerometer"]), [0.0, 0.0, 9.81]);
        assert_eq!(state["soc"], 90);
        assert_eq!(f32s(&state["cell_vol"]), [3600.0; 15]);
        assert_eq!(state["power_v"].as_f64().unwrap() as f32, 28.8);
        assert!(state["tick"].as_u64().unwrap() > 0);
    });
}

#[test]
fn unitree_clients_release_the_sport_mode_and_drive_the_joints() {
    let _turn = one_at_a_time();
    let Some(py) = interop_python() else { return };
    with_loopback_multicast(|| {
        let sim = sim();
        let answers = python(&py, "cyclone_drives_lowcmd.py");
        assert_eq!(answers["check_mode_before"], serde_json::json!([0, {"form": "0", "name": "normal"}]));
        assert_eq!(answers["release"], 0);
        assert_eq!(answers["check_mode_after"], serde_json::json!([0, {"form": "0", "name": ""}]));
        let snapshot = sim.snapshot();
        assert!(snapshot.lowcmd.accepted > 500, "{:?}", snapshot.lowcmd);
        assert_eq!(snapshot.lowcmd.bad_head, 0);
        assert!(snapshot.lowcmd.bad_crc >= 1, "the LowCmd with a wrong CRC was dropped: {:?}", snapshot.lowcmd);
        let q = snapshot.joints_rad;
        assert!(
            q.iter().enumerate().all(|(i, q)| (q - STAND_POSE_RAD[i % 3]).abs() < 0.05),
            "the joints follow CycloneDDS's LowCmds to the stand pose: {q:?}"
        );
        assert!(snapshot.requests >= 3);
    });
}
