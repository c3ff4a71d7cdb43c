//! Field access by IDL path: every field of every table reachable, set-then-get, only the
//! field's bytes changed, typed errors, no panic for any path.

use proptest::prelude::*;
use unitree_proto::field::{Element, PlaceKind};
use unitree_proto::layout::{Scalar, Shape, StructLayout};
use unitree_proto::{
    FieldError, FieldPlace, FieldValue, FromZeros, HgLowCmd, HgLowState, IntoBytes, LowCmd, LowState, Message, go2, hg,
};

/// A scalar leaf of a message: its path, type and byte range, computed from the table here.
#[derive(Debug, Clone)]
struct Leaf {
    path: String,
    scalar: Scalar,
    offset: usize,
}

fn leaves_of(layout: &StructLayout, prefix: &str, base: usize, out: &mut Vec<Leaf>) {
    for field in layout.idl_fields() {
        let name = if prefix.is_empty() { field.name.to_string() } else { format!("{prefix}.{}", field.name) };
        let elements: Vec<(String, usize)> = match field.count {
            None => vec![(name, base + field.offset)],
            Some(n) => (0..n).map(|i| (format!("{name}[{i}]"), base + field.offset + i * field.stride())).collect(),
        };
        for (path, offset) in elements {
            match field.shape {
                Shape::Scalar(scalar) => out.push(Leaf { path, scalar, offset }),
                Shape::Struct(sub) => leaves_of(sub, &path, offset, out),
                Shape::Pad => unreachable!("idl_fields leaves padding out"),
            }
        }
    }
}

fn leaves<M: Message>() -> Vec<Leaf> {
    let mut out = Vec::new();
    leaves_of(M::FIELDS, "", 0, &mut out);
    out
}

/// A distinctive value of `scalar` (every byte non-zero and different from its neighbour).
fn marker(scalar: Scalar) -> FieldValue {
    match scalar {
        Scalar::U8 => FieldValue::U8(0xA5),
        Scalar::U16 => FieldValue::U16(0xA5C3),
        Scalar::I16 => FieldValue::I16(-0x5A3D),
        Scalar::U32 => FieldValue::U32(0xA5C3_E187),
        Scalar::I32 => FieldValue::I32(-0x5A3C_1E79),
        Scalar::F32 => FieldValue::F32(-1.234_568e-3),
    }
}

/// The value's bits, so that NaNs compare.
fn bits(value: FieldValue) -> (Scalar, u32) {
    let bits = match value {
        FieldValue::U8(v) => v.into(),
        FieldValue::U16(v) => v.into(),
        FieldValue::I16(v) => u32::from(v as u16),
        FieldValue::U32(v) => v,
        FieldValue::I32(v) => v as u32,
        FieldValue::F32(v) => v.to_bits(),
    };
    (value.scalar(), bits)
}

/// Sets `value` at `leaf` in a copy of `image` through its path; checks the read-back and
/// that exactly the leaf's bytes changed, to the value's little-endian bytes.
fn set_and_check<M: Message>(image: &[u8], leaf: &Leaf, value: FieldValue) -> Result<(), TestCaseError> {
    let place =
        FieldPlace::of::<M>().path(&leaf.path).map_err(|e| TestCaseError::fail(format!("{}: {e}", leaf.path)))?;
    prop_assert_eq!(place.kind(), PlaceKind::Scalar(leaf.scalar), "{}", leaf.path);
    let mut after = image.to_vec();
    place.set(&mut after, value).map_err(|e| TestCaseError::fail(format!("{}: {e}", leaf.path)))?;
    let read = place.get(&after).map_err(|e| TestCaseError::fail(format!("{}: {e}", leaf.path)))?;
    prop_assert_eq!(bits(read), bits(value), "{}", leaf.path);
    let (_, word) = bits(value);
    let span = leaf.offset..leaf.offset + leaf.scalar.size();
    prop_assert_eq!(&after[span.clone()], &word.to_le_bytes()[..leaf.scalar.size()], "{} bytes", leaf.path);
    for (i, (a, b)) in after.iter().zip(image).enumerate() {
        prop_assert!(span.contains(&i) || a == b, "{}: byte {} outside the field changed", leaf.path, i);
    }
    // The message-level shorthand says the same.
    let mut message = M::read_from_bytes(image).unwrap();
    message.set_field(&leaf.path, value).unwrap();
    prop_assert_eq!(message.as_bytes(), &after[..]);
    prop_assert_eq!(message.field(&leaf.path).map(bits), Ok(bits(value)));
    Ok(())
}

/// Every leaf of `M`'s table is reachable by its path and a set changes exactly its bytes; the
/// leaves and the padding together cover the image once.
fn every_field_reachable<M: Message>(expected_leaves: usize) {
    let leaves = leaves::<M>();
    assert_eq!(leaves.len(), expected_leaves, "{}", M::DDS_TYPE_NAME);
    let image: Vec<u8> = (0..M::IMAGE_LEN).map(|i| (i * 7 + 3) as u8).collect();
    let mut covered = vec![0u8; M::IMAGE_LEN];
    for leaf in &leaves {
        set_and_check::<M>(&image, leaf, marker(leaf.scalar)).unwrap();
        covered[leaf.offset..leaf.offset + leaf.scalar.size()].iter_mut().for_each(|c| *c += 1);
    }
    for &(offset, len) in M::PADDING {
        covered[offset..offset + len].iter_mut().for_each(|c| *c += 1);
    }
    assert!(covered.iter().all(|&c| c == 1), "{}: leaves and padding tile the image", M::DDS_TYPE_NAME);
}

#[test]
fn every_field_of_every_table_is_reachable_by_name() {
    // LowCmd: head 2, level_flag, frame_reserve, sn 2, version 2, bandwidth, 20 motors × 9,
    // bms_cmd 1 + 3, wireless_remote 40, led 12, fan 2, gpio, reserve, crc.
    every_field_reachable::<LowCmd>(2 + 1 + 1 + 2 + 2 + 1 + 20 * 9 + 4 + 40 + 12 + 2 + 1 + 1 + 1);
    // LowState: head 2, level_flag, frame_reserve, sn 2, version 2, bandwidth, imu 4+3+3+3+1,
    // 20 motors × 12, bms 4+1+1+2+2+15, foot_force 4 + 4, tick, wireless_remote 40, bit_flag,
    // adc_reel, ntc 2, power 2, fan_frequency 4, reserve, crc.
    every_field_reachable::<LowState>(
        2 + 1 + 1 + 2 + 2 + 1 + 14 + 20 * 12 + 25 + 8 + 1 + 40 + 1 + 1 + 2 + 2 + 4 + 1 + 1,
    );
    // HgLowCmd: mode_pr, mode_machine, 35 motors × 7, reserve 4, crc.
    every_field_reachable::<HgLowCmd>(2 + 35 * 7 + 4 + 1);
    // HgLowState: version 2, mode_pr, mode_machine, tick, imu 14, 35 motors × 15,
    // wireless_remote 40, reserve 4, crc.
    every_field_reachable::<HgLowState>(2 + 2 + 1 + 14 + 35 * 15 + 40 + 4 + 1);
}

/// Paths land where the compiler put the Rust fields (an oracle independent of the tables).
#[test]
fn paths_agree_with_the_structs() {
    let mut cmd = LowCmd::default();
    cmd.set_field("motor_cmd[3].q", FieldValue::F32(0.5)).unwrap();
    cmd.set_field("motor_cmd[19].reserve[2]", 7u32.into()).unwrap();
    cmd.set_field("bms_cmd.reserve[1]", 9u8.into()).unwrap();
    cmd.set_field("crc", 0xDEAD_BEEFu32.into()).unwrap();
    assert_eq!(cmd.motor_cmd[3].q.get(), 0.5);
    assert_eq!(cmd.motor_cmd[19].reserve[2].get(), 7);
    assert_eq!(cmd.bms_cmd.reserve[1], 9);
    assert_eq!(cmd.crc(), 0xDEAD_BEEF, "crc is writable; the encoder overwrites it");
    assert_eq!(cmd.sealed().field("crc"), Ok(FieldValue::U32(cmd.computed_crc())));
    assert_eq!(cmd.field("head[1]"), Ok(FieldValue::U8(go2::HEAD[1])));

    let mut state = LowState::new_zeroed();
    state.imu_state.rpy[2] = (-0.25).into();
    state.bms_state.cell_vol[14] = 3700.into();
    state.foot_force[3] = (-12).into();
    assert_eq!(state.field("imu_state.rpy[2]"), Ok(FieldValue::F32(-0.25)));
    assert_eq!(state.field("bms_state.cell_vol[14]"), Ok(FieldValue::U16(3700)));
    assert_eq!(state.field("foot_force[3]"), Ok(FieldValue::I16(-12)));

    let mut hg_state = HgLowState::new_zeroed();
    hg_state.set_field("motor_state[34].temperature[1]", FieldValue::I16(-40)).unwrap();
    hg_state.set_field("imu_state.temperature", FieldValue::I16(31)).unwrap();
    assert_eq!(hg_state.motor_state[34].temperature[1].get(), -40);
    assert_eq!(hg_state.imu_state.temperature.get(), 31);
    let mut hg_cmd = HgLowCmd::default();
    hg_cmd.set_field("mode_machine", 5u8.into()).unwrap();
    assert_eq!(hg_cmd.mode_machine, 5);
}

#[test]
fn kinds_of_places() {
    let cmd = FieldPlace::of::<LowCmd>();
    assert_eq!(cmd.kind(), PlaceKind::Struct(&go2::LOW_CMD_LAYOUT));
    let motors = cmd.field("motor_cmd").unwrap();
    assert_eq!(motors.kind(), PlaceKind::Array { element: Element::Struct(&go2::MOTOR_CMD_LAYOUT), len: 20 });
    assert_eq!(motors.kind().size(), 20 * 36);
    assert_eq!(motors.index(3).unwrap(), cmd.path("motor_cmd[3]").unwrap());
    assert_eq!(motors.path("[3].q").unwrap(), cmd.path("motor_cmd[3].q").unwrap());
    assert_eq!(cmd.path("").unwrap(), cmd);
    assert_eq!(cmd.path("head").unwrap().kind().to_string(), "uint8[2]");
    assert_eq!(motors.kind().to_string(), "MotorCmd_ (36 bytes)[20]");
}

#[test]
fn typed_errors() {
    let cmd = LowCmd::default();
    let hg = HgLowCmd::default();
    let index = |index, len| Err(FieldError::IndexOutOfRange { index, len });
    assert_eq!(cmd.field("motor_cmd[20].q"), index(20, 20));
    assert_eq!(hg.field("motor_cmd[35].q"), index(35, 35));
    assert_eq!(cmd.field("head[2]"), index(2, 2));
    assert_eq!(cmd.field("head[99999999999999999999999]"), index(usize::MAX, 2));
    assert_eq!(cmd.field("nope"), Err(FieldError::UnknownField { within: "LowCmd_" }));
    assert_eq!(cmd.field("motor_cmd[0].nope"), Err(FieldError::UnknownField { within: "MotorCmd_" }));
    assert_eq!(cmd.field("_pad0"), Err(FieldError::UnknownField { within: "LowCmd_" }), "padding has no name");

    let motor = PlaceKind::Struct(&go2::MOTOR_CMD_LAYOUT);
    assert_eq!(cmd.field("motor_cmd[0]"), Err(FieldError::NotAScalar { found: motor }));
    let level_flag = PlaceKind::Scalar(Scalar::U8);
    assert_eq!(cmd.field("level_flag[0]"), Err(FieldError::NotAnArray { found: level_flag }));
    assert_eq!(cmd.field("level_flag.x"), Err(FieldError::NotAStruct { found: level_flag }));
    let head = PlaceKind::Array { element: Element::Scalar(Scalar::U8), len: 2 };
    assert_eq!(cmd.field("head.x"), Err(FieldError::NotAStruct { found: head }));

    for (path, at) in
        [(".q", 0), ("motor_cmd[", 10), ("motor_cmd[]", 10), ("motor_cmd[-1]", 10), ("motor_cmd[1", 11), ("gpio..x", 5)]
    {
        assert_eq!(cmd.field(path), Err(FieldError::Syntax { at }), "{path:?}");
    }
    assert_eq!(cmd.field("head[1]x"), Err(FieldError::Syntax { at: 7 }));
    assert_eq!(cmd.field("motor_cmd[0]."), Err(FieldError::Syntax { at: 13 }));

    // A value of the wrong type, or out of the type's range, changes nothing.
    let mut changed = cmd;
    let wrong = FieldError::WrongType { expected: level_flag, found: PlaceKind::Scalar(Scalar::F32) };
    assert_eq!(changed.set_field("level_flag", FieldValue::F32(1.0)), Err(wrong));
    assert_eq!(FieldValue::from_f64(Scalar::U8, 1.5), Err(wrong));
    assert_eq!(changed, cmd);
    let range = FieldValue::from_i64(Scalar::U8, 256).unwrap_err();
    assert_eq!(range, FieldError::OutOfRange { scalar: Scalar::U8, value: 256, min: 0, max: 255 });
    assert_eq!(range.to_string(), "256 is outside the uint8 range 0..=255");
    assert!(FieldValue::from_i64(Scalar::I16, -32769).is_err() && FieldValue::from_i64(Scalar::I16, -32768).is_ok());
    assert!(FieldValue::from_i64(Scalar::U32, -1).is_err() && FieldValue::from_i64(Scalar::U32, 0xFFFF_FFFF).is_ok());
    assert!(FieldValue::from_i64(Scalar::I32, 1 << 31).is_err());
    assert_eq!(FieldValue::from_i64(Scalar::F32, 3), Ok(FieldValue::F32(3.0)));

    // An image of another length.
    let place = FieldPlace::of::<LowCmd>().path("gpio").unwrap();
    assert_eq!(place.get(&[0; 811]), Err(FieldError::ImageLength { expected: 812, found: 811 }));
    assert_eq!(place.set(&mut [0; 1004], 1u8.into()), Err(FieldError::ImageLength { expected: 812, found: 1004 }));
}

#[test]
fn copying_structs_between_messages() {
    let mut source = LowCmd::default();
    source.motor_cmd[4] = go2::MotorCmd::servo(-1.3, 0.0, 60.0, 5.0, 0.0);
    let mut target = LowCmd::new_zeroed();
    let from = FieldPlace::of::<LowCmd>().path("motor_cmd[4]").unwrap();
    let to = FieldPlace::of::<LowCmd>().path("motor_cmd[0]").unwrap();
    to.copy_from(target.as_mut_bytes(), &from, source.as_bytes()).unwrap();
    assert_eq!(target.motor_cmd[0], source.motor_cmd[4]);
    assert_eq!(target.motor_cmd[1..], LowCmd::new_zeroed().motor_cmd[1..], "only the target motor changed");
    assert_eq!(to.bytes(target.as_bytes()).unwrap(), from.bytes(source.as_bytes()).unwrap());

    // A G1 motor is not a Go2 motor, though both are `MotorCmd_`.
    let hg = FieldPlace::of::<HgLowCmd>().path("motor_cmd[0]").unwrap();
    let refused = to.copy_from(target.as_mut_bytes(), &hg, HgLowCmd::default().as_bytes()).unwrap_err();
    let hg_motor = PlaceKind::Struct(&hg::HG_MOTOR_CMD_LAYOUT);
    assert_eq!(refused, FieldError::WrongType { expected: PlaceKind::Struct(&go2::MOTOR_CMD_LAYOUT), found: hg_motor });
    assert_eq!(refused.to_string(), "expected a MotorCmd_ (36 bytes), found a MotorCmd_ (28 bytes)");
}

/// Any value of `scalar`.
fn any_value(scalar: Scalar) -> BoxedStrategy<FieldValue> {
    match scalar {
        Scalar::U8 => any::<u8>().prop_map(FieldValue::U8).boxed(),
        Scalar::U16 => any::<u16>().prop_map(FieldValue::U16).boxed(),
        Scalar::I16 => any::<i16>().prop_map(FieldValue::I16).boxed(),
        Scalar::U32 => any::<u32>().prop_map(FieldValue::U32).boxed(),
        Scalar::I32 => any::<i32>().prop_map(FieldValue::I32).boxed(),
        Scalar::F32 => any::<u32>().prop_map(|b| FieldValue::F32(f32::from_bits(b))).boxed(),
    }
}

/// A leaf of `M`, a value of its type and a random image.
fn any_set<M: Message>() -> impl Strategy<Value = (Leaf, FieldValue, Vec<u8>)> {
    prop::sample::select(leaves::<M>()).prop_flat_map(|leaf| {
        let image = prop::collection::vec(any::<u8>(), M::IMAGE_LEN);
        (Just(leaf.clone()), any_value(leaf.scalar), image)
    })
}

/// No panic for any path: an error, or a place whose reads and writes stay in the image.
fn any_path_is_safe<M: Message>(path: &str) -> Result<(), TestCaseError> {
    let mut message = M::default();
    let before = message;
    match FieldPlace::of::<M>().path(path) {
        Ok(place) => {
            let span = place.bytes(message.as_bytes()).map_err(|e| TestCaseError::fail(e.to_string()))?;
            prop_assert!(span.len() == place.kind().size());
            if let Ok(value) = place.get(message.as_bytes()) {
                place.set(message.as_mut_bytes(), value).map_err(|e| TestCaseError::fail(e.to_string()))?;
                prop_assert!(message.as_bytes() == before.as_bytes(), "writing back what was read changes nothing");
            }
        }
        Err(e) => prop_assert!(!e.to_string().is_empty()),
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn lowcmd_set_then_get((leaf, value, image) in any_set::<LowCmd>()) { set_and_check::<LowCmd>(&image, &leaf, value)?; }
    #[test]
    fn lowstate_set_then_get((leaf, value, image) in any_set::<LowState>()) { set_and_check::<LowState>(&image, &leaf, value)?; }
    #[test]
    fn hg_lowcmd_set_then_get((leaf, value, image) in any_set::<HgLowCmd>()) { set_and_check::<HgLowCmd>(&image, &leaf, value)?; }
    #[test]
    fn hg_lowstate_set_then_get((leaf, value, image) in any_set::<HgLowState>()) { set_and_check::<HgLowState>(&image, &leaf, value)?; }

    #[test]
    fn integers_convert_exactly_within_range(scalar in prop::sample::select(&[Scalar::U8, Scalar::U16, Scalar::I16, Scalar::U32, Scalar::I32][..]), v in any::<i64>()) {
        match FieldValue::from_i64(scalar, v) {
            Ok(value) => prop_assert_eq!(bits(value), (scalar, v as u32 & (u32::MAX >> (32 - 8 * scalar.size())))),
            Err(FieldError::OutOfRange { min, max, .. }) => prop_assert!(v < min || v > max),
            Err(e) => prop_assert!(false, "{}", e),
        }
    }

    #[test]
    fn no_panic_for_any_string(path in any::<String>()) {
        any_path_is_safe::<LowCmd>(&path)?;
        any_path_is_safe::<HgLowState>(&path)?;
    }
    #[test]
    fn no_panic_for_any_path_like_string(path in "[a-z_]{0,12}(\\.|\\[[0-9]{0,3}\\]?|[a-z_]{0,10}|\\.\\.){0,6}") {
        any_path_is_safe::<LowCmd>(&path)?;
        any_path_is_safe::<LowState>(&path)?;
        any_path_is_safe::<HgLowCmd>(&path)?;
        any_path_is_safe::<HgLowState>(&path)?;
    }
}
