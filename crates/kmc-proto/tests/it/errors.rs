//! Typed errors for every way the bytes or the arguments can be wrong.

use kmc_proto::{
    AfFrame, AllState, BufferTooSmall, ChassisFrame, ChassisFrameDecoder, DecodeError, EncodeError, FrameBuffer,
    HostFrame, ParamId, PcControl, StreamDecoder, VehicleSpeed,
};

#[test]
fn strict_parse_errors() {
    assert_eq!(HostFrame::parse(&[]), Err(DecodeError::Empty));
    assert_eq!(HostFrame::parse(&[0x42]), Err(DecodeError::UnknownFrameId(0x42)));
    // 0xA5 is not a chassis frame.
    assert_eq!(ChassisFrame::parse(&[0xa5; 9]), Err(DecodeError::UnknownFrameId(0xa5)));
    assert_eq!(HostFrame::parse(&[0xa5, 0, 0]), Err(DecodeError::Truncated { needed: 9, available: 3 }));
    assert_eq!(HostFrame::parse(&[0xb3, 0xb3]), Err(DecodeError::TrailingBytes { frame_len: 1, available: 2 }));
    assert_eq!(HostFrame::parse(&[0xaf, 0, 2, 1, 7]), Err(DecodeError::InvalidRw(2)));
    assert_eq!(HostFrame::parse(&[0xaf, 0, 0, 0]), Err(DecodeError::InvalidIdCount(0)));
    assert_eq!(HostFrame::parse(&[0xaf, 0, 0, 17]), Err(DecodeError::InvalidIdCount(17)));
    assert_eq!(HostFrame::parse(&[0xaf, 0, 0, 2, 7, 4]), Err(DecodeError::UnknownParamId(4)));
    assert_eq!(HostFrame::parse(&[0xaf, 0, 1, 1, 3, 0, 0]), Err(DecodeError::Truncated { needed: 9, available: 7 }));
    // NaN velocity, +inf write data.
    let nan = f32::NAN.to_le_bytes();
    assert_eq!(
        HostFrame::parse(&[0xa5, 0, 0, 0, 0, nan[0], nan[1], nan[2], nan[3]]),
        Err(DecodeError::NonFinite { offset: 5 })
    );
    let inf = f32::INFINITY.to_le_bytes();
    assert_eq!(
        HostFrame::parse(&[0xaf, 0, 1, 1, 3, inf[0], inf[1], inf[2], inf[3]]),
        Err(DecodeError::NonFinite { offset: 5 })
    );
}

#[test]
fn speed_bound_is_exclusive_and_configurable() {
    let frame = |v: f32| {
        let b = v.to_le_bytes();
        [0xb3, b[0], b[1], b[2], b[3]]
    };
    assert!(ChassisFrame::parse(&frame(19.99)).is_ok());
    assert_eq!(
        ChassisFrame::parse(&frame(-20.0)),
        Err(DecodeError::SpeedOutOfBounds { speed_mps: -20.0, bound_mps: 20.0 })
    );
    let mut strict: FrameBuffer<ChassisFrameDecoder, 128> =
        FrameBuffer::new(ChassisFrameDecoder::new().with_max_speed_mps(2.0).unwrap());
    let mut got = Vec::new();
    strict.push_all(&frame(3.0), |f| got.push(f));
    strict.push_all(&frame(1.0), |f| got.push(f));
    assert_eq!(got, [ChassisFrame::VehicleSpeed(VehicleSpeed { speed_mps: 1.0 })]);
    assert_eq!(strict.counters().rejected_candidates, 1);
    assert!(matches!(strict.decoder().last_rejection(), Some(DecodeError::SpeedOutOfBounds { .. })));
    // A nonsensical bound is refused, not silently ignored.
    for bad in [f32::NAN, f32::INFINITY, 0.0, -1.0] {
        let refused = ChassisFrameDecoder::new().with_max_speed_mps(bad).unwrap_err();
        assert_eq!(refused.bound_mps.to_bits(), bad.to_bits());
    }
}

#[test]
fn all_state_u32_and_reserved_slots_may_hold_any_bits() {
    let mut state = AllState::new(1);
    state.id = 0xFFFF_FFFF; // NaN as f32
    state.error_code = 0x7F80_0000; // +inf as f32
    state.reserved = [f32::NAN, f32::INFINITY, f32::from_bits(0xFFC0_0001)];
    let mut buf = [0u8; 64];
    let n = ChassisFrame::AllState(state).emit(&mut buf).unwrap();
    let ChassisFrame::AllState(back) = ChassisFrame::parse(&buf[..n]).unwrap() else { panic!() };
    assert_eq!((back.id, back.error_code), (0xFFFF_FFFF, 0x7F80_0000));
    assert_eq!(back.reserved.map(f32::to_bits), state.reserved.map(f32::to_bits));
    // ... but not the float fields.
    state.temperature_c = f32::NAN;
    assert_eq!(ChassisFrame::AllState(state).emit(&mut buf), Err(EncodeError::NonFinite { offset: 29 }));
    buf[29..33].copy_from_slice(&f32::NAN.to_le_bytes());
    assert_eq!(ChassisFrame::parse(&buf[..n]), Err(DecodeError::NonFinite { offset: 29 }));
}

#[test]
fn encoders_refuse_non_finite_and_short_buffers() {
    let mut buf = [0u8; 84];
    let nan_control = PcControl { velocity_mps: f32::NAN, curvature_per_m: 0.0 };
    assert_eq!(HostFrame::PcControl(nan_control).emit(&mut buf), Err(EncodeError::NonFinite { offset: 1 }));
    assert_eq!(buf, [0u8; 84], "nothing written");
    let inf_write = AfFrame::speed_write_erpm(0, f32::NEG_INFINITY);
    assert_eq!(HostFrame::Af(inf_write).emit(&mut buf), Err(EncodeError::NonFinite { offset: 5 }));
    assert_eq!(
        HostFrame::PcControl(PcControl::STOP).emit(&mut buf[..8]),
        Err(EncodeError::BufferTooSmall(BufferTooSmall { needed: 9, available: 8 }))
    );
    assert_eq!(
        HostFrame::Af(AfFrame::battery_read(0)).emit(&mut buf[..4]),
        Err(EncodeError::BufferTooSmall(BufferTooSmall { needed: 5, available: 4 }))
    );
    assert_eq!(AfFrame::read(0, &[]), Err(EncodeError::IdCount(0)));
    assert_eq!(AfFrame::read(0, &[ParamId::AllState; 17]), Err(EncodeError::IdCount(17)));
    assert_eq!(PcControl::from_yaw_rate(0.5, f32::INFINITY), Err(EncodeError::NonFinite { offset: 5 }));
    // |v| just above the threshold with a huge yaw rate overflows the quotient.
    assert_eq!(PcControl::from_yaw_rate(0.0011, f32::MAX), Err(EncodeError::NonFinite { offset: 5 }));
}

#[test]
fn curvature_rule_of_spec_4_2() {
    let c = PcControl::from_yaw_rate(0.5, 0.2).unwrap();
    assert_eq!(c.curvature_per_m.to_bits(), 0x3ECC_CCCD);
    assert_eq!(PcControl::from_yaw_rate(0.001, 1.0).unwrap().curvature_per_m, 0.0, "|v| <= 1e-3 drops omega");
    assert_eq!(PcControl::from_yaw_rate(-0.001, 1.0).unwrap().curvature_per_m, 0.0);
    let just_above = PcControl::from_yaw_rate(0.0011, 1.0).unwrap();
    assert!((just_above.curvature_per_m - 909.09).abs() < 0.01);
    let reverse = PcControl::from_yaw_rate(-0.25, 0.5).unwrap();
    assert_eq!(reverse.curvature_per_m, -2.0);
    assert_eq!(reverse.yaw_rate_radps(), 0.5, "reversing keeps the meaning of omega");
}

#[test]
fn decoders_never_panic_on_hostile_headers() {
    // Every 4-byte 0xAF header followed by 80 bytes of 0x07 (a valid ID, and a valid float).
    for rw in 0..=255u8 {
        for n in 0..=255u8 {
            let mut bytes = vec![0xaf, 0x01, rw, n];
            bytes.extend_from_slice(&[0x07; 80]);
            let _ = HostFrame::parse(&bytes);
            let _ = ChassisFrame::parse(&bytes);
            let mut d = ChassisFrameDecoder::new();
            let step = d.decode(&bytes);
            assert!(step.consumed <= bytes.len());
        }
    }
}
