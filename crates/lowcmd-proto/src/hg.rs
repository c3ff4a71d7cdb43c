//! HG family (G1, H1-2, `unitree_hg`) `LowCmd_` and `LowState_` (spec §7). Same CRC; no golden
//! vectors exist, so sizes, offsets and the all-zero CRCs of the spec are what is checked.

use zerocopy::little_endian::{F32, I16, U32};
use zerocopy::{FromBytes, FromZeros, Immutable, IntoBytes, KnownLayout, Unaligned};

use crate::layout::{Scalar, Shape, StructLayout, field};

/// Motor slots of the HG messages.
pub const HG_MOTOR_COUNT: usize = 35;

const U8: Shape = Shape::Scalar(Scalar::U8);
const I16S: Shape = Shape::Scalar(Scalar::I16);
const U32S: Shape = Shape::Scalar(Scalar::U32);
const F32S: Shape = Shape::Scalar(Scalar::F32);

/// HG motor command, 28 bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct HgMotorCmd {
    /// 1 enables, 0 disables the motor.
    pub mode: u8,
    _pad0: [u8; 3],
    /// Position target, rad.
    pub q: F32,
    /// Velocity target, rad/s.
    pub dq: F32,
    /// Feed-forward torque, N·m.
    pub tau: F32,
    /// Position gain.
    pub kp: F32,
    /// Velocity gain.
    pub kd: F32,
    /// Reserved.
    pub reserve: U32,
}

/// HG low-level command, `unitree_hg::msg::dds_::LowCmd_`, 1004 bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct HgLowCmd {
    /// 0: pitch/roll series control, 1: A/B parallel control.
    pub mode_pr: u8,
    /// Copied from the received state.
    pub mode_machine: u8,
    _pad0: [u8; 2],
    /// Motors.
    pub motor_cmd: [HgMotorCmd; HG_MOTOR_COUNT],
    /// Reserved; the last words the CRC covers.
    pub reserve: [U32; 4],
    /// CRC of bytes 0..1000.
    pub crc: U32,
}

impl Default for HgLowCmd {
    /// Every field zero: every motor disabled (mode 0), nothing moves.
    fn default() -> Self {
        Self::new_zeroed()
    }
}

impl HgLowCmd {
    pub(crate) fn zero_padding_impl(&mut self) {
        self._pad0 = [0; 2];
        for m in &mut self.motor_cmd {
            m._pad0 = [0; 3];
        }
    }
}

/// HG IMU sample, 56 bytes; temperature is `int16`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct HgImuState {
    /// Orientation quaternion (w, x, y, z).
    pub quaternion: [F32; 4],
    /// Angular rate, rad/s.
    pub gyroscope: [F32; 3],
    /// Acceleration, m/s².
    pub accelerometer: [F32; 3],
    /// Roll, pitch, yaw, rad.
    pub rpy: [F32; 3],
    /// Temperature (`int16`).
    pub temperature: I16,
    _pad0: [u8; 2],
}

/// HG motor state, 56 bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct HgMotorState {
    /// Mode.
    pub mode: u8,
    _pad0: [u8; 3],
    /// Position, rad.
    pub q: F32,
    /// Velocity, rad/s.
    pub dq: F32,
    /// Acceleration, rad/s².
    pub ddq: F32,
    /// Estimated torque, N·m.
    pub tau_est: F32,
    /// Temperatures (`int16`).
    pub temperature: [I16; 2],
    /// Voltage, V.
    pub vol: F32,
    /// Sensor words.
    pub sensor: [U32; 2],
    /// Motor state word.
    pub motorstate: U32,
    /// Reserved.
    pub reserve: [U32; 4],
}

/// HG low-level state, `unitree_hg::msg::dds_::LowState_`, 2092 bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct HgLowState {
    /// Version.
    pub version: [U32; 2],
    /// Pitch/roll mode.
    pub mode_pr: u8,
    /// Machine mode.
    pub mode_machine: u8,
    _pad0: [u8; 2],
    /// Tick counter.
    pub tick: U32,
    /// IMU.
    pub imu_state: HgImuState,
    /// Motors.
    pub motor_state: [HgMotorState; HG_MOTOR_COUNT],
    /// Wireless remote.
    pub wireless_remote: [u8; 40],
    /// Reserved; the last words the CRC covers.
    pub reserve: [U32; 4],
    /// CRC of bytes 0..2088.
    pub crc: U32,
}

impl Default for HgLowState {
    /// Every field zero.
    fn default() -> Self {
        Self::new_zeroed()
    }
}

impl HgLowState {
    pub(crate) fn zero_padding_impl(&mut self) {
        self._pad0 = [0; 2];
        self.imu_state._pad0 = [0; 2];
        for m in &mut self.motor_state {
            m._pad0 = [0; 3];
        }
    }
}

/// Layout of [`HgMotorCmd`].
pub static HG_MOTOR_CMD_LAYOUT: StructLayout = StructLayout {
    name: "MotorCmd_",
    size: size_of::<HgMotorCmd>(),
    fields: &[
        field!(HgMotorCmd, mode, U8),
        field!(HgMotorCmd, q, F32S),
        field!(HgMotorCmd, dq, F32S),
        field!(HgMotorCmd, tau, F32S),
        field!(HgMotorCmd, kp, F32S),
        field!(HgMotorCmd, kd, F32S),
        field!(HgMotorCmd, reserve, U32S),
    ],
};

/// Layout of [`HgLowCmd`].
pub static HG_LOW_CMD_LAYOUT: StructLayout = StructLayout {
    name: "LowCmd_",
    size: size_of::<HgLowCmd>(),
    fields: &[
        field!(HgLowCmd, mode_pr, U8),
        field!(HgLowCmd, mode_machine, U8),
        field!(HgLowCmd, motor_cmd, Shape::Struct(&HG_MOTOR_CMD_LAYOUT), [HG_MOTOR_COUNT]),
        field!(HgLowCmd, reserve, U32S, [4]),
        field!(HgLowCmd, crc, U32S),
    ],
};

/// Layout of [`HgImuState`].
pub static HG_IMU_STATE_LAYOUT: StructLayout = StructLayout {
    name: "IMUState_",
    size: size_of::<HgImuState>(),
    fields: &[
        field!(HgImuState, quaternion, F32S, [4]),
        field!(HgImuState, gyroscope, F32S, [3]),
        field!(HgImuState, accelerometer, F32S, [3]),
        field!(HgImuState, rpy, F32S, [3]),
        field!(HgImuState, temperature, I16S),
    ],
};

/// Layout of [`HgMotorState`].
pub static HG_MOTOR_STATE_LAYOUT: StructLayout = StructLayout {
    name: "MotorState_",
    size: size_of::<HgMotorState>(),
    fields: &[
        field!(HgMotorState, mode, U8),
        field!(HgMotorState, q, F32S),
        field!(HgMotorState, dq, F32S),
        field!(HgMotorState, ddq, F32S),
        field!(HgMotorState, tau_est, F32S),
        field!(HgMotorState, temperature, I16S, [2]),
        field!(HgMotorState, vol, F32S),
        field!(HgMotorState, sensor, U32S, [2]),
        field!(HgMotorState, motorstate, U32S),
        field!(HgMotorState, reserve, U32S, [4]),
    ],
};

/// Layout of [`HgLowState`].
pub static HG_LOW_STATE_LAYOUT: StructLayout = StructLayout {
    name: "LowState_",
    size: size_of::<HgLowState>(),
    fields: &[
        field!(HgLowState, version, U32S, [2]),
        field!(HgLowState, mode_pr, U8),
        field!(HgLowState, mode_machine, U8),
        field!(HgLowState, tick, U32S),
        field!(HgLowState, imu_state, Shape::Struct(&HG_IMU_STATE_LAYOUT)),
        field!(HgLowState, motor_state, Shape::Struct(&HG_MOTOR_STATE_LAYOUT), [HG_MOTOR_COUNT]),
        field!(HgLowState, wireless_remote, U8, [40]),
        field!(HgLowState, reserve, U32S, [4]),
        field!(HgLowState, crc, U32S),
    ],
};

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
