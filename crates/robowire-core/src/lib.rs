#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]

mod datagram;
pub mod le;
mod stream;
pub mod timing;

pub use datagram::DatagramCodec;
pub use stream::{DecodeStep, DecoderCounters, FrameBuffer, StreamDecoder};

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
