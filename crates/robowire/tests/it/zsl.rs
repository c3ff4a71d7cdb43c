//! `robowire decode zsl` over every captured ZSL-1 datagram.

use std::process::Command;

use serde_json::Value;

#[test]
fn every_fixture_decodes_strictly_or_says_why_not() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/zsl1/frames.json");
    let entries: Vec<Value> = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    assert_eq!(entries.len(), 36);
    for entry in entries {
        let hex = entry["hex"].as_str().unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_robowire")).args(["decode", "zsl", hex, "--json"]).output().unwrap();
        // Strict mode: states need their header (HighLevel a5 5a) or magic (LowLevel 0x5AA5).
        let is_state = entry["direction"] == "dog->sdk";
        let strict_ok = !is_state || hex.starts_with("a55a");
        assert_eq!(out.status.success(), strict_ok, "{}: {}", entry["api"], String::from_utf8_lossy(&out.stderr));
        if !strict_ok {
            continue;
        }
        let json: Value = serde_json::from_slice(&out.stdout).unwrap();
        let expected_type = match (is_state, hex.len() / 2) {
            (false, 40) => "high_level_command",
            (false, 248) => "low_level_command",
            (true, 560) => "high_level_state",
            (true, 272) => "low_level_state",
            other => panic!("{other:?}"),
        };
        assert_eq!(json["datagram"], expected_type);
        if expected_type == "high_level_command" {
            let model = if hex.starts_with("a65a") { "zsl-1w" } else { "zsl-1" };
            assert_eq!(json["model"], model);
            assert_eq!(json["mode"], entry["decoded"]["u16_1e_mode"]);
            assert_eq!(json["checksum"], entry["decoded"]["u32_24_checksum"]);
        }
    }
}

#[test]
fn move_example_of_the_spec() {
    let out = Command::new(env!("CARGO_BIN_EXE_robowire"))
        .args([
            "decode",
            "zsl",
            "a55a00000000003f000080be00000000000000000000c03f0000000000001200010000003e010000",
            "--json",
        ])
        .output()
        .unwrap();
    let json: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        (json["vx_mps"].as_f64(), json["vy_mps"].as_f64(), json["yaw_rate_radps"].as_f64()),
        (Some(0.5), Some(-0.25), Some(1.5))
    );
    assert_eq!(json["mode_name"], "Move");
    let bad = Command::new(env!("CARGO_BIN_EXE_robowire")).args(["decode", "zsl", "a55a0000"]).output().unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("4 bytes is no ZSL-1 datagram"));
}
