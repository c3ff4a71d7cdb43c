//! The ZSL-1 / ZSL-1W UDP datagrams (spec `zsl1-udp.md`): HighLevel command (40 bytes) and state
//! (560), LowLevel command (248) and state (272). Little-endian, no padding.
//!
//! Commands carry a magic and a checksum that only the encoder writes; every reserved or
//! unknown byte is a field that round-trips unchanged.

use zerocopy::little_endian::{F32, U16, U32};
use zerocopy::{FromBytes, FromZeros, Immutable, IntoBytes, KnownLayout, Unaligned};

/// UDP port of the HighLevel interface on the dog.
pub const HIGH_LEVEL_PORT: u16 = 43997;
/// UDP port of the LowLevel interface on the dog.
pub const LOW_LEVEL_PORT: u16 = 43900;
/// The vendor's default client port (the robot's configured state target).
pub const DEFAULT_LOCAL_PORT: u16 = 43988;
/// Magic of ZSL-1 commands and of the LowLevel state (`a5 5a`).
pub const MAGIC_ZSL1: u16 = 0x5AA5;
/// Magic of ZSL-1W commands (`a6 5a`).
pub const MAGIC_ZSL1W: u16 = 0x5AA6;

/// Why a datagram is not what it should be.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum DatagramError {
    /// Not the datagram's length.
    #[error("wrong length: {expected} bytes expected, {found} received")]
    Length {
        /// The datagram's length.
        expected: usize,
        /// Bytes received.
        found: usize,
    },
    /// Longer than the state datagram (refused in lenient mode too).
    #[error("datagram of {found} bytes is longer than the {max}-byte state")]
    TooLong {
        /// The state's length.
        max: usize,
        /// Bytes received.
        found: usize,
    },
    /// A magic other than `0x5AA5` (ZSL-1) or `0x5AA6` (ZSL-1W).
    #[error("unknown magic 0x{0:04x}")]
    Magic(u16),
    /// The HighLevel state does not start with `a5 5a` (strict mode).
    #[error("HighLevel state header {0:02x?} is not a5 5a")]
    Header([u8; 2]),
    /// The checksum word disagrees with the sum of bytes 0..7.
    #[error("checksum {found} does not match the sum of bytes 0..7 ({expected})")]
    Checksum {
        /// Sum of bytes 0..7.
        expected: u32,
        /// The checksum word.
        found: u32,
    },
    /// The output buffer is shorter than the datagram.
    #[error(transparent)]
    Buffer(#[from] robowire_core::BufferTooSmall),
}

/// The robot model, told by the command magic.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Model {
    /// ZSL-1, magic `0x5AA5`.
    #[default]
    Zsl1,
    /// ZSL-1W (wheel-legged), magic `0x5AA6`.
    Zsl1W,
}

impl Model {
    /// The command magic.
    pub const fn magic(self) -> u16 {
        match self {
            Self::Zsl1 => MAGIC_ZSL1,
            Self::Zsl1W => MAGIC_ZSL1W,
        }
    }

    /// The model of a command magic.
    pub fn from_magic(magic: u16) -> Result<Self, DatagramError> {
        match magic {
            MAGIC_ZSL1 => Ok(Self::Zsl1),
            MAGIC_ZSL1W => Ok(Self::Zsl1W),
            other => Err(DatagramError::Magic(other)),
        }
    }
}

/// Control modes, shared by command 0x1E and state 0x16C (spec §8.1; meanings from the docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ControlMode {
    /// 0: lying down, motors damped.
    Passive,
    /// 1: standing (also shake-hand).
    Stand,
    /// 10: lying down, motors go free after a while.
    LieDownFree,
    /// 18: walking (also ZSL-1W crawl and climb).
    Move,
    /// 21: action state (tricks, attitude, two-leg stand).
    Action,
    /// 51: lying down, joints locked.
    LieDown,
    /// Any other value, kept raw.
    Unknown(u32),
}

impl ControlMode {
    /// The raw value.
    pub const fn raw(self) -> u32 {
        match self {
            Self::Passive => 0,
            Self::Stand => 1,
            Self::LieDownFree => 10,
            Self::Move => 18,
            Self::Action => 21,
            Self::LieDown => 51,
            Self::Unknown(raw) => raw,
        }
    }

    /// The mode of a raw value.
    pub const fn from_raw(raw: u32) -> Self {
        match raw {
            0 => Self::Passive,
            1 => Self::Stand,
            10 => Self::LieDownFree,
            18 => Self::Move,
            21 => Self::Action,
            51 => Self::LieDown,
            other => Self::Unknown(other),
        }
    }
}

/// Action codes of command 0x1C (spec §8.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Action {
    /// 0: none.
    None,
    /// 2: backflip (6 datagrams, then cleared).
    Backflip,
    /// 5: jump (6 datagrams).
    Jump,
    /// 6: front jump (6 datagrams).
    FrontJump,
    /// 7: two-leg stand (sticky).
    TwoLegStand,
    /// 11: shake hand (6 datagrams).
    ShakeHand,
    /// 16: ZSL-1W climb (sticky).
    Climb,
    /// 17: ZSL-1W crawl (sticky).
    Crawl,
    /// Any other value, kept raw.
    Unknown(u16),
}

impl Action {
    /// The raw value.
    pub const fn raw(self) -> u16 {
        match self {
            Self::None => 0,
            Self::Backflip => 2,
            Self::Jump => 5,
            Self::FrontJump => 6,
            Self::TwoLegStand => 7,
            Self::ShakeHand => 11,
            Self::Climb => 16,
            Self::Crawl => 17,
            Self::Unknown(raw) => raw,
        }
    }

    /// The action of a raw value.
    pub const fn from_raw(raw: u16) -> Self {
        match raw {
            0 => Self::None,
            2 => Self::Backflip,
            5 => Self::Jump,
            6 => Self::FrontJump,
            7 => Self::TwoLegStand,
            11 => Self::ShakeHand,
            16 => Self::Climb,
            17 => Self::Crawl,
            other => Self::Unknown(other),
        }
    }

    /// One-shot tricks the sender clears after 6 datagrams (2, 5, 6, 11).
    pub const fn is_one_shot(self) -> bool {
        matches!(self, Self::Backflip | Self::Jump | Self::FrontJump | Self::ShakeHand)
    }
}

/// Return codes of the HighLevel calls and error words of state 0x1F4 (spec §8.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ReturnCode {
    /// 0: queued (not "the robot obeyed").
    Queued,
    /// 0x3007: state-machine switch failed.
    SwitchFailed,
    /// 0x3009: motor angle limit exceeded.
    AngleLimit,
    /// 0x3010: motor disabled.
    MotorDisabled,
    /// 0x3011: motor fault.
    MotorFault,
    /// 0x3012: motor data lost.
    MotorDataLost,
    /// 0x3013: speed command too large.
    SpeedTooLarge,
    /// Any other word, kept raw.
    Unknown(u32),
}

impl ReturnCode {
    /// The raw word.
    pub const fn raw(self) -> u32 {
        match self {
            Self::Queued => 0,
            Self::SwitchFailed => 0x3007,
            Self::AngleLimit => 0x3009,
            Self::MotorDisabled => 0x3010,
            Self::MotorFault => 0x3011,
            Self::MotorDataLost => 0x3012,
            Self::SpeedTooLarge => 0x3013,
            Self::Unknown(raw) => raw,
        }
    }

    /// The code of a raw word.
    pub const fn from_raw(raw: u32) -> Self {
        match raw {
            0 => Self::Queued,
            0x3007 => Self::SwitchFailed,
            0x3009 => Self::AngleLimit,
            0x3010 => Self::MotorDisabled,
            0x3011 => Self::MotorFault,
            0x3012 => Self::MotorDataLost,
            0x3013 => Self::SpeedTooLarge,
            other => Self::Unknown(other),
        }
    }
}

/// Sum of bytes 0..7 (spec §4): the checksum of both command datagrams.
pub fn checksum(datagram: &[u8]) -> u32 {
    datagram.iter().take(8).map(|&b| u32::from(b)).sum()
}

/// HighLevel command, client → dog, 40 bytes (spec §5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct HighLevelCommand {
    magic: U16,
    /// Reserved, 0 in every captured datagram.
    pub reserved_02: U16,
    /// Forward velocity, m/s (`move`, `twoLegStand`; `frontJump` writes 1.0).
    pub vx: F32,
    /// Lateral velocity, m/s (`move`).
    pub vy: F32,
    /// Roll rate, rad/s (`attitudeControl`).
    pub roll_rate: F32,
    /// Pitch rate, rad/s (`attitudeControl`).
    pub pitch_rate: F32,
    /// Yaw rate, rad/s (`move`, `twoLegStand`, `attitudeControl`).
    pub yaw_rate: F32,
    /// Height rate, m/s (`attitudeControl`).
    pub height_rate: F32,
    /// Action code (§8.2).
    pub action: U16,
    /// Requested control mode (§8.1).
    pub mode: U16,
    /// 1 after every accepted call except `cancelTwoLegStand`; meaning unknown.
    pub flag: U16,
    /// Reserved, 0.
    pub reserved_22: U16,
    checksum: U32,
}

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

/// HighLevel state, dog → client, 560 bytes (spec §6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct HighLevelState {
    /// Never read by the vendor SDK; robowire's simulator writes `a5 5a 00 00`.
    pub header: [u8; 4],
    /// Quaternion w, x, y, z.
    pub quaternion: [F32; 4],
    /// Body angular rate x, y, z, rad/s.
    pub gyro: [F32; 3],
    /// Body acceleration x, y, z, m/s².
    pub acc: [F32; 3],
    /// Roll, pitch, yaw, rad.
    pub rpy: [F32; 3],
    /// Body-frame velocity x, y, z, m/s.
    pub body_velocity: [F32; 3],
    /// World-frame velocity x, y, z, m/s.
    pub world_velocity: [F32; 3],
    /// Position x, y, z, m.
    pub position: [F32; 3],
    /// Unknown.
    pub unknown_05c: [u8; 12],
    /// Joint angles, rad: `[abad, hip, knee, foot][leg]`.
    pub joint_angle: [[F32; 4]; 4],
    /// Joint velocities, rad/s: `[abad, hip, knee, foot][leg]`.
    pub joint_velocity: [[F32; 4]; 4],
    /// Joint torques, N·m: `[abad, hip, knee, foot][leg]`.
    pub joint_torque: [[F32; 4]; 4],
    /// Unknown.
    pub unknown_128: [u8; 68],
    /// Current control mode (§8.1).
    pub control_mode: U32,
    /// Unknown.
    pub unknown_170: [u8; 128],
    /// Battery level, % (0–100 per docs).
    pub battery_percent: U32,
    /// Error word: non-zero = self-check failed (§8.3).
    pub error_word: U32,
    /// "SDK mismatch": exactly 1 stops the vendor's HighLevel sender for good.
    pub sdk_mismatch: U32,
    /// Unknown.
    pub unknown_1fc: [u8; 52],
}

/// What lenient decoding found (spec decision 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LenientUpdate {
    /// Bytes received (the prefix of the state that was overwritten).
    pub len: usize,
    /// Shorter than the full state.
    pub short: bool,
    /// HighLevel: the header was `a5 5a`; LowLevel: the magic `0x5AA5` was present.
    pub header_ok: bool,
}

macro_rules! command_codec {
    ($ty:ty, $len:literal, $checksum_at:literal) => {
        impl $ty {
            /// Datagram length in bytes.
            pub const LEN: usize = $len;

            /// The magic the datagram carries.
            pub fn magic(&self) -> u16 {
                self.magic.get()
            }

            /// The checksum word the datagram carries.
            pub fn checksum(&self) -> u32 {
                self.checksum.get()
            }

            /// The datagram for `model`: magic and checksum written here, never by the user.
            pub fn encode(&self, model: Model) -> [u8; $len] {
                let mut datagram = *self;
                datagram.magic = model.magic().into();
                datagram.checksum = 0.into();
                let sum = checksum(datagram.as_bytes());
                datagram.checksum = sum.into();
                let mut out = [0u8; $len];
                out.copy_from_slice(datagram.as_bytes());
                out
            }

            /// Writes the datagram for `model` at the start of `buf`; returns its length.
            pub fn encode_into(&self, model: Model, buf: &mut [u8]) -> Result<usize, DatagramError> {
                let available = buf.len();
                let out = buf.get_mut(..$len).ok_or(robowire_core::BufferTooSmall { needed: $len, available })?;
                out.copy_from_slice(&self.encode(model));
                Ok($len)
            }

            /// Strict decoding: exact length, a known magic, the checksum of bytes 0..7.
            pub fn decode(bytes: &[u8]) -> Result<(Self, Model), DatagramError> {
                let datagram = Self::read_from_bytes(bytes)
                    .map_err(|_| DatagramError::Length { expected: $len, found: bytes.len() })?;
                let model = Model::from_magic(datagram.magic.get())?;
                let expected = checksum(bytes);
                if datagram.checksum.get() != expected {
                    return Err(DatagramError::Checksum { expected, found: datagram.checksum.get() });
                }
                Ok((datagram, model))
            }
        }

        impl crate::codec::CommandDatagram for $ty {
            const LEN: usize = $len;
            fn encode_into(&self, model: Model, buf: &mut [u8]) -> Result<usize, DatagramError> {
                <$ty>::encode_into(self, model, buf)
            }
            fn decode(bytes: &[u8]) -> Result<(Self, Model), DatagramError> {
                <$ty>::decode(bytes)
            }
        }

        const _: () = assert!(size_of::<$ty>() == $len && core::mem::offset_of!($ty, checksum) == $checksum_at);
    };
}

command_codec!(HighLevelCommand, 40, 0x24);
command_codec!(LowLevelCommand, 248, 0xF4);

impl Default for HighLevelCommand {
    /// The idle command: every field zero (mode 0, no action, flag 0).
    fn default() -> Self {
        Self::new_zeroed()
    }
}

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

impl HighLevelCommand {
    /// The command of an accepted call: every field zero, then mode, action and flag 1 (§5.2).
    fn call(mode: ControlMode, action: Action) -> Self {
        let mut c = Self::new_zeroed();
        c.mode = (mode.raw() as u16).into();
        c.action = action.raw().into();
        c.flag = 1.into();
        c
    }

    /// `standUp()`: mode 1.
    pub fn stand_up() -> Self {
        Self::call(ControlMode::Stand, Action::None)
    }

    /// `lieDown()`: mode 51.
    pub fn lie_down() -> Self {
        Self::call(ControlMode::LieDown, Action::None)
    }

    /// `passive()`: mode 0.
    pub fn passive() -> Self {
        Self::call(ControlMode::Passive, Action::None)
    }

    /// `move(vx, vy, yaw_rate)`: mode 18 (m/s, m/s, rad/s).
    pub fn move_velocity(vx_mps: f32, vy_mps: f32, yaw_rate_radps: f32) -> Self {
        let mut c = Self::call(ControlMode::Move, Action::None);
        c.vx = vx_mps.into();
        c.vy = vy_mps.into();
        c.yaw_rate = yaw_rate_radps.into();
        c
    }

    /// `jump()`: mode 21, action 5.
    pub fn jump() -> Self {
        Self::call(ControlMode::Action, Action::Jump)
    }

    /// `frontJump()`: mode 21, action 6, vx 1.0.
    pub fn front_jump() -> Self {
        let mut c = Self::call(ControlMode::Action, Action::FrontJump);
        c.vx = 1.0.into();
        c
    }

    /// `backflip()`: mode 21, action 2.
    pub fn backflip() -> Self {
        Self::call(ControlMode::Action, Action::Backflip)
    }

    /// `shakeHand()`: mode 1, action 11.
    pub fn shake_hand() -> Self {
        Self::call(ControlMode::Stand, Action::ShakeHand)
    }

    /// `twoLegStand(vx, yaw_rate)`: mode 21, action 7 (sticky).
    pub fn two_leg_stand(vx_mps: f32, yaw_rate_radps: f32) -> Self {
        let mut c = Self::call(ControlMode::Action, Action::TwoLegStand);
        c.vx = vx_mps.into();
        c.yaw_rate = yaw_rate_radps.into();
        c
    }

    /// `cancelTwoLegStand()`: mode 21, action 0, flag **0**.
    pub fn cancel_two_leg_stand() -> Self {
        let mut c = Self::call(ControlMode::Action, Action::None);
        c.flag = 0.into();
        c
    }

    /// `attitudeControl(roll, pitch, yaw, height)` rates: mode 21.
    pub fn attitude(roll_radps: f32, pitch_radps: f32, yaw_radps: f32, height_mps: f32) -> Self {
        let mut c = Self::call(ControlMode::Action, Action::None);
        c.roll_rate = roll_radps.into();
        c.pitch_rate = pitch_radps.into();
        c.yaw_rate = yaw_radps.into();
        c.height_rate = height_mps.into();
        c
    }

    /// ZSL-1W `crawl(vx, vy, yaw_rate)`: mode 18, action 17 (sticky).
    pub fn crawl(vx_mps: f32, vy_mps: f32, yaw_rate_radps: f32) -> Self {
        let mut c = Self::move_velocity(vx_mps, vy_mps, yaw_rate_radps);
        c.action = Action::Crawl.raw().into();
        c
    }

    /// ZSL-1W `climb(vx, vy, yaw_rate)`: mode 18, action 16 (sticky).
    pub fn climb(vx_mps: f32, vy_mps: f32, yaw_rate_radps: f32) -> Self {
        let mut c = Self::move_velocity(vx_mps, vy_mps, yaw_rate_radps);
        c.action = Action::Climb.raw().into();
        c
    }

    /// ZSL-1W `cancelCrawl()` / `cancelClimb()`: mode 18, action 0, flag 0.
    pub fn cancel_crawl_or_climb() -> Self {
        let mut c = Self::call(ControlMode::Move, Action::None);
        c.flag = 0.into();
        c
    }

    /// The requested mode.
    pub fn control_mode(&self) -> ControlMode {
        ControlMode::from_raw(u32::from(self.mode.get()))
    }

    /// The action code.
    pub fn action_code(&self) -> Action {
        Action::from_raw(self.action.get())
    }
}

macro_rules! state_codec {
    ($ty:ty, $len:literal, $strict:expr, $header_ok:expr) => {
        impl $ty {
            /// Datagram length in bytes.
            pub const LEN: usize = $len;

            /// Strict decoding: exact length and the header or magic of spec decision 2.
            pub fn decode_strict(bytes: &[u8]) -> Result<Self, DatagramError> {
                let state = Self::read_from_bytes(bytes)
                    .map_err(|_| DatagramError::Length { expected: $len, found: bytes.len() })?;
                let check: fn(&Self) -> Result<(), DatagramError> = $strict;
                check(&state)?;
                Ok(state)
            }

            /// Lenient decoding, like the vendor client: the bytes present overwrite a prefix of
            /// `self`, the rest is kept; a 0-byte datagram changes nothing. Longer than the
            /// state is an error.
            pub fn update_lenient(&mut self, bytes: &[u8]) -> Result<LenientUpdate, DatagramError> {
                if bytes.len() > $len {
                    return Err(DatagramError::TooLong { max: $len, found: bytes.len() });
                }
                self.as_mut_bytes()[..bytes.len()].copy_from_slice(bytes);
                let header_ok: fn(&Self) -> bool = $header_ok;
                Ok(LenientUpdate { len: bytes.len(), short: bytes.len() < $len, header_ok: header_ok(self) })
            }

            /// The datagram (state is sent as it is: no magic or checksum is added).
            pub fn encode(&self) -> [u8; $len] {
                let mut out = [0u8; $len];
                out.copy_from_slice(self.as_bytes());
                out
            }
        }

        impl crate::codec::StateDatagram for $ty {
            const LEN: usize = $len;
            fn decode_strict(bytes: &[u8]) -> Result<Self, DatagramError> {
                <$ty>::decode_strict(bytes)
            }
            fn update_lenient(&mut self, bytes: &[u8]) -> Result<LenientUpdate, DatagramError> {
                <$ty>::update_lenient(self, bytes)
            }
            fn encode_into(&self, buf: &mut [u8]) -> Result<usize, DatagramError> {
                let available = buf.len();
                let out = buf.get_mut(..$len).ok_or(robowire_core::BufferTooSmall { needed: $len, available })?;
                out.copy_from_slice(self.as_bytes());
                Ok($len)
            }
        }

        impl Default for $ty {
            fn default() -> Self {
                Self::new_zeroed()
            }
        }

        const _: () = assert!(size_of::<$ty>() == $len);
    };
}

/// The header robowire's simulator writes at HighLevel state offset 0.
pub const HIGH_LEVEL_STATE_HEADER: [u8; 4] = [0xa5, 0x5a, 0x00, 0x00];

state_codec!(
    HighLevelState,
    560,
    |s| if s.header[..2] == HIGH_LEVEL_STATE_HEADER[..2] {
        Ok(())
    } else {
        Err(DatagramError::Header([s.header[0], s.header[1]]))
    },
    |s| s.header[..2] == HIGH_LEVEL_STATE_HEADER[..2]
);
state_codec!(
    LowLevelState,
    272,
    |s| if s.magic.get() == MAGIC_ZSL1 { Ok(()) } else { Err(DatagramError::Magic(s.magic.get())) },
    |s| s.magic.get() == MAGIC_ZSL1
);

impl HighLevelState {
    /// Current control mode (state 0x16C).
    pub fn mode(&self) -> ControlMode {
        ControlMode::from_raw(self.control_mode.get())
    }

    /// The error word as a return code (0: no error).
    pub fn error(&self) -> ReturnCode {
        ReturnCode::from_raw(self.error_word.get())
    }
}

impl LowLevelState {
    /// `haveMotorData()`: the magic `0x5AA5` is present.
    pub fn has_motor_data(&self) -> bool {
        self.magic.get() == MAGIC_ZSL1
    }
}

// Offsets of spec §5.1, §6.1, §7.
const _: () = {
    use core::mem::offset_of;
    assert!(offset_of!(HighLevelCommand, vx) == 0x04);
    assert!(offset_of!(HighLevelCommand, yaw_rate) == 0x14);
    assert!(offset_of!(HighLevelCommand, height_rate) == 0x18);
    assert!(offset_of!(HighLevelCommand, action) == 0x1C);
    assert!(offset_of!(HighLevelCommand, mode) == 0x1E);
    assert!(offset_of!(HighLevelCommand, flag) == 0x20);
    assert!(offset_of!(LowLevelCommand, motor) == 0x04);
    assert!(offset_of!(HighLevelState, quaternion) == 0x004);
    assert!(offset_of!(HighLevelState, gyro) == 0x014);
    assert!(offset_of!(HighLevelState, acc) == 0x020);
    assert!(offset_of!(HighLevelState, rpy) == 0x02C);
    assert!(offset_of!(HighLevelState, body_velocity) == 0x038);
    assert!(offset_of!(HighLevelState, world_velocity) == 0x044);
    assert!(offset_of!(HighLevelState, position) == 0x050);
    assert!(offset_of!(HighLevelState, joint_angle) == 0x068);
    assert!(offset_of!(HighLevelState, joint_velocity) == 0x0A8);
    assert!(offset_of!(HighLevelState, joint_torque) == 0x0E8);
    assert!(offset_of!(HighLevelState, control_mode) == 0x16C);
    assert!(offset_of!(HighLevelState, battery_percent) == 0x1F0);
    assert!(offset_of!(HighLevelState, error_word) == 0x1F4);
    assert!(offset_of!(HighLevelState, sdk_mismatch) == 0x1F8);
    assert!(offset_of!(LowLevelState, motor) == 0x04);
    assert!(offset_of!(LowLevelState, quaternion) == 0x94);
    assert!(offset_of!(LowLevelState, gyro) == 0xA4);
    assert!(offset_of!(LowLevelState, acc) == 0xB0);
    assert!(offset_of!(LowLevelState, rpy) == 0xBC);
    assert!(offset_of!(LowLevelState, unknown_c8) == 0xC8);
};
