//! The ZSL-1 links described to a recorder: golden datagrams decode to their schema names and
//! fields, under the names captures have always carried; the shared-memory blocks decode by
//! direction and exact length; any bytes give JSON or a typed error.

use proptest::prelude::*;
use robowire_core::Direction;
use robowire_core::json::LinkDescription;
use serde_json::{Value, json};
use zsl_proto::description::{DESCRIPTIONS, HIGH_LEVEL, IMU, LOW_LEVEL, SPLINE_CLIENT, SPLINE_DAEMON, WrongLength};
use zsl_proto::shm::{JointFlags, JointIndex, Leg, NavImu, NavImuSample, SplineCommandBlock, SplineStateBlock};
use zsl_proto::zerocopy::IntoBytes;

/// The golden datagrams: (the vendor call or state it is, its bytes).
fn golden() -> Vec<(String, Vec<u8>)> {
    let entries: Vec<Value> = serde_json::from_str(include_str!("../../../../fixtures/zsl1/frames.json")).unwrap();
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
    let shm = "zsl1-spline-shm, vendor SDK v0.2.7 lowlevel.h";
    assert_eq!(
        names,
        [
            ("zsl1.high_level", "zsl1-udp, vendor SDK v0.2.7"),
            ("zsl1.low_level", "zsl1-udp, vendor SDK v0.2.7"),
            ("zsl1.spline.client", shm),
            ("zsl1.spline.daemon", shm),
            ("zsl1.imu", shm),
        ]
    );
}

/// A command as a client publishes it: the 336 bytes of legs.
fn command_frame() -> Vec<u8> {
    let mut command = SplineCommandBlock::default();
    *command.joint_mut(Leg::RearRight, JointIndex::Knee) = zsl_proto::JointControl::new(-1.375, 0.25, 60.0, 2.0, 1.5);
    command.joint_mut(Leg::FrontLeft, JointIndex::Abad).kp = f32::NAN.into();
    command.legs.as_bytes().to_vec()
}

/// A state as the daemon publishes it: the 256 bytes of legs.
fn state_frame() -> Vec<u8> {
    let mut state = SplineStateBlock::default();
    let joint = state.joint_mut(Leg::RearLeft, JointIndex::Hip);
    joint.flags = 0x0030_8C09.into();
    (joint.p, joint.v, joint.t) = (0.75.into(), (-0.5).into(), 3.25.into());
    state.joint_mut(Leg::FrontRight, JointIndex::Foot).flags = JointFlags::new(24, -40, 0).0.into();
    state.legs.as_bytes().to_vec()
}

#[test]
fn a_command_reads_per_leg_and_joint_with_units_sent_by_the_client_and_received_by_the_daemon() {
    let bytes = command_frame();
    assert_eq!(bytes.len(), 336);
    for (description, direction) in [(&SPLINE_CLIENT, Direction::Sent), (&SPLINE_DAEMON, Direction::Received)] {
        let frame = description.decode(direction, &bytes).unwrap();
        assert_eq!(frame.schema, "zsl1.SplineCommand");
        assert_eq!(
            frame.value["RR"]["knee"],
            json!({ "p_des_rad": -1.375, "v_des_radps": 0.25, "kp": 60.0, "kd": 2.0, "t_ff_nm": 1.5 })
        );
        assert_eq!(frame.value["FL"]["abad"]["kp"], json!("NaN"), "as the client would have refused it");
        assert_eq!(frame.value["FR"]["flags"], 1);
        let legs: Vec<_> = frame.value.as_object().unwrap().keys().cloned().collect();
        assert_eq!(legs, ["FR", "FL", "RR", "RL"]);
        let joints: Vec<_> = frame.value["RL"].as_object().unwrap().keys().cloned().collect();
        assert_eq!(joints, ["abad", "hip", "knee", "foot", "flags"]);
        assert_eq!(description.schema(&frame)["properties"]["RR"]["properties"]["knee"]["type"], "object");
    }
}

#[test]
fn a_state_reads_with_its_flags_decoded_received_by_the_client_and_sent_by_the_daemon() {
    let bytes = state_frame();
    assert_eq!(bytes.len(), 256);
    for (description, direction) in [(&SPLINE_CLIENT, Direction::Received), (&SPLINE_DAEMON, Direction::Sent)] {
        let frame = description.decode(direction, &bytes).unwrap();
        assert_eq!(frame.schema, "zsl1.SplineState");
        let faults = json!({
            "overvoltage": false, "overcurrent": false, "over_temperature": true, "overspeed": false,
            "dual_encoder": false,
        });
        assert_eq!(
            frame.value["RL"]["hip"],
            json!({
                "p_rad": 0.75, "v_radps": -0.5, "t_nm": 3.25, "flags": 0x0030_8C09, "enabled": true,
                "faults": faults, "voltage_v": 48, "temperature_c": 100,
            })
        );
        let foot = &frame.value["FR"]["foot"];
        assert_eq!(
            (&foot["enabled"], &foot["voltage_v"], &foot["temperature_c"]),
            (&json!(false), &json!(24), &json!(-40))
        );
    }
}

#[test]
fn an_imu_record_reads_either_way() {
    let record = NavImu {
        timestamp_ns: 1_234_567_890_123.into(),
        sample: NavImuSample {
            acc: [0.5, -0.25, 9.75].map(Into::into),
            gyro: [0.0, 0.125, -1.0].map(Into::into),
            q: [1.0, 0.0, 0.0, 0.0].map(Into::into),
        },
    };
    for direction in [Direction::Sent, Direction::Received] {
        let frame = IMU.decode(direction, record.as_bytes()).unwrap();
        assert_eq!(
            (frame.schema, frame.value),
            (
                "zsl1.ImuSample",
                json!({
                    "timestamp_ns": 1_234_567_890_123u64, "acc_mps2": [0.5, -0.25, 9.75],
                    "gyro_radps": [0.0, 0.125, -1.0], "quaternion_wxyz": [1.0, 0.0, 0.0, 0.0],
                })
            )
        );
    }
}

#[test]
fn a_shared_memory_frame_of_another_length_is_a_typed_error() {
    let (command, state) = (command_frame(), state_frame());
    /// (link, direction, frame, the message it should be, its length).
    type Case<'a> = (&'a dyn LinkDescription, Direction, &'a [u8], &'static str, usize);
    let cases: [Case<'_>; 7] = [
        // A state where a command must be, and the other way round.
        (&SPLINE_CLIENT, Direction::Sent, &state, "zsl1.SplineCommand", 336),
        (&SPLINE_CLIENT, Direction::Received, &command, "zsl1.SplineState", 256),
        (&SPLINE_DAEMON, Direction::Received, &state, "zsl1.SplineCommand", 336),
        (&SPLINE_DAEMON, Direction::Sent, &command, "zsl1.SplineState", 256),
        // One word short, one too many, nothing.
        (&SPLINE_CLIENT, Direction::Sent, &command[..332], "zsl1.SplineCommand", 336),
        (&SPLINE_DAEMON, Direction::Sent, &[state.clone(), vec![0; 4]].concat(), "zsl1.SplineState", 256),
        (&IMU, Direction::Received, &[], "zsl1.ImuSample", 48),
    ];
    for (description, direction, bytes, message, expected) in cases {
        let error = description.decode(direction, bytes).unwrap_err();
        assert_eq!(error.to_string(), format!("{} bytes are not a {} frame", bytes.len(), description.protocol()));
        let source = std::error::Error::source(&error).and_then(|s| s.downcast_ref::<WrongLength>());
        assert_eq!(source, Some(&WrongLength { message, expected, found: bytes.len() }));
    }
    assert!(IMU.decode(Direction::Received, &[0; 40]).is_err(), "the sample without its timestamp");
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
        // Either UDP link's description, either way: the datagram's length tells what it is.
        for description in [&HIGH_LEVEL, &LOW_LEVEL] {
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

    #[test]
    fn any_bytes_on_a_shared_memory_link_give_json_exactly_at_its_length(bytes in prop_oneof![
        prop::collection::vec(any::<u8>(), 0..700),
        prop::collection::vec(any::<u8>(), 48),
        prop::collection::vec(any::<u8>(), 256),
        prop::collection::vec(any::<u8>(), 336),
    ]) {
        for direction in [Direction::Sent, Direction::Received] {
            let command = direction == Direction::Sent;
            let cases = [(&SPLINE_CLIENT, if command { 336 } else { 256 }), (&SPLINE_DAEMON, if command { 256 } else { 336 }), (&IMU, 48)];
            for (description, len) in cases {
                let decoded = description.decode(direction, &bytes);
                prop_assert_eq!(decoded.is_ok(), bytes.len() == len, "{} {:?}", description.protocol(), direction);
                if let Ok(frame) = decoded {
                    // Every field present, whatever the floats: NaN and infinities as their names.
                    prop_assert!(serde_json::to_string(&frame.value).is_ok());
                }
            }
        }
    }
}
