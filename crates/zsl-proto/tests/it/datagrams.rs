//! Any datagram survives encode → decode; typed errors for every way it can be wrong.

use proptest::prelude::*;
use zsl_proto::udp::{
    DatagramError, HighLevelCommand, HighLevelState, LowLevelCommand, LowLevelState, Model, checksum,
};
use zsl_proto::zerocopy::{FromBytes, IntoBytes};

fn model() -> impl Strategy<Value = Model> {
    prop_oneof![Just(Model::Zsl1), Just(Model::Zsl1W)]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn high_level_command_round_trips(bytes in prop::collection::vec(any::<u8>(), 40), model in model()) {
        let command = HighLevelCommand::read_from_bytes(&bytes).unwrap();
        let datagram = command.encode(model);
        let (decoded, decoded_model) = HighLevelCommand::decode(&datagram).unwrap();
        prop_assert_eq!(decoded_model, model);
        prop_assert_eq!(decoded.checksum(), checksum(&datagram));
        prop_assert_eq!(decoded.encode(model), datagram);
        // Every field but magic and checksum is carried unchanged, NaN payloads included.
        prop_assert_eq!(&datagram[2..36], &bytes[2..36]);
    }

    #[test]
    fn low_level_command_round_trips(bytes in prop::collection::vec(any::<u8>(), 248)) {
        let command = LowLevelCommand::read_from_bytes(&bytes).unwrap();
        let datagram = command.encode(Model::Zsl1);
        prop_assert_eq!(&datagram[2..244], &bytes[2..244]);
        let (decoded, _) = LowLevelCommand::decode(&datagram).unwrap();
        prop_assert_eq!(decoded.as_bytes(), &datagram[..]);
    }

    #[test]
    fn any_changed_checksum_byte_is_caught(bytes in prop::collection::vec(any::<u8>(), 40), i in 0usize..8, flip in 1u8..=255) {
        let mut datagram = HighLevelCommand::read_from_bytes(&bytes).unwrap().encode(Model::Zsl1);
        datagram[i] ^= flip;
        prop_assert!(HighLevelCommand::decode(&datagram).is_err(), "bytes 0..7 are covered (magic or checksum)");
    }

    #[test]
    fn lenient_state_updates_a_prefix(prefix in prop::collection::vec(any::<u8>(), 0..=560)) {
        let mut state = HighLevelState { battery_percent: 77.into(), ..HighLevelState::default() };
        let update = state.update_lenient(&prefix).unwrap();
        prop_assert_eq!(update.len, prefix.len());
        if prefix.len() <= 0x1F0 {
            prop_assert_eq!(state.battery_percent.get(), 77, "bytes past the prefix are kept");
        }
    }
}

#[test]
fn typed_errors() {
    let mut datagram = HighLevelCommand::stand_up().encode(Model::Zsl1);
    assert_eq!(HighLevelCommand::decode(&datagram[..39]), Err(DatagramError::Length { expected: 40, found: 39 }));
    datagram[0] = 0xa7;
    assert_eq!(HighLevelCommand::decode(&datagram), Err(DatagramError::Magic(0x5aa7)));
    let mut datagram = HighLevelCommand::stand_up().encode(Model::Zsl1);
    datagram[36] ^= 1;
    assert_eq!(HighLevelCommand::decode(&datagram), Err(DatagramError::Checksum { expected: 255, found: 254 }));
    assert_eq!(HighLevelState::decode_strict(&[0u8; 560]), Err(DatagramError::Header([0, 0])));
    assert_eq!(LowLevelState::decode_strict(&[0u8; 272]), Err(DatagramError::Magic(0)));
    assert_eq!(
        HighLevelState::default().update_lenient(&[0u8; 561]),
        Err(DatagramError::TooLong { max: 560, found: 561 })
    );
    let mut low = LowLevelState::default();
    let update = low.update_lenient(&[0xa5, 0x5a]).unwrap();
    assert!(update.short && update.header_ok && low.has_motor_data());
    let empty = low.update_lenient(&[]).unwrap();
    assert!(empty.header_ok && low.has_motor_data(), "a 0-byte datagram changes nothing");
}

/// The JSON of `robowire decode zsl --json`: units in the keys, floats in their shortest form,
/// a state without error says so (not the name of a call's return code).
#[test]
fn datagrams_as_json() {
    use zsl_proto::udp::{HIGH_LEVEL_STATE_HEADER, HighLevelCommand, HighLevelState, Model};
    let command =
        HighLevelCommand::decode(&HighLevelCommand::move_velocity(0.4, 0.0, -1.5).encode(Model::Zsl1W)).unwrap().0;
    let json = serde_json::to_value(command).unwrap();
    assert_eq!(json["model"], "zsl-1w");
    assert_eq!(json["mode_name"], "Move");
    assert!(serde_json::to_string(&command).unwrap().contains(r#""vx_mps":0.4,"#), "shortest f32 text");
    assert_eq!(json["yaw_rate_radps"], -1.5);

    let mut state = HighLevelState { header: HIGH_LEVEL_STATE_HEADER, ..HighLevelState::default() };
    assert_eq!(serde_json::to_value(state).unwrap()["error_name"], "none");
    state.error_word = 0x3011.into();
    state.position[0] = f32::NAN.into();
    let json = serde_json::to_value(state).unwrap();
    assert_eq!((json["error_word"].as_u64(), json["error_name"].as_str()), (Some(0x3011), Some("MotorFault")));
    assert_eq!(json["position_m"][0], "NaN");
    assert_eq!(json["joint_angle_rad"]["knee"].as_array().map(Vec::len), Some(4));
}
