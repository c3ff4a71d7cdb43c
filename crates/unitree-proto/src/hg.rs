//! HG family (G1, H1-2, `unitree_hg`) `LowCmd_` and `LowState_` (spec §7). Same CRC; no golden
//! vectors exist, so sizes, offsets and the all-zero CRCs of the spec are what is checked.

use zerocopy::FromZeros;
use zerocopy::little_endian::{F32, I16, U32};

use crate::layout::idl_struct;

/// Motor slots of the HG messages.
pub const HG_MOTOR_COUNT: usize = 35;

idl_struct! {
    /// HG motor command, 28 bytes.
    pub struct HgMotorCmd as "MotorCmd_" in HG_MOTOR_CMD_LAYOUT {
        /// 1 enables, 0 disables the motor.
        pub mode: u8 => scalar(U8),
        _pad0: [u8; 3] => pad,
        /// Position target, rad.
        pub q: F32 => scalar(F32),
        /// Velocity target, rad/s.
        pub dq: F32 => scalar(F32),
        /// Feed-forward torque, N·m.
        pub tau: F32 => scalar(F32),
        /// Position gain.
        pub kp: F32 => scalar(F32),
        /// Velocity gain.
        pub kd: F32 => scalar(F32),
        /// Reserved.
        pub reserve: U32 => scalar(U32),
    }
}

impl Default for HgMotorCmd {
    /// Disabled, every field zero.
    fn default() -> Self {
        Self::new_zeroed()
    }
}

impl HgMotorCmd {
    /// Enabled (mode 1) with the given targets: `q` rad, `dq` rad/s, gains `kp`, `kd`, torque
    /// `tau` N·m.
    pub fn servo(q: f32, dq: f32, kp: f32, kd: f32, tau: f32) -> Self {
        let mut cmd = Self::new_zeroed();
        cmd.mode = 1;
        cmd.q = q.into();
        cmd.dq = dq.into();
        cmd.kp = kp.into();
        cmd.kd = kd.into();
        cmd.tau = tau.into();
        cmd
    }
}

idl_struct! {
    /// HG low-level command, `unitree_hg::msg::dds_::LowCmd_`, 1004 bytes.
    pub struct HgLowCmd as "LowCmd_" in HG_LOW_CMD_LAYOUT {
        /// 0: pitch/roll series control, 1: A/B parallel control.
        pub mode_pr: u8 => scalar(U8),
        /// Copied from the received state.
        pub mode_machine: u8 => scalar(U8),
        _pad0: [u8; 2] => pad,
        /// Motors.
        pub motor_cmd: [HgMotorCmd; HG_MOTOR_COUNT] => nested_array(HG_MOTOR_CMD_LAYOUT),
        /// Reserved; the last words the CRC covers.
        pub reserve: [U32; 4] => array(U32),
        /// CRC of bytes 0..1000.
        pub crc: U32 => scalar(U32),
    }
}

impl Default for HgLowCmd {
    /// Every field zero: every motor disabled (mode 0), nothing moves.
    fn default() -> Self {
        Self::new_zeroed()
    }
}

idl_struct! {
    /// HG IMU sample, 56 bytes; temperature is `int16`.
    pub struct HgImuState as "IMUState_" in HG_IMU_STATE_LAYOUT {
        /// Orientation quaternion (w, x, y, z).
        pub quaternion: [F32; 4] => array(F32),
        /// Angular rate, rad/s.
        pub gyroscope: [F32; 3] => array(F32),
        /// Acceleration, m/s².
        pub accelerometer: [F32; 3] => array(F32),
        /// Roll, pitch, yaw, rad.
        pub rpy: [F32; 3] => array(F32),
        /// Temperature (`int16`).
        pub temperature: I16 => scalar(I16),
        _pad0: [u8; 2] => pad,
    }
}

idl_struct! {
    /// HG motor state, 56 bytes.
    pub struct HgMotorState as "MotorState_" in HG_MOTOR_STATE_LAYOUT {
        /// Mode.
        pub mode: u8 => scalar(U8),
        _pad0: [u8; 3] => pad,
        /// Position, rad.
        pub q: F32 => scalar(F32),
        /// Velocity, rad/s.
        pub dq: F32 => scalar(F32),
        /// Acceleration, rad/s².
        pub ddq: F32 => scalar(F32),
        /// Estimated torque, N·m.
        pub tau_est: F32 => scalar(F32),
        /// Temperatures (`int16`).
        pub temperature: [I16; 2] => array(I16),
        /// Voltage, V.
        pub vol: F32 => scalar(F32),
        /// Sensor words.
        pub sensor: [U32; 2] => array(U32),
        /// Motor state word.
        pub motorstate: U32 => scalar(U32),
        /// Reserved.
        pub reserve: [U32; 4] => array(U32),
    }
}

idl_struct! {
    /// HG low-level state, `unitree_hg::msg::dds_::LowState_`, 2092 bytes.
    pub struct HgLowState as "LowState_" in HG_LOW_STATE_LAYOUT {
        /// Version.
        pub version: [U32; 2] => array(U32),
        /// Pitch/roll mode.
        pub mode_pr: u8 => scalar(U8),
        /// Machine mode.
        pub mode_machine: u8 => scalar(U8),
        _pad0: [u8; 2] => pad,
        /// Tick counter.
        pub tick: U32 => scalar(U32),
        /// IMU.
        pub imu_state: HgImuState => nested(HG_IMU_STATE_LAYOUT),
        /// Motors.
        pub motor_state: [HgMotorState; HG_MOTOR_COUNT] => nested_array(HG_MOTOR_STATE_LAYOUT),
        /// Wireless remote.
        pub wireless_remote: [u8; 40] => array(U8),
        /// Reserved; the last words the CRC covers.
        pub reserve: [U32; 4] => array(U32),
        /// CRC of bytes 0..2088.
        pub crc: U32 => scalar(U32),
    }
}

impl Default for HgLowState {
    /// Every field zero.
    fn default() -> Self {
        Self::new_zeroed()
    }
}

// Sizes and offsets of spec §7, checked at compile time.
const _: () = {
    use core::mem::offset_of;
    assert!(size_of::<HgMotorCmd>() == 28);
    assert!(size_of::<HgLowCmd>() == 1004);
    assert!(offset_of!(HgLowCmd, motor_cmd) == 4);
    assert!(offset_of!(HgLowCmd, reserve) == 984);
    assert!(offset_of!(HgLowCmd, crc) == 1000);
    assert!(size_of::<HgImuState>() == 56);
    assert!(offset_of!(HgImuState, temperature) == 52);
    assert!(size_of::<HgMotorState>() == 56);
    assert!(offset_of!(HgMotorState, temperature) == 20);
    assert!(offset_of!(HgMotorState, vol) == 24);
    assert!(offset_of!(HgMotorState, sensor) == 28);
    assert!(offset_of!(HgMotorState, motorstate) == 36);
    assert!(offset_of!(HgMotorState, reserve) == 40);
    assert!(size_of::<HgLowState>() == 2092);
    assert!(offset_of!(HgLowState, tick) == 12);
    assert!(offset_of!(HgLowState, imu_state) == 16);
    assert!(offset_of!(HgLowState, motor_state) == 72);
    assert!(offset_of!(HgLowState, wireless_remote) == 2032);
    assert!(offset_of!(HgLowState, reserve) == 2072);
    assert!(offset_of!(HgLowState, crc) == 2088);
};
