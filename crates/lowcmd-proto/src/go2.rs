//! Go2 (`unitree_go`) `LowCmd_` and `LowState_` and their nested types (spec §3).
//!
//! `#[repr(C)]` with little-endian field types of alignment 1: the layout is exactly the
//! declaration order, and every byte of C padding is a private field that robowire keeps at zero.
//! Outside this crate a message can only be made with [`Default`] (a safe command),
//! [`zerocopy::FromZeros::new_zeroed`] (the IDL default) or by decoding, never with non-zero
//! padding that would poison the CRC.

use zerocopy::little_endian::{F32, I16, I32, U16, U32};
use zerocopy::{FromBytes, FromZeros, Immutable, IntoBytes, KnownLayout, Unaligned};

use crate::layout::{Scalar, Shape, StructLayout, field};

/// `head` of every `LowCmd_` the vendor examples send.
pub const HEAD: [u8; 2] = [0xFE, 0xEF];
/// `level_flag` for low-level control (`LOWLEVEL`).
pub const LEVEL_LOW: u8 = 0xFF;
/// `level_flag` `HIGHLEVEL` (unused by the Go2 low-level examples).
pub const LEVEL_HIGH: u8 = 0xEE;
/// `level_flag` `TRIGERLEVEL` (vendor spelling; unused by the Go2 examples).
pub const LEVEL_TRIGGER: u8 = 0xF0;
/// `MotorCmd_.mode`: servo (FOC, PMSM) mode, set on all 20 slots by the vendor examples.
pub const MOTOR_MODE_SERVO: u8 = 0x01;
/// `PosStopF`: in `q`, "no position target" (bits `0x4EFFD2B9`).
pub const POS_STOP_F: f32 = 2.146e9;
/// `VelStopF`: in `dq`, "no velocity target" (bits `0x467A0000`).
pub const VEL_STOP_F: f32 = 16000.0;
/// Motor slots in both messages; the Go2 drives the first 12.
pub const MOTOR_COUNT: usize = 20;

const U8: Shape = Shape::Scalar(Scalar::U8);
const U16S: Shape = Shape::Scalar(Scalar::U16);
const I16S: Shape = Shape::Scalar(Scalar::I16);
const U32S: Shape = Shape::Scalar(Scalar::U32);
const I32S: Shape = Shape::Scalar(Scalar::I32);
const F32S: Shape = Shape::Scalar(Scalar::F32);

/// One motor's command, 36 bytes (spec §3.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct MotorCmd {
    /// 0x01 servo; 0 is the IDL default; other values undocumented.
    pub mode: u8,
    _pad0: [u8; 3],
    /// Position target, rad ([`POS_STOP_F`]: none).
    pub q: F32,
    /// Velocity target, rad/s ([`VEL_STOP_F`]: none).
    pub dq: F32,
    /// Feed-forward torque, N·m.
    pub tau: F32,
    /// Position gain.
    pub kp: F32,
    /// Velocity gain.
    pub kd: F32,
    /// Reserved.
    pub reserve: [U32; 3],
}

impl MotorCmd {
    /// Servo mode with no position or velocity target and zero gains and torque: the motor
    /// holds no position and exerts no torque.
    pub fn hold_nothing() -> Self {
        Self::servo(POS_STOP_F, VEL_STOP_F, 0.0, 0.0, 0.0)
    }

    /// Servo mode with the given targets: `q` rad, `dq` rad/s, gains `kp`, `kd`, torque `tau` N·m.
    pub fn servo(q: f32, dq: f32, kp: f32, kd: f32, tau: f32) -> Self {
        let mut cmd = Self::new_zeroed();
        cmd.mode = MOTOR_MODE_SERVO;
        cmd.q = q.into();
        cmd.dq = dq.into();
        cmd.kp = kp.into();
        cmd.kd = kd.into();
        cmd.tau = tau.into();
        cmd
    }

    pub(crate) fn zero_padding(&mut self) {
        self._pad0 = [0; 3];
    }
}

/// Battery command, 4 bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct BmsCmd {
    /// Battery off.
    pub off: u8,
    /// Reserved.
    pub reserve: [u8; 3],
}

/// Go2 low-level command, `unitree_go::msg::dds_::LowCmd_`, 812 bytes (spec §3.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct LowCmd {
    /// [`HEAD`] (0xFE 0xEF).
    pub head: [u8; 2],
    /// [`LEVEL_LOW`] for low-level control.
    pub level_flag: u8,
    /// Reserved.
    pub frame_reserve: u8,
    /// Serial number.
    pub sn: [U32; 2],
    /// Version.
    pub version: [U32; 2],
    /// Bandwidth.
    pub bandwidth: U16,
    _pad0: [u8; 2],
    /// Motors, joint order FR, FL, RR, RL × hip, thigh, calf; slots 12..19 unused on the Go2.
    pub motor_cmd: [MotorCmd; MOTOR_COUNT],
    /// Battery command.
    pub bms_cmd: BmsCmd,
    /// Wireless remote bytes.
    pub wireless_remote: [u8; 40],
    /// LEDs.
    pub led: [u8; 12],
    /// Fans.
    pub fan: [u8; 2],
    /// GPIO.
    pub gpio: u8,
    _pad1: [u8; 1],
    /// Reserved; the last word the CRC covers.
    pub reserve: U32,
    /// CRC of bytes 0..808, written by the encoder.
    pub crc: U32,
}

impl Default for LowCmd {
    /// The safe command: [`HEAD`], [`LEVEL_LOW`], and every motor in servo mode with
    /// [`MotorCmd::hold_nothing`]. Sending it never moves a joint.
    fn default() -> Self {
        let mut cmd = Self::new_zeroed();
        cmd.head = HEAD;
        cmd.level_flag = LEVEL_LOW;
        cmd.motor_cmd = [MotorCmd::hold_nothing(); MOTOR_COUNT];
        cmd
    }
}

impl LowCmd {
    pub(crate) fn zero_padding_impl(&mut self) {
        self._pad0 = [0; 2];
        self._pad1 = [0; 1];
        self.motor_cmd.iter_mut().for_each(MotorCmd::zero_padding);
    }
}

/// IMU sample, 56 bytes (spec §3.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct ImuState {
    /// Orientation quaternion (w, x, y, z).
    pub quaternion: [F32; 4],
    /// Angular rate, rad/s.
    pub gyroscope: [F32; 3],
    /// Acceleration, m/s².
    pub accelerometer: [F32; 3],
    /// Roll, pitch, yaw, rad.
    pub rpy: [F32; 3],
    /// Temperature, raw `uint8` (°C).
    pub temperature: u8,
    _pad0: [u8; 3],
}

/// One motor's state, 48 bytes (spec §3.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct MotorState {
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
    /// Raw position.
    pub q_raw: F32,
    /// Raw velocity.
    pub dq_raw: F32,
    /// Raw acceleration.
    pub ddq_raw: F32,
    /// Temperature, raw `uint8` (°C).
    pub temperature: u8,
    _pad1: [u8; 3],
    /// Lost-frame counter.
    pub lost: U32,
    /// Reserved.
    pub reserve: [U32; 2],
}

/// Battery state, 44 bytes, no padding (spec §3.5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct BmsState {
    /// Version, high byte.
    pub version_high: u8,
    /// Version, low byte.
    pub version_low: u8,
    /// Status.
    pub status: u8,
    /// State of charge, %.
    pub soc: u8,
    /// Current, mA.
    pub current: I32,
    /// Charge cycles.
    pub cycle: U16,
    /// BQ temperatures, raw `uint8`.
    pub bq_ntc: [u8; 2],
    /// MCU temperatures, raw `uint8`.
    pub mcu_ntc: [u8; 2],
    /// Cell voltages, mV.
    pub cell_vol: [U16; 15],
}

/// Go2 low-level state, `unitree_go::msg::dds_::LowState_`, 1180 bytes (spec §3.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct LowState {
    /// Header bytes.
    pub head: [u8; 2],
    /// Level flag.
    pub level_flag: u8,
    /// Reserved.
    pub frame_reserve: u8,
    /// Serial number.
    pub sn: [U32; 2],
    /// Version.
    pub version: [U32; 2],
    /// Bandwidth.
    pub bandwidth: U16,
    _pad0: [u8; 2],
    /// IMU.
    pub imu_state: ImuState,
    /// Motors, joint order as in [`LowCmd::motor_cmd`].
    pub motor_state: [MotorState; MOTOR_COUNT],
    /// Battery.
    pub bms_state: BmsState,
    /// Foot force, raw.
    pub foot_force: [I16; 4],
    /// Estimated foot force.
    pub foot_force_est: [I16; 4],
    /// Tick counter.
    pub tick: U32,
    /// Wireless remote (spec §5.4).
    pub wireless_remote: [u8; 40],
    /// Bit flags.
    pub bit_flag: u8,
    _pad1: [u8; 3],
    /// ADC reel.
    pub adc_reel: F32,
    /// NTC temperature 1, raw `uint8`.
    pub temperature_ntc1: u8,
    /// NTC temperature 2, raw `uint8`.
    pub temperature_ntc2: u8,
    _pad2: [u8; 2],
    /// Supply voltage, V.
    pub power_v: F32,
    /// Supply current, A.
    pub power_a: F32,
    /// Fan frequencies (`uint16`).
    pub fan_frequency: [U16; 4],
    /// Reserved; the last word the CRC covers.
    pub reserve: U32,
    /// CRC of bytes 0..1176.
    pub crc: U32,
}

impl Default for LowState {
    /// Every field zero (the IDL default).
    fn default() -> Self {
        Self::new_zeroed()
    }
}

impl LowState {
    pub(crate) fn zero_padding_impl(&mut self) {
        self._pad0 = [0; 2];
        self._pad1 = [0; 3];
        self._pad2 = [0; 2];
        self.imu_state._pad0 = [0; 3];
        for m in &mut self.motor_state {
            m._pad0 = [0; 3];
            m._pad1 = [0; 3];
        }
    }
}

/// Layout of [`MotorCmd`].
pub static MOTOR_CMD_LAYOUT: StructLayout = StructLayout {
    name: "MotorCmd_",
    size: size_of::<MotorCmd>(),
    fields: &[
        field!(MotorCmd, mode, U8),
        field!(MotorCmd, q, F32S),
        field!(MotorCmd, dq, F32S),
        field!(MotorCmd, tau, F32S),
        field!(MotorCmd, kp, F32S),
        field!(MotorCmd, kd, F32S),
        field!(MotorCmd, reserve, U32S, [3]),
    ],
};

/// Layout of [`BmsCmd`].
pub static BMS_CMD_LAYOUT: StructLayout = StructLayout {
    name: "BmsCmd_",
    size: size_of::<BmsCmd>(),
    fields: &[field!(BmsCmd, off, U8), field!(BmsCmd, reserve, U8, [3])],
};

/// Layout of [`LowCmd`].
pub static LOW_CMD_LAYOUT: StructLayout = StructLayout {
    name: "LowCmd_",
    size: size_of::<LowCmd>(),
    fields: &[
        field!(LowCmd, head, U8, [2]),
        field!(LowCmd, level_flag, U8),
        field!(LowCmd, frame_reserve, U8),
        field!(LowCmd, sn, U32S, [2]),
        field!(LowCmd, version, U32S, [2]),
        field!(LowCmd, bandwidth, U16S),
        field!(LowCmd, motor_cmd, Shape::Struct(&MOTOR_CMD_LAYOUT), [MOTOR_COUNT]),
        field!(LowCmd, bms_cmd, Shape::Struct(&BMS_CMD_LAYOUT)),
        field!(LowCmd, wireless_remote, U8, [40]),
        field!(LowCmd, led, U8, [12]),
        field!(LowCmd, fan, U8, [2]),
        field!(LowCmd, gpio, U8),
        field!(LowCmd, reserve, U32S),
        field!(LowCmd, crc, U32S),
    ],
};

/// Layout of [`ImuState`].
pub static IMU_STATE_LAYOUT: StructLayout = StructLayout {
    name: "IMUState_",
    size: size_of::<ImuState>(),
    fields: &[
        field!(ImuState, quaternion, F32S, [4]),
        field!(ImuState, gyroscope, F32S, [3]),
        field!(ImuState, accelerometer, F32S, [3]),
        field!(ImuState, rpy, F32S, [3]),
        field!(ImuState, temperature, U8),
    ],
};

/// Layout of [`MotorState`].
pub static MOTOR_STATE_LAYOUT: StructLayout = StructLayout {
    name: "MotorState_",
    size: size_of::<MotorState>(),
    fields: &[
        field!(MotorState, mode, U8),
        field!(MotorState, q, F32S),
        field!(MotorState, dq, F32S),
        field!(MotorState, ddq, F32S),
        field!(MotorState, tau_est, F32S),
        field!(MotorState, q_raw, F32S),
        field!(MotorState, dq_raw, F32S),
        field!(MotorState, ddq_raw, F32S),
        field!(MotorState, temperature, U8),
        field!(MotorState, lost, U32S),
        field!(MotorState, reserve, U32S, [2]),
    ],
};

/// Layout of [`BmsState`].
pub static BMS_STATE_LAYOUT: StructLayout = StructLayout {
    name: "BmsState_",
    size: size_of::<BmsState>(),
    fields: &[
        field!(BmsState, version_high, U8),
        field!(BmsState, version_low, U8),
        field!(BmsState, status, U8),
        field!(BmsState, soc, U8),
        field!(BmsState, current, I32S),
        field!(BmsState, cycle, U16S),
        field!(BmsState, bq_ntc, U8, [2]),
        field!(BmsState, mcu_ntc, U8, [2]),
        field!(BmsState, cell_vol, U16S, [15]),
    ],
};

/// Layout of [`LowState`].
pub static LOW_STATE_LAYOUT: StructLayout = StructLayout {
    name: "LowState_",
    size: size_of::<LowState>(),
    fields: &[
        field!(LowState, head, U8, [2]),
        field!(LowState, level_flag, U8),
        field!(LowState, frame_reserve, U8),
        field!(LowState, sn, U32S, [2]),
        field!(LowState, version, U32S, [2]),
        field!(LowState, bandwidth, U16S),
        field!(LowState, imu_state, Shape::Struct(&IMU_STATE_LAYOUT)),
        field!(LowState, motor_state, Shape::Struct(&MOTOR_STATE_LAYOUT), [MOTOR_COUNT]),
        field!(LowState, bms_state, Shape::Struct(&BMS_STATE_LAYOUT)),
        field!(LowState, foot_force, I16S, [4]),
        field!(LowState, foot_force_est, I16S, [4]),
        field!(LowState, tick, U32S),
        field!(LowState, wireless_remote, U8, [40]),
        field!(LowState, bit_flag, U8),
        field!(LowState, adc_reel, F32S),
        field!(LowState, temperature_ntc1, U8),
        field!(LowState, temperature_ntc2, U8),
        field!(LowState, power_v, F32S),
        field!(LowState, power_a, F32S),
        field!(LowState, fan_frequency, U16S, [4]),
        field!(LowState, reserve, U32S),
        field!(LowState, crc, U32S),
    ],
};

// Sizes and offsets of spec §3, checked at compile time.
const _: () = {
    use core::mem::offset_of;
    assert!(size_of::<MotorCmd>() == 36);
    assert!(size_of::<BmsCmd>() == 4);
    assert!(size_of::<LowCmd>() == 812);
    assert!(offset_of!(LowCmd, motor_cmd) == 24);
    assert!(offset_of!(LowCmd, bms_cmd) == 744);
    assert!(offset_of!(LowCmd, wireless_remote) == 748);
    assert!(offset_of!(LowCmd, led) == 788);
    assert!(offset_of!(LowCmd, fan) == 800);
    assert!(offset_of!(LowCmd, gpio) == 802);
    assert!(offset_of!(LowCmd, reserve) == 804);
    assert!(offset_of!(LowCmd, crc) == 808);
    assert!(offset_of!(MotorCmd, q) == 4);
    assert!(offset_of!(MotorCmd, reserve) == 24);
    assert!(size_of::<ImuState>() == 56);
    assert!(size_of::<MotorState>() == 48);
    assert!(size_of::<BmsState>() == 44);
    assert!(size_of::<LowState>() == 1180);
    assert!(offset_of!(LowState, imu_state) == 24);
    assert!(offset_of!(LowState, motor_state) == 80);
    assert!(offset_of!(LowState, bms_state) == 1040);
    assert!(offset_of!(LowState, foot_force) == 1084);
    assert!(offset_of!(LowState, foot_force_est) == 1092);
    assert!(offset_of!(LowState, tick) == 1100);
    assert!(offset_of!(LowState, wireless_remote) == 1104);
    assert!(offset_of!(LowState, bit_flag) == 1144);
    assert!(offset_of!(LowState, adc_reel) == 1148);
    assert!(offset_of!(LowState, temperature_ntc1) == 1152);
    assert!(offset_of!(LowState, power_v) == 1156);
    assert!(offset_of!(LowState, fan_frequency) == 1164);
    assert!(offset_of!(LowState, reserve) == 1172);
    assert!(offset_of!(LowState, crc) == 1176);
    assert!(offset_of!(MotorState, temperature) == 32);
    assert!(offset_of!(MotorState, lost) == 36);
    assert!(offset_of!(BmsState, cell_vol) == 14);
};
