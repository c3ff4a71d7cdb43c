//! Layouts, CRC, image and CDR round trips, errors (the CRC'd messages, and `SportModeState_`).

use proptest::prelude::*;
use robowire_core::cdr::CdrType;
use unitree_proto::crc::{crc32_words, crc32_words_table};
use unitree_proto::layout::{Shape, StructLayout};
use unitree_proto::sport_state::SportModeState;
use unitree_proto::{
    CdrEncoding, DecodeError, FromZeros, HgLowCmd, HgLowState, IntoBytes, LowCmd, LowState, Message, go2,
};

use crate::oracle;

/// `true` for every image byte a field covers, `false` for padding.
fn field_mask(layout: &StructLayout, mask: &mut [bool], base: usize) {
    for field in layout.fields {
        for i in 0..field.len() {
            let at = base + field.offset + i * field.stride();
            match field.shape {
                Shape::Scalar(s) => mask[at..at + s.size()].iter_mut().for_each(|b| *b = true),
                Shape::Struct(sub) => field_mask(sub, mask, at),
                Shape::Pad => {}
            }
        }
    }
}

fn mask<M: Message>() -> Vec<bool> {
    let mut mask = vec![false; M::IMAGE_LEN];
    field_mask(M::FIELDS, &mut mask, 0);
    mask
}

/// The field table and `zero_padding` agree: an all-0xFF image keeps exactly the field bytes.
fn layout_covers_everything_but_padding<M: Message>(padding_bytes: usize) {
    let mask = mask::<M>();
    let mut message = M::read_from_bytes(&vec![0xFF; M::IMAGE_LEN]).unwrap();
    message.zero_padding();
    for (i, (&byte, &is_field)) in message.as_bytes().iter().zip(&mask).enumerate() {
        assert_eq!(byte, if is_field { 0xFF } else { 0 }, "{} byte {i}", M::FIELDS.name);
    }
    assert_eq!(mask.iter().filter(|b| !**b).count(), padding_bytes, "{} padding", M::FIELDS.name);
}

#[test]
fn field_tables_match_the_structs() {
    // LowCmd: 2 after bandwidth, 3 per motor, 1 after gpio.
    layout_covers_everything_but_padding::<LowCmd>(2 + 20 * 3 + 1);
    // LowState: 2 after bandwidth, 3 in the IMU, 6 per motor, 3 after bit_flag, 2 after ntc2.
    layout_covers_everything_but_padding::<LowState>(2 + 3 + 20 * 6 + 3 + 2);
    layout_covers_everything_but_padding::<HgLowCmd>(2 + 35 * 3);
    layout_covers_everything_but_padding::<HgLowState>(2 + 2 + 35 * 3);
}

#[test]
fn all_zero_crcs_of_the_spec() {
    assert_eq!(LowCmd::new_zeroed().computed_crc(), 0x4B5A_4880);
    assert_eq!(LowState::new_zeroed().computed_crc(), 0x85F1_1EA6);
    assert_eq!(HgLowCmd::new_zeroed().computed_crc(), 0xFE17_2F9F);
    assert_eq!(HgLowState::new_zeroed().computed_crc(), 0xD64B_B04A);
    assert_eq!(&LowCmd::new_zeroed().to_image()[808..], &[0x80, 0x48, 0x5a, 0x4b]);
}

#[test]
fn cdr_lengths_of_the_spec() {
    assert_eq!(LowCmd::cdr_len(CdrEncoding::Xcdr1), 812);
    assert_eq!(LowCmd::cdr_len(CdrEncoding::Xcdr2), 820);
    assert_eq!(LowState::cdr_len(CdrEncoding::Xcdr1), 1180);
    assert_eq!(LowState::cdr_len(CdrEncoding::Xcdr2), 1188);
    assert_eq!(HgLowCmd::cdr_len(CdrEncoding::Xcdr1), 1004);
    assert_eq!(HgLowState::cdr_len(CdrEncoding::Xcdr1), 2092);
}

#[test]
fn xcdr_bodies_follow_the_relations_of_spec_6_4() {
    let mut cmd = LowCmd::default();
    cmd.motor_cmd[0] = go2::MotorCmd::servo(0.67, 0.0, 60.0, 5.0, 0.0);
    cmd.bandwidth = 0xBEEF.into();
    let img = cmd.to_image();
    let mut out = [0u8; 820];
    let n = cmd.encode_cdr(CdrEncoding::Xcdr1, &mut out).unwrap();
    let expected: Vec<u8> = [&[0, 1, 0, 0][..], &img[0..22], &img[24..25], &[0], &img[28..812]].concat();
    assert_eq!(&out[..n], &expected[..]);
    let n = cmd.encode_cdr(CdrEncoding::Xcdr2, &mut out).unwrap();
    let expected: Vec<u8> = [&[0, 7, 0, 0][..], &img[0..24], &720u32.to_le_bytes(), &img[24..812]].concat();
    assert_eq!(&out[..n], &expected[..]);
    // HG (derived in the spec, not byte-checked there): LowCmd body = img[0..2] ++ img[4..5] ++ 00 ++ img[8..].
    let mut hg = HgLowCmd::default();
    hg.mode_pr = 1;
    hg.motor_cmd[0].mode = 1;
    hg.motor_cmd[0].q = 0.5.into();
    let img = hg.to_image();
    let mut out = [0u8; 1004];
    let n = hg.encode_cdr(CdrEncoding::Xcdr1, &mut out).unwrap();
    let expected: Vec<u8> = [&[0, 1, 0, 0][..], &img[0..2], &img[4..5], &[0], &img[8..1004]].concat();
    assert_eq!(&out[..n], &expected[..]);
}

#[test]
fn the_default_command_never_moves_a_joint() {
    let cmd = LowCmd::default();
    assert_eq!(cmd.head, [0xFE, 0xEF]);
    assert_eq!(cmd.level_flag, 0xFF);
    for m in &cmd.motor_cmd {
        assert_eq!(m.mode, 0x01);
        assert_eq!(m.q.get().to_bits(), 0x4EFF_D2B9, "PosStopF");
        assert_eq!(m.dq.get().to_bits(), 0x467A_0000, "VelStopF");
        assert_eq!((m.kp.get(), m.kd.get(), m.tau.get()), (0.0, 0.0, 0.0));
    }
    let image = cmd.to_image();
    assert_eq!(LowCmd::decode_image(&image), Ok(cmd.sealed()));
}

#[test]
fn typed_errors() {
    let image = LowCmd::default().to_image();
    assert_eq!(LowCmd::decode_image(&image[..811]), Err(DecodeError::Length { expected: 812, found: 811 }));
    let mut bad_crc = image;
    bad_crc[30] ^= 0x01;
    match LowCmd::decode_image(&bad_crc) {
        Err(DecodeError::CrcMismatch { expected, found, message }) => {
            assert_eq!(found, u32::from_le_bytes(image[808..].try_into().unwrap()));
            assert_ne!(expected, found);
            assert_eq!(message.as_bytes()[30], bad_crc[30], "the error carries the decoded message");
        }
        other => panic!("{other:?}"),
    }
    let mut bad_padding = image;
    bad_padding[22] = 0x5A;
    assert_eq!(LowCmd::decode_image(&bad_padding), Err(DecodeError::NonZeroPadding { offset: 22, value: 0x5A }));
    // Lenient decoding shows the message and what is wrong with it.
    let lenient = LowCmd::decode_image_unverified(&bad_padding).unwrap();
    assert_eq!(lenient.padding, Some((22, 0x5A)));
    assert!(lenient.crc.is_ok(), "padding is not part of the CRC input: it is zeroed first");

    let mut cdr = [0u8; 820];
    let n = LowCmd::default().encode_cdr(CdrEncoding::Xcdr2, &mut cdr).unwrap();
    let mut wrong_header = cdr;
    wrong_header[1] = 0x09;
    assert_eq!(LowCmd::decode_cdr(&wrong_header[..n]), Err(DecodeError::Encapsulation { found: [0, 9, 0, 0] }));
    let mut wrong_dheader = cdr;
    wrong_dheader[4 + 24] = 0x11;
    assert_eq!(
        LowCmd::decode_cdr(&wrong_dheader[..n]),
        Err(DecodeError::ArrayHeader { field: "motor_cmd", expected: 720, found: 0x211 })
    );
    assert_eq!(
        LowCmd::decode_cdr(&cdr[..n - 1]),
        Err(DecodeError::CdrLength { encoding: CdrEncoding::Xcdr2, expected: 820, found: 819 })
    );
    assert_eq!(LowCmd::decode_cdr(&cdr[..2]), Err(DecodeError::NoEncapsulation { found: 2 }));
    let mut short = [0u8; 100];
    assert!(LowCmd::default().encode_image(&mut short).is_err());
    assert!(LowCmd::default().encode_cdr(CdrEncoding::Xcdr1, &mut short).is_err());
}

/// Any bytes as a message of type `M` (padding zeroed: the only thing a decoder keeps).
fn any_message<M: Message + core::fmt::Debug>() -> impl Strategy<Value = M> {
    prop::collection::vec(any::<u8>(), M::IMAGE_LEN).prop_map(|bytes| {
        let mut m = M::read_from_bytes(&bytes).unwrap();
        m.zero_padding();
        m
    })
}

fn identity<M: Message + core::fmt::Debug + PartialEq>(message: M) -> Result<(), TestCaseError> {
    let sealed = message.sealed();
    let mut image = vec![0u8; M::IMAGE_LEN];
    message.encode_image(&mut image).unwrap();
    prop_assert_eq!(M::decode_image(&image), Ok(sealed));
    for encoding in [CdrEncoding::Xcdr1, CdrEncoding::Xcdr2] {
        let mut cdr = vec![0u8; M::cdr_len(encoding)];
        message.encode_cdr(encoding, &mut cdr).unwrap();
        prop_assert_eq!(M::decode_cdr(&cdr), Ok((sealed, encoding)));
    }
    Ok(())
}

fn mutation_is_caught<M: Message + core::fmt::Debug>(
    message: M,
    index: prop::sample::Index,
    flip: u8,
) -> Result<(), TestCaseError> {
    let mut image = vec![0u8; M::IMAGE_LEN];
    message.encode_image(&mut image).unwrap();
    let i = index.index(M::IMAGE_LEN);
    image[i] ^= flip;
    let is_padding = !mask::<M>()[i];
    match M::decode_image(&image) {
        Err(DecodeError::NonZeroPadding { offset, .. }) => prop_assert!(is_padding && offset == i),
        Err(DecodeError::CrcMismatch { .. }) => prop_assert!(!is_padding),
        other => prop_assert!(false, "byte {} flipped by {:#04x} was not caught: {:?}", i, flip, other.map(|_| ())),
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn lowcmd_image_and_cdr_identity(m in any_message::<LowCmd>()) { identity(m)?; }
    #[test]
    fn lowstate_image_and_cdr_identity(m in any_message::<LowState>()) { identity(m)?; }
    #[test]
    fn hg_lowcmd_identity(m in any_message::<HgLowCmd>()) { identity(m)?; }
    #[test]
    fn hg_lowstate_identity(m in any_message::<HgLowState>()) { identity(m)?; }

    #[test]
    fn lowcmd_any_mutation_fails_verification(m in any_message::<LowCmd>(), i in any::<prop::sample::Index>(), flip in 1u8..=255) {
        mutation_is_caught(m, i, flip)?;
    }
    #[test]
    fn lowstate_any_mutation_fails_verification(m in any_message::<LowState>(), i in any::<prop::sample::Index>(), flip in 1u8..=255) {
        mutation_is_caught(m, i, flip)?;
    }

    #[test]
    fn both_crc_backends_equal_the_bitwise_oracle(words in prop::collection::vec(any::<u32>(), 0..523)) {
        let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        let oracle = oracle::crc32_bitwise(&bytes);
        prop_assert_eq!(crc32_words(&bytes), Some(oracle));
        prop_assert_eq!(crc32_words_table(&bytes), Some(oracle));
    }
}

/// XCDR1 alignment bytes of a `SportModeState_` body: after `mode` (65) and `gait_type` (72).
const SPORT_MODE_STATE_ALIGNMENT: [usize; 5] = [66, 67, 73, 74, 75];

/// Bytes of any length, often exactly a `SportModeState_` body's.
fn sport_mode_state_bodies() -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![
        prop::collection::vec(any::<u8>(), 0..600),
        prop::collection::vec(any::<u8>(), 512),
        prop::collection::vec(any::<u8>(), 516),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Any 512 bytes are an XCDR1 body (no DHEADER, no CRC); the state re-encodes to them, alignment
    /// bytes zeroed, and round-trips through both encodings.
    #[test]
    fn sport_mode_state_xcdr1_and_xcdr2_identity(body in prop::collection::vec(any::<u8>(), 512)) {
        let state = SportModeState::decode_body(CdrEncoding::Xcdr1, &body).unwrap();
        let mut expected = body.clone();
        SPORT_MODE_STATE_ALIGNMENT.iter().for_each(|&i| expected[i] = 0);
        let mut out = [0xAAu8; 516];
        prop_assert_eq!(state.encode_body(&mut out), Ok(512));
        prop_assert_eq!(&out[..512], &expected[..]);
        for (encoding, len) in [(CdrEncoding::Xcdr1, 512), (CdrEncoding::Xcdr2, 516)] {
            prop_assert_eq!(state.encode_cdr_body(encoding, &mut out), Ok(len));
            prop_assert_eq!(SportModeState::decode_body(encoding, &out[..len]), Ok(state));
        }
    }

    /// Any bytes decode or give a typed error: the wrong length, or (XCDR2) a DHEADER that is not
    /// `path_point`'s 280.
    #[test]
    fn sport_mode_state_any_bytes_decode_or_give_a_typed_error(
        mut body in sport_mode_state_bodies(),
        xcdr2 in any::<bool>(),
        right_dheader in any::<bool>(),
    ) {
        let (encoding, len) = if xcdr2 { (CdrEncoding::Xcdr2, 516) } else { (CdrEncoding::Xcdr1, 512) };
        if xcdr2 && right_dheader && body.len() == len {
            body[232..236].copy_from_slice(&280u32.to_le_bytes());
        }
        match SportModeState::decode_body(encoding, &body) {
            Ok(_) => prop_assert!(body.len() == len && (!xcdr2 || body[232..236] == 280u32.to_le_bytes())),
            Err(DecodeError::CdrLength { encoding: e, expected, found }) => {
                prop_assert_eq!((e, expected, found), (encoding, len, body.len()));
                prop_assert_ne!(found, len);
            }
            Err(DecodeError::ArrayHeader { field: "path_point", expected: 280, found }) => {
                prop_assert!(xcdr2 && body.len() == len);
                prop_assert_eq!(&found.to_le_bytes()[..], &body[232..236]);
                prop_assert_ne!(found, 280);
            }
            Err(other) => prop_assert!(false, "{:?}", other),
        }
    }
}

/// JSON with the IDL names: a round trip, the crc ignored and rewritten, and typed refusals.
#[test]
fn json_round_trip_and_refusals() {
    let mut cmd = LowCmd::default();
    cmd.motor_cmd[2] = go2::MotorCmd::servo(-1.3, 0.0, 60.0, 5.0, f32::NAN);
    let text = serde_json::to_string(&cmd).unwrap();
    assert!(text.contains(r#""q":-1.3,"#) && text.contains(r#""tau":"NaN""#), "shortest floats, NaN as a string");
    assert!(!text.contains("_pad"), "padding is not an IDL field");
    let back: LowCmd = serde_json::from_str(&text).unwrap();
    assert_eq!(back.to_image(), cmd.to_image());

    let mut value: serde_json::Value = serde_json::from_str(&text).unwrap();
    value["crc"] = 0.into();
    let sealed: LowCmd = serde_json::from_value(value.clone()).unwrap();
    assert_eq!(sealed.crc(), cmd.computed_crc(), "the crc is the encoder's to write");

    let refused = |edit: fn(&mut serde_json::Value)| {
        let mut v = value.clone();
        edit(&mut v);
        serde_json::from_value::<LowCmd>(v).unwrap_err().to_string()
    };
    assert!(refused(|v| v["gpio"] = 256.into()).contains("gpio: 256 does not fit uint8"));
    let kp = refused(|v| v["motor_cmd"][0]["kp"] = "fast".into());
    assert!(kp.contains(r#"motor_cmd[0].kp: expected a number (float), found "fast""#), "{kp}");
    assert!(refused(|v| v["led"] = serde_json::json!([1, 2])).contains("led: expected 12 elements, found 2"));
    assert!(refused(|v| v["bogus"] = 1.into()).contains("bogus: no such field in LowCmd_"));
    assert!(refused(|v| drop(v.as_object_mut().unwrap().remove("level_flag"))).contains("level_flag: missing"));
    let dq = refused(|v| drop(v["motor_cmd"][3].as_object_mut().unwrap().remove("dq")));
    assert!(dq.contains("motor_cmd[3].dq: missing"), "{dq}");
}
