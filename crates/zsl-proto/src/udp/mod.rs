//! The ZSL-1 / ZSL-1W UDP datagrams (spec `zsl1-udp.md`): HighLevel command (40 bytes) and state
//! (560), LowLevel command (248) and state (272). Little-endian, no padding.
//!
//! Commands carry a magic and a checksum that only the encoder writes; every reserved or
//! unknown byte is a field that round-trips unchanged.
//!
//! - [`codes`](self#codes): control modes, actions, return codes (spec §8);
//! - the HighLevel datagrams and the vendor calls that fill them ([`HighLevelCommand`],
//!   [`HighLevelState`]);
//! - the LowLevel datagrams ([`LowLevelCommand`], [`LowLevelState`]).

mod codes;
mod high_level;
mod low_level;

pub use codes::{Action, ControlMode, ReturnCode};
pub use high_level::{HIGH_LEVEL_STATE_HEADER, HighLevelCommand, HighLevelState};
pub use low_level::{LowLevelCommand, LowLevelState, MotorCommand, MotorState};
pub(crate) use robowire_core::BufferTooSmall;

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
    Buffer(#[from] BufferTooSmall),
    /// No datagram has this length.
    #[error(
        "{found} bytes is no ZSL-1 datagram (40 HighLevel command, 560 HighLevel state, 248 LowLevel command, 272 LowLevel state)"
    )]
    Unknown {
        /// Bytes given.
        found: usize,
    },
}

/// Any of the four datagrams, told by its length: what a capture or a pasted hex dump holds.
// Variants as large as the datagrams: no allocation here (no_std), and a value is short-lived.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AnyDatagram {
    /// 40 bytes, client → dog.
    HighLevelCommand(HighLevelCommand),
    /// 560 bytes, dog → client.
    HighLevelState(HighLevelState),
    /// 248 bytes, client → dog.
    LowLevelCommand(LowLevelCommand),
    /// 272 bytes, dog → client.
    LowLevelState(LowLevelState),
}

impl AnyDatagram {
    /// Decodes `bytes` strictly as the datagram of its length.
    pub fn decode(bytes: &[u8]) -> Result<Self, DatagramError> {
        Ok(match bytes.len() {
            HighLevelCommand::LEN => Self::HighLevelCommand(HighLevelCommand::decode(bytes)?.0),
            LowLevelCommand::LEN => Self::LowLevelCommand(LowLevelCommand::decode(bytes)?.0),
            HighLevelState::LEN => Self::HighLevelState(HighLevelState::decode_strict(bytes)?),
            LowLevelState::LEN => Self::LowLevelState(LowLevelState::decode_strict(bytes)?),
            found => return Err(DatagramError::Unknown { found }),
        })
    }

    /// The datagram's name: `HighLevelCommand`, `HighLevelState`, `LowLevelCommand`, `LowLevelState`.
    pub fn name(&self) -> &'static str {
        match self {
            Self::HighLevelCommand(_) => "HighLevelCommand",
            Self::HighLevelState(_) => "HighLevelState",
            Self::LowLevelCommand(_) => "LowLevelCommand",
            Self::LowLevelState(_) => "LowLevelState",
        }
    }
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

/// Sum of bytes 0..7 (spec §4): the checksum of both command datagrams.
pub fn checksum(datagram: &[u8]) -> u32 {
    datagram.iter().take(8).map(|&b| u32::from(b)).sum()
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
            pub fn encode(&self, model: $crate::udp::Model) -> [u8; $len] {
                let mut datagram = *self;
                datagram.magic = model.magic().into();
                datagram.checksum = 0.into();
                let sum = $crate::udp::checksum(datagram.as_bytes());
                datagram.checksum = sum.into();
                let mut out = [0u8; $len];
                out.copy_from_slice(datagram.as_bytes());
                out
            }

            /// Writes the datagram for `model` at the start of `buf`; returns its length.
            pub fn encode_into(
                &self,
                model: $crate::udp::Model,
                buf: &mut [u8],
            ) -> Result<usize, $crate::udp::DatagramError> {
                let available = buf.len();
                let out = buf.get_mut(..$len).ok_or($crate::udp::BufferTooSmall { needed: $len, available })?;
                out.copy_from_slice(&self.encode(model));
                Ok($len)
            }

            /// Strict decoding: exact length, a known magic, the checksum of bytes 0..7.
            pub fn decode(bytes: &[u8]) -> Result<(Self, $crate::udp::Model), $crate::udp::DatagramError> {
                let datagram = Self::read_from_bytes(bytes)
                    .map_err(|_| $crate::udp::DatagramError::Length { expected: $len, found: bytes.len() })?;
                let model = $crate::udp::Model::from_magic(datagram.magic.get())?;
                let expected = $crate::udp::checksum(bytes);
                if datagram.checksum.get() != expected {
                    return Err($crate::udp::DatagramError::Checksum { expected, found: datagram.checksum.get() });
                }
                Ok((datagram, model))
            }
        }

        impl $crate::codec::CommandDatagram for $ty {
            const LEN: usize = $len;
            fn encode_into(
                &self,
                model: $crate::udp::Model,
                buf: &mut [u8],
            ) -> Result<usize, $crate::udp::DatagramError> {
                <$ty>::encode_into(self, model, buf)
            }
            fn decode(bytes: &[u8]) -> Result<(Self, $crate::udp::Model), $crate::udp::DatagramError> {
                <$ty>::decode(bytes)
            }
        }

        const _: () = assert!(size_of::<$ty>() == $len && core::mem::offset_of!($ty, checksum) == $checksum_at);
    };
}

macro_rules! state_codec {
    ($ty:ty, $len:literal, $strict:expr, $header_ok:expr) => {
        impl $ty {
            /// Datagram length in bytes.
            pub const LEN: usize = $len;

            /// Strict decoding: exact length and the header or magic of spec decision 2.
            pub fn decode_strict(bytes: &[u8]) -> Result<Self, $crate::udp::DatagramError> {
                let state = Self::read_from_bytes(bytes)
                    .map_err(|_| $crate::udp::DatagramError::Length { expected: $len, found: bytes.len() })?;
                let check: fn(&Self) -> Result<(), $crate::udp::DatagramError> = $strict;
                check(&state)?;
                Ok(state)
            }

            /// Lenient decoding, like the vendor client: the bytes present overwrite a prefix of
            /// `self`, the rest is kept; a 0-byte datagram changes nothing. Longer than the
            /// state is an error.
            pub fn update_lenient(
                &mut self,
                bytes: &[u8],
            ) -> Result<$crate::udp::LenientUpdate, $crate::udp::DatagramError> {
                if bytes.len() > $len {
                    return Err($crate::udp::DatagramError::TooLong { max: $len, found: bytes.len() });
                }
                self.as_mut_bytes()[..bytes.len()].copy_from_slice(bytes);
                let header_ok: fn(&Self) -> bool = $header_ok;
                Ok($crate::udp::LenientUpdate {
                    len: bytes.len(),
                    short: bytes.len() < $len,
                    header_ok: header_ok(self),
                })
            }

            /// The datagram (state is sent as it is: no magic or checksum is added).
            pub fn encode(&self) -> [u8; $len] {
                let mut out = [0u8; $len];
                out.copy_from_slice(self.as_bytes());
                out
            }
        }

        impl $crate::codec::StateDatagram for $ty {
            const LEN: usize = $len;
            fn decode_strict(bytes: &[u8]) -> Result<Self, $crate::udp::DatagramError> {
                <$ty>::decode_strict(bytes)
            }
            fn update_lenient(
                &mut self,
                bytes: &[u8],
            ) -> Result<$crate::udp::LenientUpdate, $crate::udp::DatagramError> {
                <$ty>::update_lenient(self, bytes)
            }
            fn encode_into(&self, buf: &mut [u8]) -> Result<usize, $crate::udp::DatagramError> {
                let available = buf.len();
                let out = buf.get_mut(..$len).ok_or($crate::udp::BufferTooSmall { needed: $len, available })?;
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

pub(crate) use {command_codec, state_codec};

// Offsets of spec §5.1, §6.1, §7, checked at compile time.
const _: () = {
    use core::mem::offset_of;
    assert!(offset_of!(HighLevelCommand, vx) == 0x04);
    assert!(offset_of!(HighLevelCommand, yaw_rate) == 0x14);
    assert!(offset_of!(HighLevelCommand, height_rate) == 0x18);
    assert!(offset_of!(HighLevelCommand, action) == 0x1C);
    assert!(offset_of!(HighLevelCommand, mode) == 0x1E);
    assert!(offset_of!(HighLevelCommand, flag) == 0x20);
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
    assert!(offset_of!(LowLevelCommand, motor) == 0x04);
    assert!(offset_of!(LowLevelState, motor) == 0x04);
    assert!(offset_of!(LowLevelState, quaternion) == 0x94);
    assert!(offset_of!(LowLevelState, gyro) == 0xA4);
    assert!(offset_of!(LowLevelState, acc) == 0xB0);
    assert!(offset_of!(LowLevelState, rpy) == 0xBC);
    assert!(offset_of!(LowLevelState, unknown_c8) == 0xC8);
};
