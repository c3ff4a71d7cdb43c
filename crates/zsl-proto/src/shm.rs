//! The shared-memory layouts of the ZSL-1 motor daemon (spec `spline-shm.md`): `/spline_shm`
//! (10240 bytes; the 608-byte `spline_data` at offset 0) and `/imu_shm` (1024 bytes; the
//! 48-byte `nav_imu` at offset 0).
//!
//! The vendor structs are `packed`, but every field is 4 or 8 bytes wide at a multiple of its
//! size, so these little-endian zerocopy types (alignment 1, no padding) have the same bytes.
//! Leg order is FR, FL, RR, RL; joint order abad, hip, knee, foot.
//!
//! The handshake (spec §6) is declared here as layouts for the shared-memory transport:
//! [`SPLINE_COMMAND`] (the controller writes the legs and raises `cmd.consumer_flags[CONTROL]`;
//! the daemon takes them), [`SPLINE_STATE`] (the daemon writes the leg states and raises both
//! `state.consumer_flags`; each consumer takes them with its own flag) and [`IMU_RECORD`] (the
//! timestamp is the record's version).

use robowire_core::shm::{FlaggedBlock, VersionedRecord};
use zerocopy::little_endian::{F32, I32, U32, U64};
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout, Unaligned};

/// Size of the `/spline_shm` object, bytes.
pub const SPLINE_SHM_SIZE: usize = 10240;
/// Size of the `/imu_shm` object, bytes.
pub const IMU_SHM_SIZE: usize = 1024;
/// Default name of the spline object.
pub const SPLINE_SHM_NAME: &str = "/spline_shm";
/// Default name of the IMU object.
pub const IMU_SHM_NAME: &str = "/imu_shm";

/// Offset of `cmd.consumer_flags[CONSUMER_CONTROL]` (u32).
pub const CMD_FLAG_CONTROL_OFFSET: usize = 336;
/// Offset of `cmd.consumer_flags[CONSUMER_OTHER]` (u32; never written by a client).
pub const CMD_FLAG_OTHER_OFFSET: usize = 340;
/// Offset of the state block in `/spline_shm`.
pub const STATE_OFFSET: usize = 344;
/// Offset of `state.consumer_flags[CONSUMER_CONTROL]` (u32).
pub const STATE_FLAG_CONTROL_OFFSET: usize = 600;
/// Offset of `state.consumer_flags[CONSUMER_OTHER]` (u32).
pub const STATE_FLAG_OTHER_OFFSET: usize = 604;
/// Bytes of leg commands at the start of the command block (4 × 84).
pub const CMD_LEGS_LEN: usize = 336;
/// Bytes of leg states at the start of the state block (4 × 64).
pub const STATE_LEGS_LEN: usize = 256;
/// Bytes of `spline_data` a `/spline_shm` region must hold.
pub const SPLINE_DATA_LEN: usize = 608;
/// Bytes of `nav_imu` an `/imu_shm` region must hold.
pub const NAV_IMU_LEN: usize = 48;

/// The command handshake: the four [`LegControl`]s (336 bytes at 0), taken by the daemon with
/// `cmd.consumer_flags[CONTROL]` (offset 336). `consumer_flags[OTHER]` (340) is never written by a
/// client.
pub const SPLINE_COMMAND: FlaggedBlock = FlaggedBlock::new(0, CMD_LEGS_LEN, CMD_FLAG_CONTROL_OFFSET);

/// The state handshake as each consumer sees it: the four [`LegState`]s (256 bytes at 344), with
/// `state.consumer_flags[CONTROL]` (600) and `[OTHER]` (604). The daemon raises both.
pub const SPLINE_STATE: [FlaggedBlock; 2] = [
    FlaggedBlock::new(STATE_OFFSET, STATE_LEGS_LEN, STATE_FLAG_CONTROL_OFFSET),
    FlaggedBlock::new(STATE_OFFSET, STATE_LEGS_LEN, STATE_FLAG_OTHER_OFFSET),
];

/// The IMU record at offset 0 of `/imu_shm`: `timestamp_ns` is its version (0 while a robowire
/// producer updates it), the 40 bytes after it the sample.
pub const IMU_RECORD: VersionedRecord = VersionedRecord::new(0, NAV_IMU_LEN);

/// Legs, in the vendor's order (`LEG_FRONT_RIGHT` … `LEG_BACK_LEFT`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Leg {
    /// Front right (0).
    FrontRight = 0,
    /// Front left (1).
    FrontLeft = 1,
    /// Rear right (2, `LEG_BACK_RIGHT`).
    RearRight = 2,
    /// Rear left (3, `LEG_BACK_LEFT`).
    RearLeft = 3,
}

impl Leg {
    /// All legs in array order.
    pub const ALL: [Leg; 4] = [Leg::FrontRight, Leg::FrontLeft, Leg::RearRight, Leg::RearLeft];

    /// Index in the leg arrays.
    pub const fn index(self) -> usize {
        self as usize
    }

    /// `FR`, `FL`, `RR`, `RL`.
    pub const fn abbreviation(self) -> &'static str {
        match self {
            Self::FrontRight => "FR",
            Self::FrontLeft => "FL",
            Self::RearRight => "RR",
            Self::RearLeft => "RL",
        }
    }
}

/// Joints of a leg, in memory order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum JointIndex {
    /// Hip abduction/adduction.
    Abad = 0,
    /// Hip pitch.
    Hip = 1,
    /// Knee.
    Knee = 2,
    /// Foot (wheel of the ZSL-1W; unused on the ZSL-1).
    Foot = 3,
}

impl JointIndex {
    /// All joints in memory order.
    pub const ALL: [JointIndex; 4] = [JointIndex::Abad, JointIndex::Hip, JointIndex::Knee, JointIndex::Foot];
}

/// Consumers of the flag arrays.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ConsumerIndex {
    /// `CONSUMER_CONTROL` (0): the motion controller.
    Control = 0,
    /// `CONSUMER_OTHER` (1): other modules.
    Other = 1,
}

impl ConsumerIndex {
    /// The state handshake of this consumer (one of [`SPLINE_STATE`]).
    pub const fn state(self) -> FlaggedBlock {
        SPLINE_STATE[self as usize]
    }

    /// The command block with this consumer's flag ([`SPLINE_COMMAND`] for the control consumer,
    /// the one the daemon takes).
    pub const fn command(self) -> FlaggedBlock {
        match self {
            Self::Control => SPLINE_COMMAND,
            Self::Other => SPLINE_COMMAND.for_consumer(CMD_FLAG_OTHER_OFFSET),
        }
    }
}

/// One joint's command, 20 bytes (spec §3.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct JointControl {
    /// Position target, rad.
    pub p_des: F32,
    /// Velocity target, rad/s.
    pub v_des: F32,
    /// Position gain.
    pub kp: F32,
    /// Velocity gain.
    pub kd: F32,
    /// Feed-forward torque, N·m.
    pub t_ff: F32,
}

impl JointControl {
    /// A PD target: `p_des_rad`, `v_des_radps`, gains, feed-forward torque `t_ff_nm`.
    pub fn new(p_des_rad: f32, v_des_radps: f32, kp: f32, kd: f32, t_ff_nm: f32) -> Self {
        Self { p_des: p_des_rad.into(), v_des: v_des_radps.into(), kp: kp.into(), kd: kd.into(), t_ff: t_ff_nm.into() }
    }

    /// The five values, in memory order.
    pub fn values(&self) -> [f32; 5] {
        [self.p_des.get(), self.v_des.get(), self.kp.get(), self.kd.get(), self.t_ff.get()]
    }
}

/// One leg's command, 84 bytes (spec §3.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct LegControl {
    /// Joints abad, hip, knee, foot.
    pub joints: [JointControl; 4],
    /// Always 1 (the header's only value); the encoder writes it.
    pub flags: I32,
}

impl Default for LegControl {
    fn default() -> Self {
        Self { joints: [JointControl::default(); 4], flags: 1.into() }
    }
}

/// The command block, 344 bytes at offset 0 of `/spline_shm` (spec §3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct SplineCommandBlock {
    /// Legs FR, FL, RR, RL.
    pub legs: [LegControl; 4],
    /// `consumer_flags[CONTROL]`, `[OTHER]`: accessed as atomics in the mapping, never copied.
    pub consumer_flags: [U32; 2],
}

impl Default for SplineCommandBlock {
    /// Every joint zero (kp = kd = 0: limp), every leg `flags = 1`.
    fn default() -> Self {
        Self { legs: [LegControl::default(); 4], consumer_flags: [0.into(); 2] }
    }
}

impl SplineCommandBlock {
    /// A joint's command.
    pub fn joint(&self, leg: Leg, joint: JointIndex) -> &JointControl {
        &self.legs[leg.index()].joints[joint as usize]
    }

    /// A joint's command, mutably.
    pub fn joint_mut(&mut self, leg: Leg, joint: JointIndex) -> &mut JointControl {
        &mut self.legs[leg.index()].joints[joint as usize]
    }

    /// The first non-finite value as (leg, joint, field index 0..5 in memory order), if any.
    pub fn first_non_finite(&self) -> Option<(Leg, JointIndex, usize)> {
        // Fast path, one branch-free pass over all 84 words of the legs: NaN and ±inf have an
        // all-ones exponent. (A leg's `flags` word of 1 never matches; anything that does goes
        // to the exact check below.)
        let (words, _) = self.legs.as_bytes().as_chunks::<4>();
        let any = words.iter().fold(false, |acc, w| acc | (u32::from_le_bytes(*w) & 0x7f80_0000 == 0x7f80_0000));
        if !any {
            return None;
        }
        for leg in Leg::ALL {
            for joint in JointIndex::ALL {
                if let Some(field) = self.joint(leg, joint).values().iter().position(|v| !v.is_finite()) {
                    return Some((leg, joint, field));
                }
            }
        }
        None
    }

    /// Writes `flags = 1` on every leg (spec decision 7).
    pub fn normalize(&mut self) {
        for leg in &mut self.legs {
            leg.flags = 1.into();
        }
    }

    /// A copy with `flags = 1` on every leg: what a controller writes.
    pub fn normalized(&self) -> Self {
        let mut copy = *self;
        copy.normalize();
        copy
    }
}

/// `joint_state.flags`: supply voltage, temperature, faults, enable (spec §4.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct JointFlags(pub u32);

/// Fault bits of [`JointFlags`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct JointFaults {
    /// Bit 1.
    pub overvoltage: bool,
    /// Bit 2.
    pub overcurrent: bool,
    /// Bit 3.
    pub over_temperature: bool,
    /// Bit 4.
    pub overspeed: bool,
    /// Bit 5.
    pub dual_encoder: bool,
}

impl JointFaults {
    /// Any fault?
    pub fn any(&self) -> bool {
        self.overvoltage || self.overcurrent || self.over_temperature || self.overspeed || self.dual_encoder
    }
}

impl JointFlags {
    /// Bit 0: motor enabled.
    pub const ENABLED: u32 = 1 << 0;
    /// Bit 1: overvoltage.
    pub const OVERVOLTAGE: u32 = 1 << 1;
    /// Bit 2: overcurrent.
    pub const OVERCURRENT: u32 = 1 << 2;
    /// Bit 3: over-temperature.
    pub const OVER_TEMPERATURE: u32 = 1 << 3;
    /// Bit 4: overspeed.
    pub const OVERSPEED: u32 = 1 << 4;
    /// Bit 5: dual-encoder fault.
    pub const DUAL_ENCODER: u32 = 1 << 5;

    /// Flags from voltage (V, 0..255), temperature (°C, −40..215, clamped) and bits 0..5.
    pub fn new(voltage_v: u8, temperature_c: i16, bits: u32) -> Self {
        let temperature = (temperature_c.clamp(-40, 215) + 40) as u32;
        Self(u32::from(voltage_v) << 16 | temperature << 8 | (bits & 0x3F))
    }

    /// Supply voltage, V (bits 23..16).
    pub fn voltage_v(self) -> u8 {
        (self.0 >> 16) as u8
    }

    /// Temperature, °C (bits 15..8, offset −40).
    pub fn temperature_c(self) -> i16 {
        i16::from((self.0 >> 8) as u8) - 40
    }

    /// Bit 0.
    pub fn enabled(self) -> bool {
        self.0 & Self::ENABLED != 0
    }

    /// Bits 1..5.
    pub fn faults(self) -> JointFaults {
        JointFaults {
            overvoltage: self.0 & Self::OVERVOLTAGE != 0,
            overcurrent: self.0 & Self::OVERCURRENT != 0,
            over_temperature: self.0 & Self::OVER_TEMPERATURE != 0,
            overspeed: self.0 & Self::OVERSPEED != 0,
            dual_encoder: self.0 & Self::DUAL_ENCODER != 0,
        }
    }
}

/// One joint's state, 16 bytes (spec §4.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct JointState {
    /// [`JointFlags`] bits (the header's i32 read as u32).
    pub flags: U32,
    /// Position, rad.
    pub p: F32,
    /// Velocity, rad/s.
    pub v: F32,
    /// Torque, N·m.
    pub t: F32,
}

impl JointState {
    /// The decoded flag word.
    pub fn joint_flags(&self) -> JointFlags {
        JointFlags(self.flags.get())
    }
}

/// One leg's state, 64 bytes (spec §4.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct LegState {
    /// Joints abad, hip, knee, foot.
    pub joints: [JointState; 4],
}

/// The state block, 264 bytes at offset 344 of `/spline_shm` (spec §4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct SplineStateBlock {
    /// Legs FR, FL, RR, RL.
    pub legs: [LegState; 4],
    /// `consumer_flags[CONTROL]`, `[OTHER]`: accessed as atomics in the mapping, never copied.
    pub consumer_flags: [U32; 2],
}

impl SplineStateBlock {
    /// A joint's state.
    pub fn joint(&self, leg: Leg, joint: JointIndex) -> &JointState {
        &self.legs[leg.index()].joints[joint as usize]
    }

    /// A joint's state, mutably.
    pub fn joint_mut(&mut self, leg: Leg, joint: JointIndex) -> &mut JointState {
        &mut self.legs[leg.index()].joints[joint as usize]
    }
}

/// The whole `spline_data`, 608 bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct SplineData {
    /// Command block (offset 0).
    pub cmd: SplineCommandBlock,
    /// State block (offset 344).
    pub state: SplineStateBlock,
}

/// One IMU record, `nav_imu`, 48 bytes at offset 0 of `/imu_shm` (spec §5): the timestamp
/// (the record's version, [`IMU_RECORD`]), then the sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct NavImu {
    /// Sample time, ns (the header's `size_t`; clock undocumented).
    pub timestamp_ns: U64,
    /// The sample.
    pub sample: NavImuSample,
}

/// The 40 bytes of a `nav_imu` after its timestamp.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct NavImuSample {
    /// Acceleration x, y, z, m/s².
    pub acc: [F32; 3],
    /// Angular rate x, y, z, rad/s.
    pub gyro: [F32; 3],
    /// Orientation quaternion w, x, y, z (rotation order ZYX).
    pub q: [F32; 4],
}

// Sizes and offsets of spec §3 – §5, checked at compile time.
const _: () = {
    use core::mem::offset_of;
    assert!(size_of::<JointControl>() == 20);
    assert!(size_of::<LegControl>() == 84);
    assert!(offset_of!(LegControl, flags) == 80);
    assert!(size_of::<SplineCommandBlock>() == 344);
    assert!(offset_of!(SplineCommandBlock, consumer_flags) == CMD_FLAG_CONTROL_OFFSET);
    assert!(size_of::<JointState>() == 16);
    assert!(size_of::<LegState>() == 64);
    assert!(size_of::<SplineStateBlock>() == 264);
    assert!(offset_of!(SplineStateBlock, consumer_flags) == STATE_LEGS_LEN);
    assert!(size_of::<SplineData>() == SPLINE_DATA_LEN);
    assert!(size_of::<[LegControl; 4]>() == CMD_LEGS_LEN);
    assert!(size_of::<[LegState; 4]>() == STATE_LEGS_LEN);
    assert!(SPLINE_STATE[1].end() == SPLINE_DATA_LEN);
    assert!(offset_of!(SplineData, state) == STATE_OFFSET);
    assert!(STATE_OFFSET + STATE_LEGS_LEN == STATE_FLAG_CONTROL_OFFSET);
    assert!(size_of::<NavImu>() == NAV_IMU_LEN);
    assert!(offset_of!(NavImu, sample) == 8);
    assert!(8 + offset_of!(NavImuSample, gyro) == 20);
    assert!(8 + offset_of!(NavImuSample, q) == 32);
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joint_flags_worked_examples() {
        let a = JointFlags(0x0030_4101);
        assert_eq!((a.voltage_v(), a.temperature_c(), a.enabled(), a.faults().any()), (48, 25, true, false));
        let b = JointFlags(0x0030_8C09);
        assert_eq!((b.voltage_v(), b.temperature_c(), b.enabled()), (48, 100, true));
        assert_eq!(b.faults(), JointFaults { over_temperature: true, ..JointFaults::default() });
        assert_eq!(JointFlags::new(48, 25, JointFlags::ENABLED), a);
        assert_eq!(JointFlags::new(0, -100, 0).temperature_c(), -40, "clamped");
    }

    #[test]
    fn offsets_of_the_spec_tables() {
        let mut data = SplineData::default();
        // Field f of joint j of leg l at 84·l + 20·j + rel(f).
        data.cmd.joint_mut(Leg::RearRight, JointIndex::Knee).kd = 7.0.into();
        let bytes = data.as_bytes();
        assert_eq!(&bytes[84 * 2 + 20 * 2 + 12..][..4], &7.0f32.to_le_bytes());
        // State: 344 + 64·l + 16·j + rel(f).
        data.state.joint_mut(Leg::RearLeft, JointIndex::Foot).t = 3.0.into();
        let bytes = data.as_bytes();
        assert_eq!(&bytes[344 + 64 * 3 + 16 * 3 + 12..][..4], &3.0f32.to_le_bytes());
        assert_eq!(&bytes[80..84], &1i32.to_le_bytes(), "leg flags default to 1");
    }
}
