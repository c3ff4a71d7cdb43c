#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]

mod af;
mod control;
mod decoder;
#[cfg(feature = "serde")]
pub mod description;
mod error;
mod frame;
#[cfg(feature = "serde")]
mod serde_impl;
pub mod stream;
#[cfg(feature = "fuzzing")]
#[doc(hidden)]
pub mod stream_consistency;

pub use af::{AfFrame, AfRequest, AfResponse, AllState, BatteryVoltage, ParamId, Rw};
pub use control::{CURVATURE_VELOCITY_THRESHOLD_MPS, PcControl, VehicleSpeed, VehicleSpeedRequest};
pub use decoder::{ChassisFrameDecoder, HostFrameDecoder, InvalidSpeedBound};
pub use error::{DecodeError, EncodeError};
pub use frame::{ChassisFrame, HostFrame};
pub use robowire_core::{BufferTooSmall, DecodeStep, DecoderCounters, FrameBuffer, StreamDecoder};

/// Frame ID of the `0xA5` control command (host → chassis, 9 bytes).
pub const FRAME_ID_CONTROL: u8 = 0xA5;
/// Frame ID of the `0xB3` vehicle speed request (1 byte) and response (5 bytes).
pub const FRAME_ID_SPEED: u8 = 0xB3;
/// Frame ID of the `0xAF` auxiliary read/write frame (both directions).
pub const FRAME_ID_AF: u8 = 0xAF;
/// Most parameter IDs in one 0xAF frame (`MAX_IDS`).
pub const MAX_IDS: usize = 16;
/// Longest frame: an 0xAF write with 16 IDs, 4 + 16 + 64 bytes.
pub const MAX_FRAME_LEN: usize = 84;
/// Default plausibility bound of the host-side decoder for `0xB3` responses, m/s (spec §6.2).
pub const DEFAULT_MAX_SPEED_MPS: f32 = 20.0;
/// Number of fields in the all-state record (`ALL_STATE_FIELD_COUNT`).
pub const ALL_STATE_FIELD_COUNT: usize = 9;
