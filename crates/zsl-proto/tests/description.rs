//! The ZSL-1 links described to a recorder: golden datagrams decode to their schema names and
//! fields, under the names captures have always carried; any bytes give JSON or a typed error.

use proptest::prelude::*;
use robowire_core::Direction;
use robowire_core::json::LinkDescription;
use serde_json::{Value, json};
use zsl_proto::description::{DESCRIPTIONS, HIGH_LEVEL, LOW_LEVEL};

/// The golden datagrams: (the vendor call or state it is, its bytes).
fn golden() -> Vec<(String, Vec<u8>)> {
    let entries: Vec<Value> = serde_json::from_str(include_str!("../../../fixtures/zsl1/frames.json")).unwrap();
    entries
        .iter()
        .map(|e| {
            let hex = e["hex"].as_str().unwrap();
            let bytes = (0..hex.len()).step_by(2).map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap()).collect();
            (e["api"].as_str().unwrap().to_string(), bytes)
        })
        .collect()
}

fn datagram(api: &str) -> Vec<u8> {
    golden().into_iter().find(|(a, _)| a.starts_with(api)).unwrap_or_else(|| panic!("no fixture {api}")).1
}

#[test]
fn the_names_captures_carry() {
    let names: Vec<_> = DESCRIPTIONS.iter().map(|d| (d.protocol(), d.layout())).collect();
    assert_eq!(
        names,
        [("zsl1.high_level", "zsl1-udp, vendor SDK v0.2.7"), ("zsl1.low_level", "zsl1-udp, vendor SDK v0.2.7")]
    );
}

#[test]
fn golden_datagrams_decode_to_their_schema_and_fields() {
    let cases = [
        ("HighLevel.move(0.5, -0.25, 1.5)", "zsl1.HighLevelCommand", "mode_name", json!("Move")),
        ("HighLevel.move(0.5, -0.25, 1.5)", "zsl1.HighLevelCommand", "vy_mps", json!(-0.25)),
        ("HighLevel.move(nan, 0.0, 0.0)", "zsl1.HighLevelCommand", "vx_mps", json!("NaN")),
        ("HighLevel state, plausible standing robot", "zsl1.HighLevelState", "battery_percent", json!(90)),
        ("HighLevel state with error word", "zsl1.HighLevelState", "error_name", json!("MotorFault")),
        ("LowLevel.sendMotorCmd(demo-like", "zsl1.LowLevelCommand", "q_des_knee", json!([-1.5, -1.5, -1.5, -1.5])),
        ("LowLevel state, plausible standing robot", "zsl1.LowLevelState", "tau_hip_fb", json!([2.0, 2.0, 2.0, 2.0])),
    ];
    for (api, schema, field, value) in cases {
        let bytes = datagram(api);
        // Either link's description, either way: the datagram's length tells what it is.
        for description in DESCRIPTIONS {
            for direction in [Direction::Sent, Direction::Received] {
                let frame = description.decode(direction, &bytes).unwrap_or_else(|e| panic!("{api}: {e}"));
                assert_eq!((frame.schema, &frame.value[field]), (schema, &value), "{api}");
                assert_eq!(description.schema(&frame)["title"], schema);
            }
        }
    }
}

#[test]
fn a_state_without_its_magic_is_a_typed_error() {
    let error = LOW_LEVEL.decode(Direction::Received, &datagram("LowLevel state without 0x5AA5")).unwrap_err();
    assert_eq!(error.to_string(), "272 bytes are not a zsl1.low_level frame");
    let source = std::error::Error::source(&error).map(ToString::to_string);
    assert!(source.is_some_and(|s| s.contains("magic")), "{error:?}");
}

proptest! {
    #[test]
    fn any_bytes_give_json_or_an_error(bytes in prop_oneof![
        prop::collection::vec(any::<u8>(), 0..600),
        prop::collection::vec(any::<u8>(), 40),
        prop::collection::vec(any::<u8>(), 248),
        prop::collection::vec(any::<u8>(), 272),
        prop::collection::vec(any::<u8>(), 560),
    ]) {
        let decoded = HIGH_LEVEL.decode(Direction::Received, &bytes);
        if ![40, 248, 272, 560].contains(&bytes.len()) {
            prop_assert!(decoded.is_err());
        }
    }
}
