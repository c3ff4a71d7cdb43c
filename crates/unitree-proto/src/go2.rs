//! Go2 (`unitree_go`) `LowCmd_` and `LowState_` and their nested types (spec §3).
//!
//! `#[repr(C)]` with little-endian field types of alignment 1: the layout is exactly the
//! declaration order, and every byte of C padding is a private field that robowire keeps at zero.
//! Outside this crate a message can only be made with [`Default`] (a safe command),
//! [`zerocopy::FromZeros::new_zeroed`] (the IDL default) or by decoding, never with non-zero
//! padding that would poison the CRC.

use zerocopy::FromZeros;
use zerocopy::little_endian::{F32, I16, I32, U16, U32};

use crate::layout::idl_struct;

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

idl_struct! {
    /// One motor's command, 36 bytes (spec §3.2).
    pub struct MotorCmd as "MotorCmd_" in MOTOR_CMD_LAYOUT {
        /// 0x01 servo; 0 is the IDL default; other values undocumented.
        pub mode: u8 => scalar(U8),
        _pad0: [u8; 3] => pad,
        /// Position target, rad ([`POS_STOP_F`]: none).
        pub q: F32 => scalar(F32),
        /// Velocity target, rad/s ([`VEL_STOP_F`]: none).
        pub dq: F32 => scalar(F32),
        /// Feed-forward torque, N·m.
        pub tau: F32 => scalar(F32),
        /// Position gain.
        pub kp: F32 => scalar(F32),
        /// Velocity gain.
        pub kd: F32 => scalar(F32),
        /// Reserved.
        pub reserve: [U32; 3] => array(U32),
    }
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
}

idl_struct! {
    /// Battery command, 4 bytes.
    pub struct BmsCmd as "BmsCmd_" in BMS_CMD_LAYOUT {
        /// Battery off.
        pub off: u8 => scalar(U8),
        /// Reserved.
        pub reserve: [u8; 3] => array(U8),
    }
}

idl_struct! {
    /// Go2 low-level command, `unitree_go::msg::dds_::LowCmd_`, 812 bytes (spec §3.1).
    pub struct LowCmd as "LowCmd_" in LOW_CMD_LAYOUT {
        /// [`HEAD`] (0xFE 0xEF).
        pub head: [u8; 2] => array(U8),
        /// [`LEVEL_LOW`] for low-level control.
        pub level_flag: u8 => scalar(U8),
        /// Reserved.
        pub frame_reserve: u8 => scalar(U8),
        /// Serial number.
        pub sn: [U32; 2] => array(U32),
        /// Version.
        pub version: [U32; 2] => array(U32),
        /// Bandwidth.
        pub bandwidth: U16 => scalar(U16),
        _pad0: [u8; 2] => pad,
        /// Motors, joint order FR, FL, RR, RL × hip, thigh, calf; slots 12..19 unused on the Go2.
        pub motor_cmd: [MotorCmd; MOTOR_COUNT] => nested_array(MOTOR_CMD_LAYOUT),
        /// Battery command.
        pub bms_cmd: BmsCmd => nested(BMS_CMD_LAYOUT),
        /// Wireless remote bytes.
        pub wireless_remote: [u8; 40] => array(U8),
        /// LEDs.
        pub led: [u8; 12] => array(U8),
        /// Fans.
        pub fan: [u8; 2] => array(U8),
        /// GPIO.
        pub gpio: u8 => scalar(U8),
        _pad1: [u8; 1] => pad,
        /// Reserved; the last word the CRC covers.
        pub reserve: U32 => scalar(U32),
        /// CRC of bytes 0..808, written by the encoder.
        pub crc: U32 => scalar(U32),
    }
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

idl_struct! {
    /// IMU sample, 56 bytes (spec §3.4).
    pub struct ImuState as "IMUState_" in IMU_STATE_LAYOUT {
        /// Orientation quaternion (w, x, y, z).
        pub quaternion: [F32; 4] => array(F32),
        /// Angular rate, rad/s.
        pub gyroscope: [F32; 3] => array(F32),
        /// Acceleration, m/s².
        pub accelerometer: [F32; 3] => array(F32),
        /// Roll, pitch, yaw, rad.
        pub rpy: [F32; 3] => array(F32),
        /// Temperature, raw `uint8` (°C).
        pub temperature: u8 => scalar(U8),
        _pad0: [u8; 3] => pad,
    }
}

idl_struct! {
    /// One motor's state, 48 bytes (spec §3.4).
    pub struct MotorState as "MotorState_" in MOTOR_STATE_LAYOUT {
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
        /// Raw position.
        pub q_raw: F32 => scalar(F32),
        /// Raw velocity.
        pub dq_raw: F32 => scalar(F32),
        /// Raw acceleration.
        pub ddq_raw: F32 => scalar(F32),
        /// Temperature, raw `uint8` (°C).
        pub temperature: u8 => scalar(U8),
        _pad1: [u8; 3] => pad,
        /// Lost-frame counter.
        pub lost: U32 => scalar(U32),
        /// Reserved.
        pub reserve: [U32; 2] => array(U32),
    }
}

idl_struct! {
    /// Battery state, 44 bytes, no padding (spec §3.5).
    pub struct BmsState as "BmsState_" in BMS_STATE_LAYOUT {
        /// Version, high byte.
        pub version_high: u8 => scalar(U8),
        /// Version, low byte.
        pub version_low: u8 => scalar(U8),
        /// Status.
        pub status: u8 => scalar(U8),
        /// State of charge, %.
        pub soc: u8 => scalar(U8),
        /// Current, mA.
        pub current: I32 => scalar(I32),
        /// Charge cycles.
        pub cycle: U16 => scalar(U16),
        /// BQ temperatures, raw `uint8`.
        pub bq_ntc: [u8; 2] => array(U8),
        /// MCU temperatures, raw `uint8`.
        pub mcu_ntc: [u8; 2] => array(U8),
        /// Cell voltages, mV.
        pub cell_vol: [U16; 15] => array(U16),
    }
}

idl_struct! {
    /// Go2 low-level state, `unitree_go::msg::dds_::LowState_`, 1180 bytes (spec §3.3).
    pub struct LowState as "LowState_" in LOW_STATE_LAYOUT {
        /// Header bytes.
        pub head: [u8; 2] => array(U8),
        /// Level flag.
        pub level_flag: u8 => scalar(U8),
        /// Reserved.
        pub frame_reserve: u8 => scalar(U8),
        /// Serial number.
        pub sn: [U32; 2] => array(U32),
        /// Version.
        pub version: [U32; 2] => array(U32),
        /// Bandwidth.
        pub bandwidth: U16 => scalar(U16),
        _pad0: [u8; 2] => pad,
        /// IMU.
        pub imu_state: ImuState => nested(IMU_STATE_LAYOUT),
        /// Motors, joint order as in [`LowCmd::motor_cmd`].
        pub motor_state: [MotorState; MOTOR_COUNT] => nested_array(MOTOR_STATE_LAYOUT),
        /// Battery.
        pub bms_state: BmsState => nested(BMS_STATE_LAYOUT),
        /// Foot force, raw.
        pub foot_force: [I16; 4] => array(I16),
        /// Estimated foot force.
        pub foot_force_est: [I16; 4] => array(I16),
        /// Tick counter.
        pub tick: U32 => scalar(U32),
        /// Wireless remote (spec §5.4).
        pub wireless_remote: [u8; 40] => array(U8),
        /// Bit flags.
        pub bit_flag: u8 => scalar(U8),
        _pad1: [u8; 3] => pad,
        /// ADC reel.
        pub adc_reel: F32 => scalar(F32),
        /// NTC temperature 1, raw `uint8`.
        pub temperature_ntc1: u8 => scalar(U8),
        /// NTC temperature 2, raw `uint8`.
        pub temperature_ntc2: u8 => scalar(U8),
        _pad2: [u8; 2] => pad,
        /// Supply voltage, V.
        pub power_v: F32 => scalar(F32),
        /// Supply current, A.
        pub power_a: F32 => scalar(F32),
        /// Fan frequencies (`uint16`).
        pub fan_frequency: [U16; 4] => array(U16),
        /// Reserved; the last word the CRC covers.
        pub reserve: U32 => scalar(U32),
        /// CRC of bytes 0..1176.
        pub crc: U32 => scalar(U32),
    }
}

impl Default for LowState {
    /// Every field zero (the IDL default).
    fn default() -> Self {
        Self::new_zeroed()
    }
}

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
