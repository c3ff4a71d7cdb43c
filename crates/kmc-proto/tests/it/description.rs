//! Both ends of a KMC link described to a recorder: every golden frame decodes, on the end and
//! direction it travels, to its schema name and the fixture's fields; the other frame set's
//! decoder refuses it where the two differ; any bytes give JSON or a typed error.

use kmc_proto::description::{CHASSIS, DESCRIPTIONS, HOST};
use proptest::prelude::*;
use robowire_core::Direction;
use robowire_core::json::LinkDescription;
use serde_json::Value;

/// The golden frames: (name, direction as the fixture says, bytes, fields).
fn golden() -> Vec<(String, String, Vec<u8>, Value)> {
    let entries: Vec<Value> = serde_json::from_str(include_str!("../../../../fixtures/kmc/frames.json")).unwrap();
    entries
        .iter()
        .map(|e| {
            let hex = e["hex"].as_str().unwrap();
            let bytes = (0..hex.len()).step_by(2).map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap()).collect();
            let text = |k: &str| e[k].as_str().unwrap().to_string();
            (text("name"), text("direction"), bytes, e["fields"].clone())
        })
        .collect()
}

/// JSON values equal, numbers compared as the `f32`s they carry.
fn same(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => x.as_f64().map(|v| v as f32) == y.as_f64().map(|v| v as f32),
        (Value::Array(x), Value::Array(y)) => x.len() == y.len() && x.iter().zip(y).all(|(x, y)| same(x, y)),
        (Value::Object(x), Value::Object(y)) => {
            x.len() == y.len() && x.iter().all(|(k, v)| y.get(k).is_some_and(|w| same(v, w)))
        }
        _ => a == b,
    }
}

/// `kmc.PcControl` from `pc_control`.
fn schema_of_frame(frame: &str) -> String {
    let camel: String = frame.split('_').map(|w| w[..1].to_uppercase() + &w[1..]).collect();
    format!("kmc.{camel}")
}

#[test]
fn golden_frames_decode_on_the_end_and_direction_they_travel() {
    assert_eq!(DESCRIPTIONS.map(|d| d.protocol()), ["kmc.host", "kmc.chassis"]);
    for (name, direction, bytes, fields) in golden() {
        let (host, chassis) = match direction.as_str() {
            "host->chassis" => (Direction::Sent, Direction::Received),
            "chassis->host" => (Direction::Received, Direction::Sent),
            other => panic!("{name}: direction {other}"),
        };
        for (description, direction) in [(&HOST as &dyn LinkDescription, host), (&CHASSIS, chassis)] {
            let frame = description.decode(direction, &bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
            let expected = schema_of_frame(fields["frame"].as_str().unwrap());
            assert_eq!(frame.schema, expected, "{name}");
            assert!(same(&frame.value, &fields), "{name}: {} vs {fields}", frame.value);
        }
    }
}

#[test]
fn a_frame_read_the_wrong_way_is_a_typed_error() {
    let speed_response = [0xb3, 0x00, 0x00, 0xa0, 0x3f];
    let error = HOST.decode(Direction::Sent, &speed_response).unwrap_err();
    assert_eq!(error.to_string(), "5 bytes are not a kmc.host frame");
    assert!(std::error::Error::source(&error).is_some());
    assert!(CHASSIS.decode(Direction::Received, &[0xa5, 0, 0]).is_err(), "a truncated control frame");
}

proptest! {
    #[test]
    fn any_bytes_give_json_or_an_error(bytes in prop::collection::vec(any::<u8>(), 0..100), sent in any::<bool>()) {
        let direction = if sent { Direction::Sent } else { Direction::Received };
        for description in DESCRIPTIONS {
            let _ = description.decode(direction, &bytes);
        }
    }
}
