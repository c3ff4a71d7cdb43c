#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]

#[cfg(feature = "std")]
extern crate std;

pub mod cdr;
mod datagram;
#[cfg(feature = "json")]
pub mod json;
pub mod kinematics;
pub mod le;
pub mod schedule;
#[cfg(feature = "serde")]
pub mod serde_f32;
pub mod shm;
mod stream;
pub mod timing;

pub use datagram::DatagramCodec;
pub use stream::{Consumed, DecodeStep, DecoderCounters, FrameBuffer, StreamDecoder};

/// Which way a frame went, seen from the end of the link that owns it (the one recording it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Direction {
    /// Written by this end.
    Sent,
    /// Read by this end.
    Received,
}

impl Direction {
    /// `sent` or `received`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Sent => "sent",
            Self::Received => "received",
        }
    }
}

/// A float argument that must be finite is NaN or infinite. Every facade refuses such a value
/// before anything is queued or sent.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("{name} must be finite, got {value}")]
pub struct NonFinite {
    /// The argument's name, with its unit.
    pub name: &'static str,
    /// What was passed.
    pub value: f32,
}

/// `value` if it is finite, else [`NonFinite`] naming the argument.
///
/// ```
/// assert_eq!(robowire_core::finite("velocity_mps", 0.5), Ok(0.5));
/// assert!(robowire_core::finite("velocity_mps", f32::NAN).is_err());
/// ```
pub fn finite(name: &'static str, value: f32) -> Result<f32, NonFinite> {
    if value.is_finite() { Ok(value) } else { Err(NonFinite { name, value }) }
}

/// The caller's buffer cannot hold what is to be written into it.
///
/// Every encoder in robowire returns this (or wraps it) instead of panicking on a short buffer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("buffer too small: {needed} bytes needed, {available} available")]
pub struct BufferTooSmall {
    /// Bytes the encoder needs to write.
    pub needed: usize,
    /// Bytes the buffer has.
    pub available: usize,
}
