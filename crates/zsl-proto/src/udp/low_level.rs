//! The LowLevel datagrams (spec §7): the 248-byte motor command and the 272-byte state.

use zerocopy::little_endian::{F32, U16, U32};
use zerocopy::{FromBytes, FromZeros, Immutable, IntoBytes, KnownLayout, Unaligned};

use super::{DatagramError, MAGIC_ZSL1, command_codec, state_codec};

/// LowLevel motor command, field-major: `[field][leg]` with the 15 fields of spec §7.1.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct MotorCommand {
    /// Position targets, rad: abad, hip, knee (each legs FR, FL, RR, RL).
    pub q_des: [[F32; 4]; 3],
    /// Velocity targets, rad/s: abad, hip, knee.
    pub qd_des: [[F32; 4]; 3],
    /// Position gains: abad, hip, knee.
    pub kp: [[F32; 4]; 3],
    /// Velocity gains: abad, hip, knee.
    pub kd: [[F32; 4]; 3],
    /// Feed-forward torques, N·m: abad, hip, knee.
    pub tau_ff: [[F32; 4]; 3],
}

impl MotorCommand {
    /// A PD hold: position targets `q_des_rad[joint][leg]` (abad, hip, knee × FR, FL, RR, RL)
    /// with one `kp` and `kd` per joint; zero velocity targets and feed-forward torques.
    pub fn pd_hold(q_des_rad: [[f32; 4]; 3], kp: [f32; 3], kd: [f32; 3]) -> Self {
        let f = |legs: [f32; 4]| legs.map(F32::new);
        Self {
            q_des: q_des_rad.map(f),
            kp: kp.map(|k| [F32::new(k); 4]),
            kd: kd.map(|k| [F32::new(k); 4]),
            ..Self::default()
        }
    }
}

/// LowLevel command, client → dog, 248 bytes (spec §7.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct LowLevelCommand {
    magic: U16,
    /// Reserved, 0.
    pub reserved_02: U16,
    /// The 60 floats.
    pub motor: MotorCommand,
    checksum: U32,
}

/// The nine motor-state arrays of the LowLevel state, `[field][leg]` (spec §7.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct MotorState {
    /// Positions, rad: abad, hip, knee.
    pub q: [[F32; 4]; 3],
    /// Velocities, rad/s: abad, hip, knee.
    pub qd: [[F32; 4]; 3],
    /// Torque feedback, N·m: abad, hip, knee.
    pub tau_fb: [[F32; 4]; 3],
}

/// LowLevel state, dog → client, 272 bytes (spec §7.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct LowLevelState {
    /// `0x5AA5` when motor data is present (`haveMotorData()`).
    pub magic: U16,
    /// Unknown.
    pub unknown_02: [u8; 2],
    /// Motor state.
    pub motor: MotorState,
    /// Quaternion w, x, y, z.
    pub quaternion: [F32; 4],
    /// Angular rate x, y, z, rad/s.
    pub gyro: [F32; 3],
    /// Acceleration x, y, z, m/s².
    pub acc: [F32; 3],
    /// Roll, pitch, yaw, rad.
    pub rpy: [F32; 3],
    /// Unknown.
    pub unknown_c8: [u8; 72],
}

command_codec!(LowLevelCommand, 248, 0xF4);

impl LowLevelCommand {
    /// The command carrying `motor` (magic and checksum are written when encoded).
    pub fn new(motor: MotorCommand) -> Self {
        Self { motor, ..Self::default() }
    }
}

impl Default for LowLevelCommand {
    /// The idle command: all 60 floats zero (kp = kd = 0, nothing driven).
    fn default() -> Self {
        Self::new_zeroed()
    }
}

state_codec!(
    LowLevelState,
    272,
    |s| if s.magic.get() == MAGIC_ZSL1 { Ok(()) } else { Err(DatagramError::Magic(s.magic.get())) },
    |s| s.magic.get() == MAGIC_ZSL1
);

impl LowLevelState {
    /// `haveMotorData()`: the magic `0x5AA5` is present.
    pub fn has_motor_data(&self) -> bool {
        self.magic.get() == MAGIC_ZSL1
    }
}
