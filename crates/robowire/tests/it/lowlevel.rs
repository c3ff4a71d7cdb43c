//! `robowire decode|encode lowcmd|lowstate|…` round-trips every Unitree vector.

use std::io::Write;
use std::process::{Command, Output, Stdio};

use serde_json::Value;

fn vectors() -> Value {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/unitree/vectors.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn robowire(args: &[&str], stdin: Option<&str>) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_robowire"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut input = child.stdin.take().unwrap();
    if let Some(text) = stdin {
        input.write_all(text.as_bytes()).unwrap();
    }
    drop(input);
    child.wait_with_output().unwrap()
}

/// The same fields: numbers equal as `f32` (the vectors write each float's exact value, robowire
/// its shortest text; both read back to the same `f32`).
fn same_fields(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            x.len() == y.len() && x.iter().all(|(k, v)| y.get(k).is_some_and(|w| same_fields(v, w)))
        }
        (Value::Array(x), Value::Array(y)) => x.len() == y.len() && x.iter().zip(y).all(|(v, w)| same_fields(v, w)),
        (Value::Number(x), Value::Number(y)) => x.as_f64().map(|v| v as f32) == y.as_f64().map(|v| v as f32),
        (x, y) => x == y,
    }
}

fn stdout(out: &Output) -> String {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout.clone()).unwrap()
}

#[test]
fn every_image_vector_round_trips_through_json() {
    let vectors = vectors();
    for (list, kind) in [("lowcmd", "lowcmd"), ("lowstate", "lowstate")] {
        for vector in vectors[list].as_array().unwrap() {
            let hex = vector["packed_hex"].as_str().unwrap();
            let json: Value = serde_json::from_str(&stdout(&robowire(&["decode", kind, hex, "--json"], None))).unwrap();
            assert!(same_fields(&json, &vector["fields"]), "decode {}: {json}", vector["name"]);
            let encoded = stdout(&robowire(&["encode", kind, "-"], Some(&json.to_string())));
            assert_eq!(encoded.trim(), hex, "encode {}", vector["name"]);
        }
    }
}

#[test]
fn every_cdr_vector_round_trips_through_json() {
    let vectors = vectors();
    for vector in vectors["cdr"].as_array().unwrap() {
        let source = vector["source_vector"].as_str().unwrap();
        let (kind, list) = if vector["dds_type_name"].as_str().unwrap().ends_with("LowCmd_") {
            ("lowcmd", "lowcmd")
        } else {
            ("lowstate", "lowstate")
        };
        let fields = &vectors[list].as_array().unwrap().iter().find(|v| v["name"] == source).unwrap()["fields"];
        let hex = vector["cdr_hex"].as_str().unwrap();
        let json: Value =
            serde_json::from_str(&stdout(&robowire(&["decode", kind, "--cdr", hex, "--json"], None))).unwrap();
        assert!(same_fields(&json, fields), "decode {}: {json}", vector["name"]);
        let encoding = if hex.starts_with("00070000") { "xcdr2" } else { "xcdr1" };
        let encoded = stdout(&robowire(&["encode", kind, "--cdr", encoding, "-"], Some(&json.to_string())));
        assert_eq!(encoded.trim(), hex, "encode {}", vector["name"]);
    }
}

#[test]
fn crc_mismatch_is_an_error_unless_lenient() {
    let vectors = vectors();
    let mut hex = vectors["lowcmd"][1]["packed_hex"].as_str().unwrap().to_string();
    hex.replace_range(60..62, "ff"); // a byte of motor 0's q
    let strict = robowire(&["decode", "lowcmd", &hex], None);
    assert!(!strict.status.success());
    assert!(String::from_utf8_lossy(&strict.stderr).contains("CRC mismatch"));
    let lenient = robowire(&["decode", "lowcmd", &hex, "--lenient", "--json"], None);
    assert!(lenient.status.success());
    assert!(String::from_utf8_lossy(&lenient.stderr).contains("warning: CRC mismatch"));
    let json: Value = serde_json::from_slice(&lenient.stdout).unwrap();
    assert_eq!(json["crc"], vectors["lowcmd"][1]["fields"]["crc"], "the received CRC is shown");
}

#[test]
fn hg_messages_encode_and_decode() {
    for kind in ["lowcmd-hg", "lowstate-hg"] {
        // The zero message's JSON, from the decoder itself.
        let zero_len = if kind == "lowcmd-hg" { 1004 } else { 2092 };
        let mut zero = "00".repeat(zero_len);
        let crc = if kind == "lowcmd-hg" { 0xFE17_2F9Fu32 } else { 0xD64B_B04A };
        let crc_hex: String = crc.to_le_bytes().iter().map(|b| format!("{b:02x}")).collect();
        zero.replace_range(zero.len() - 8.., &crc_hex);
        let json = stdout(&robowire(&["decode", kind, &zero, "--json"], None));
        let mut value: Value = serde_json::from_str(&json).unwrap();
        let motors = if kind == "lowcmd-hg" { "motor_cmd" } else { "motor_state" };
        value[motors][0]["q"] = Value::from(0.5);
        let encoded = stdout(&robowire(&["encode", kind, "-"], Some(&value.to_string())));
        let back: Value =
            serde_json::from_str(&stdout(&robowire(&["decode", kind, encoded.trim(), "--json"], None))).unwrap();
        assert_eq!(back[motors][0]["q"], Value::from(0.5));
        assert_ne!(back["crc"], Value::from(crc), "a new CRC for the new content");
    }
}

#[test]
fn bad_json_is_a_clear_error() {
    let unknown = robowire(&["encode", "lowcmd", "-"], Some(r#"{"head":[254,239],"levelflag":255}"#));
    assert!(!unknown.status.success());
    let text = String::from_utf8_lossy(&unknown.stderr);
    assert!(text.contains("levelflag: no such field in LowCmd_"), "{text}");
    let vectors = vectors();
    let mut fields = vectors["lowcmd"][1]["fields"].clone();
    fields["motor_cmd"][3]["mode"] = Value::from(300);
    let range = robowire(&["encode", "lowcmd", "-"], Some(&fields.to_string()));
    let text = String::from_utf8_lossy(&range.stderr);
    assert!(text.contains("motor_cmd[3].mode: 300 does not fit uint8"), "{text}");
}
