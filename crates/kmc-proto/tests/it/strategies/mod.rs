//! proptest strategies for every KMC frame type (shared by the integration tests).

#![allow(dead_code, unreachable_pub, missing_docs)]

use kmc_proto::{AfFrame, AllState, BatteryVoltage, ChassisFrame, HostFrame, ParamId, PcControl, VehicleSpeed};
use proptest::prelude::*;

/// Any finite f32, including subnormals, ±0 and extremes.
pub fn finite_f32() -> impl Strategy<Value = f32> {
    any::<u32>().prop_map(f32::from_bits).prop_filter("finite", |v| v.is_finite())
}

/// Any f32 bit pattern, NaN payloads included.
pub fn any_bits_f32() -> impl Strategy<Value = f32> {
    any::<u32>().prop_map(f32::from_bits)
}

pub fn param_id() -> impl Strategy<Value = ParamId> {
    prop_oneof![
        Just(ParamId::SystemReset),
        Just(ParamId::SpeedErpm),
        Just(ParamId::ServoPulseUs),
        Just(ParamId::AllState),
        Just(ParamId::BatteryVoltage),
    ]
}

pub fn pc_control() -> impl Strategy<Value = PcControl> {
    (finite_f32(), finite_f32()).prop_map(|(velocity_mps, curvature_per_m)| PcControl { velocity_mps, curvature_per_m })
}

pub fn af_request() -> impl Strategy<Value = AfFrame> {
    let read = (any::<u8>(), prop::collection::vec(param_id(), 1..=16))
        .prop_map(|(motor, ids)| AfFrame::read(motor, &ids).unwrap());
    let write = (any::<u8>(), prop::collection::vec((param_id(), finite_f32()), 1..=16))
        .prop_map(|(motor, entries)| AfFrame::write(motor, &entries).unwrap());
    prop_oneof![read, write]
}

pub fn host_frame() -> impl Strategy<Value = HostFrame> {
    prop_oneof![
        pc_control().prop_map(HostFrame::PcControl),
        Just(HostFrame::VehicleSpeedRequest),
        af_request().prop_map(HostFrame::Af),
    ]
}

pub fn vehicle_speed() -> impl Strategy<Value = VehicleSpeed> {
    (-19.999f32..19.999).prop_map(|speed_mps| VehicleSpeed { speed_mps })
}

pub fn all_state() -> impl Strategy<Value = AllState> {
    (
        any::<u8>(),
        any::<u32>(),
        (finite_f32(), finite_f32(), finite_f32(), finite_f32()),
        any::<u32>(),
        (any_bits_f32(), any_bits_f32(), any_bits_f32()),
    )
        .prop_map(|(motor_id, id, (p, s, c, t), error_code, (r0, r1, r2))| AllState {
            motor_id,
            ids: AllState::IDS,
            id,
            position_deg: p,
            speed_rpm: s,
            current_a: c,
            temperature_c: t,
            error_code,
            reserved: [r0, r1, r2],
        })
}

/// Raw responses: slots whose ID is 0x06 hold any bits, the others finite floats. Frames that
/// spec §6.1 maps to [`BatteryVoltage`] or [`AllState`] are left out.
pub fn af_response() -> impl Strategy<Value = AfFrame> {
    let entries = prop::collection::vec((param_id(), any::<u32>(), finite_f32()), 1..=16)
        .prop_filter("typed responses are not raw", |e| {
            !((e.len() == 1 && e[0].0 == ParamId::BatteryVoltage) || (e.len() == 9 && e[0].0 == ParamId::AllState))
        });
    (any::<u8>(), entries).prop_map(|(motor, entries)| {
        let raw: Vec<(ParamId, [u8; 4])> = entries
            .iter()
            .map(|&(id, bits, value)| {
                (id, if id == ParamId::AllState { bits.to_le_bytes() } else { value.to_le_bytes() })
            })
            .collect();
        AfFrame::write_raw(motor, &raw).unwrap()
    })
}

pub fn chassis_frame() -> impl Strategy<Value = ChassisFrame> {
    prop_oneof![
        vehicle_speed().prop_map(ChassisFrame::VehicleSpeed),
        (any::<u8>(), finite_f32())
            .prop_map(|(motor_id, volts)| ChassisFrame::BatteryVoltage(BatteryVoltage { motor_id, volts })),
        all_state().prop_map(ChassisFrame::AllState),
        af_response().prop_map(ChassisFrame::Af),
    ]
}

pub fn emit_host(frame: &HostFrame) -> Vec<u8> {
    let mut buf = [0u8; kmc_proto::MAX_FRAME_LEN];
    let n = frame.emit(&mut buf).expect("strategy frames encode");
    buf[..n].to_vec()
}

pub fn emit_chassis(frame: &ChassisFrame) -> Vec<u8> {
    let mut buf = [0u8; kmc_proto::MAX_FRAME_LEN];
    let n = frame.emit(&mut buf).expect("strategy frames encode");
    buf[..n].to_vec()
}
