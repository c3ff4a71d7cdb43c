//! Codec errors: `Copy`, allocation-free, one variant per way the bytes can be wrong.

use robowire_core::BufferTooSmall;

/// Why bytes are not a frame.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum DecodeError {
    /// No bytes at all.
    #[error("empty input")]
    Empty,
    /// The first byte is not a frame ID of this direction.
    #[error("unknown frame id 0x{0:02x}")]
    UnknownFrameId(u8),
    /// Fewer bytes than the frame needs.
    #[error("truncated frame: {needed} bytes needed, {available} available")]
    Truncated {
        /// Length of the frame (as far as its header tells).
        needed: usize,
        /// Bytes given.
        available: usize,
    },
    /// More bytes than the frame is long (strict whole-frame parsing only).
    #[error("trailing bytes: the frame is {frame_len} bytes, {available} given")]
    TrailingBytes {
        /// Length of the frame.
        frame_len: usize,
        /// Bytes given.
        available: usize,
    },
    /// 0xAF `rw` byte (offset 2) is neither 0x00 (read) nor 0x01 (write).
    #[error("invalid rw byte 0x{0:02x} (expected 0x00 read or 0x01 write)")]
    InvalidRw(u8),
    /// 0xAF `n_id` (offset 3) outside 1..=16.
    #[error("invalid id count {0} (expected 1..=16)")]
    InvalidIdCount(u8),
    /// A parameter ID that the protocol does not define.
    #[error("unknown parameter id 0x{0:02x}")]
    UnknownParamId(u8),
    /// A float slot holds NaN or an infinity where the protocol carries a value.
    #[error("non-finite float at byte offset {offset}")]
    NonFinite {
        /// Offset of the slot within the frame.
        offset: usize,
    },
    /// A vehicle speed beyond the decoder's plausibility bound.
    #[error("implausible vehicle speed {speed_mps} m/s (bound {bound_mps} m/s)")]
    SpeedOutOfBounds {
        /// Speed in the frame.
        speed_mps: f32,
        /// The decoder's bound.
        bound_mps: f32,
    },
}

/// Why a frame could not be written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum EncodeError {
    /// The caller's buffer is too short; [`crate::MAX_FRAME_LEN`] always suffices.
    #[error(transparent)]
    BufferTooSmall(#[from] BufferTooSmall),
    /// A float that would go on the wire is NaN or infinite; nothing was written.
    #[error("non-finite float at byte offset {offset}")]
    NonFinite {
        /// Offset the slot would have in the frame.
        offset: usize,
    },
    /// An 0xAF frame needs 1..=16 parameter IDs.
    #[error("an 0xAF frame carries 1..=16 ids, {0} given")]
    IdCount(usize),
}
