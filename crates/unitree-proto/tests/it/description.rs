//! The Unitree DDS links described to a recorder: the golden CDR payloads (Unitree's own
//! serializer) decode to their DDS type and the vendor's fields; HG messages and the services'
//! requests and answers by what they are; any bytes give JSON or a typed error.

use proptest::prelude::*;
use robowire_core::Direction;
use robowire_core::json::LinkDescription;
use serde_json::{Value, json};
use unitree_proto::api::{self, Request, RequestHeader, Response};
use unitree_proto::description::{API_CLIENT, API_SERVER, DESCRIPTIONS, GO2_LOW_LEVEL, HG_LOW_LEVEL};
use unitree_proto::{CdrEncoding, HgLowCmd, HgLowState, LowCmd, LowState, Message};

use crate::golden;

fn hex(text: &str) -> Vec<u8> {
    (0..text.len()).step_by(2).map(|i| u8::from_str_radix(&text[i..i + 2], 16).unwrap()).collect()
}

/// The vendor's fields as robowire's JSON of the message they make.
fn fields_as_json<M: Message + serde::Serialize + serde::de::DeserializeOwned>(fields: &Value) -> Value {
    serde_json::to_value(serde_json::from_value::<M>(fields.clone()).unwrap()).unwrap()
}

#[test]
fn golden_payloads_decode_to_their_type_and_the_vendors_fields() {
    let vectors = golden::vectors();
    let source = |name: &str| golden::source_fields(&vectors, name);
    let payloads = vectors["cdr"].as_array().unwrap();
    assert!(payloads.len() >= 8);
    for payload in payloads {
        let (name, bytes) = (&payload["name"], hex(payload["cdr_hex"].as_str().unwrap()));
        let frame = GO2_LOW_LEVEL.decode(Direction::Received, &bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(frame.schema, payload["dds_type_name"], "{name}");
        let fields = source(payload["source_vector"].as_str().unwrap());
        let expected = match frame.schema {
            "unitree_go::msg::dds_::LowCmd_" => fields_as_json::<LowCmd>(&fields),
            _ => fields_as_json::<LowState>(&fields),
        };
        assert_eq!(frame.value, expected, "{name}");
        assert_eq!(GO2_LOW_LEVEL.schema(&frame)["properties"]["crc"]["type"], "integer");
    }
}

#[test]
fn hg_messages_decode_by_their_length_in_either_encoding() {
    let mut state = HgLowState::default();
    state.motor_state[3].q = 0.5.into();
    let mut command = HgLowCmd::default();
    command.mode_pr = 1;
    let mut out = [0u8; 2200];
    for encoding in [CdrEncoding::Xcdr1, CdrEncoding::Xcdr2] {
        let n = state.encode_cdr(encoding, &mut out).unwrap();
        let frame = HG_LOW_LEVEL.decode(Direction::Received, &out[..n]).unwrap();
        assert_eq!(
            (frame.schema, &frame.value["motor_state"][3]["q"]),
            ("unitree_hg::msg::dds_::LowState_", &json!(0.5))
        );
        let n = command.encode_cdr(encoding, &mut out).unwrap();
        let frame = HG_LOW_LEVEL.decode(Direction::Sent, &out[..n]).unwrap();
        assert_eq!((frame.schema, &frame.value["mode_pr"]), ("unitree_hg::msg::dds_::LowCmd_", &json!(1)));
        // A Go2 link does not take an HG message for one of its own.
        assert!(GO2_LOW_LEVEL.decode(Direction::Sent, &out[..n]).is_err());
    }
    let n = state.encode_cdr(CdrEncoding::Xcdr1, &mut out).unwrap();
    out[n - 1] ^= 1;
    let error = HG_LOW_LEVEL.decode(Direction::Received, &out[..n]).unwrap_err();
    assert_eq!(error.to_string(), format!("{n} bytes are not a unitree_hg.low_level frame"));
    let why = std::error::Error::source(&error).unwrap().to_string();
    assert!(why.contains("CRC mismatch"), "{why}");
    let error = HG_LOW_LEVEL.decode(Direction::Received, &out[..n - 1]).unwrap_err();
    assert!(std::error::Error::source(&error).unwrap().to_string().contains("LowCmd_ is 1004"), "{error:?}");
}

/// A payload as DDS carries it: the XCDR1 header, then the body.
fn payload(body: impl Fn(&mut [u8]) -> usize) -> Vec<u8> {
    let mut out = vec![0u8; 256];
    out[..4].copy_from_slice(&CdrEncoding::Xcdr1.header());
    let n = body(&mut out[4..]);
    out.truncate(4 + n);
    out
}

#[test]
fn service_requests_and_answers_decode_on_the_end_and_direction_they_travel() {
    let header = RequestHeader::call(7, api::motion_switcher::SELECT_MODE);
    let request =
        payload(|out| Request { header, parameter: r#"{"name":"ai"}"#, binary: &[1, 2] }.encode_body(out).unwrap());
    let answer = payload(|out| Response::to(&header, 0, r#"{"form":"0","name":"ai"}"#).encode_body(out).unwrap());
    for (description, sent, received) in
        [(&API_CLIENT as &dyn LinkDescription, &request, &answer), (&API_SERVER, &answer, &request)]
    {
        let frame = description.decode(Direction::Sent, sent).unwrap();
        let back = description.decode(Direction::Received, received).unwrap();
        let (request, answer) =
            if description.protocol() == "unitree_api.client" { (frame, back) } else { (back, frame) };
        assert_eq!(request.schema, "unitree_api::msg::dds_::Request_");
        assert_eq!(request.value["header"]["identity"], json!({ "id": 7, "api_id": 1002 }));
        assert_eq!(
            (&request.value["parameter"], &request.value["binary"]),
            (&json!(r#"{"name":"ai"}"#), &json!([1, 2]))
        );
        assert_eq!(answer.schema, "unitree_api::msg::dds_::Response_");
        assert_eq!(answer.value["header"]["status"]["code"], 0);
        assert_eq!(answer.value["data"], r#"{"form":"0","name":"ai"}"#);
    }
    let mut bad = request.clone();
    bad[1] = 0x09;
    let error = API_CLIENT.decode(Direction::Sent, &bad).unwrap_err();
    assert!(std::error::Error::source(&error).unwrap().to_string().contains("unknown CDR encapsulation"), "{error:?}");
    assert!(API_CLIENT.decode(Direction::Sent, &request[..3]).is_err());
}

proptest! {
    #[test]
    fn any_bytes_give_json_or_an_error(
        body in prop_oneof![
            prop::collection::vec(any::<u8>(), 0..64),
            prop::collection::vec(any::<u8>(), 808),
            prop::collection::vec(any::<u8>(), 1176),
        ],
        xcdr2 in any::<bool>(),
        sent in any::<bool>(),
    ) {
        let header = if xcdr2 { CdrEncoding::Xcdr2 } else { CdrEncoding::Xcdr1 }.header();
        let frame = [&header[..], &body].concat();
        let direction = if sent { Direction::Sent } else { Direction::Received };
        for description in DESCRIPTIONS {
            let _ = description.decode(direction, &frame);
            let _ = description.decode(direction, &body);
        }
    }
}

#[test]
fn every_plotted_series_names_a_number_of_its_message() {
    use unitree_proto::description::PLOTS;
    fn xcdr1<M: Message>(message: M) -> Vec<u8> {
        let mut out = vec![0u8; 2200];
        let n = message.encode_cdr(CdrEncoding::Xcdr1, &mut out).unwrap();
        out[..n].to_vec()
    }
    let frames: Vec<_> = [
        (&GO2_LOW_LEVEL, Direction::Sent, xcdr1(LowCmd::default())),
        (&GO2_LOW_LEVEL, Direction::Received, xcdr1(LowState::default())),
        (&HG_LOW_LEVEL, Direction::Sent, xcdr1(HgLowCmd::default())),
        (&HG_LOW_LEVEL, Direction::Received, xcdr1(HgLowState::default())),
    ]
    .into_iter()
    .map(|(link, direction, payload)| (link.name, direction, link.decode(direction, &payload).unwrap()))
    .collect();
    for plots in &PLOTS {
        let mut checked = 0;
        for series in plots.panels.iter().flat_map(|p| p.series) {
            let (_, _, frame) = frames
                .iter()
                .find(|(link, direction, frame)| {
                    *link == plots.protocol && *direction == series.direction && frame.schema == series.schema
                })
                .unwrap_or_else(|| panic!("{}: no {} frame", plots.protocol, series.schema));
            let value = frame.value.pointer(series.pointer);
            assert!(value.is_some_and(Value::is_number), "{} {}: {:?}", plots.protocol, series.pointer, value);
            checked += 1;
        }
        assert!(checked > 10, "{}", plots.protocol);
    }
}
