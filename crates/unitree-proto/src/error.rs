//! Decode errors. A CRC mismatch carries the decoded message, for diagnostics.

/// Why bytes are not a valid message `M`.
///
/// A CRC mismatch carries the decoded message, so the error is as large as the message
/// (up to 2 KiB, no allocation). Box it (`.map_err(Box::new)`) to pass it up a call chain.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum DecodeError<M> {
    /// A struct image that is not the message's exact length.
    #[error("wrong length: the struct image is {expected} bytes, {found} given")]
    Length {
        /// The image's length.
        expected: usize,
        /// Bytes given.
        found: usize,
    },
    /// Too short for a CDR payload's 4-byte encapsulation header.
    #[error(
        "a CDR payload starts with its 4-byte encapsulation header (00 01 00 00 XCDR1, 00 07 00 00 XCDR2); {found} bytes given"
    )]
    NoEncapsulation {
        /// Bytes given.
        found: usize,
    },
    /// A CDR payload that is not the message's exact length in its encoding.
    #[error("wrong length: the {encoding:?} payload is {expected} bytes with its header, {found} given")]
    CdrLength {
        /// The payload's encoding, from its header.
        encoding: crate::CdrEncoding,
        /// The payload's length in that encoding, header included.
        expected: usize,
        /// Bytes given.
        found: usize,
    },
    /// The CDR encapsulation header is neither XCDR1 (`00 01 00 00`) nor XCDR2 (`00 07 00 00`).
    #[error("unknown CDR encapsulation {found:02x?} (expected 00 01 00 00 for XCDR1 or 00 07 00 00 for XCDR2)")]
    Encapsulation {
        /// The header found.
        found: [u8; 4],
    },
    /// An XCDR2 array length header (DHEADER) disagrees with the array.
    #[error("XCDR2 header of array {field} says {found} bytes, the array has {expected}")]
    ArrayHeader {
        /// The array's IDL name.
        field: &'static str,
        /// The array's length in bytes.
        expected: u32,
        /// What the header says.
        found: u32,
    },
    /// A padding byte of the struct image is not zero (the firmware drops such frames).
    #[error("padding byte at offset {offset} is 0x{value:02x}, not zero")]
    NonZeroPadding {
        /// Offset in the image.
        offset: usize,
        /// The byte found.
        value: u8,
    },
    /// The `crc` field disagrees with the CRC of the zero-padded image.
    #[error("CRC mismatch: the zero-padded image gives 0x{expected:08x}, the message carries 0x{found:08x}")]
    CrcMismatch {
        /// CRC computed over the zero-padded image.
        expected: u32,
        /// The message's `crc` field.
        found: u32,
        /// The decoded message (padding zeroed), for diagnostics.
        message: M,
    },
}

impl<M> DecodeError<M> {
    /// The same error without the message.
    pub fn without_message(self) -> DecodeError<()> {
        match self {
            Self::Length { expected, found } => DecodeError::Length { expected, found },
            Self::NoEncapsulation { found } => DecodeError::NoEncapsulation { found },
            Self::CdrLength { encoding, expected, found } => DecodeError::CdrLength { encoding, expected, found },
            Self::Encapsulation { found } => DecodeError::Encapsulation { found },
            Self::ArrayHeader { field, expected, found } => DecodeError::ArrayHeader { field, expected, found },
            Self::NonZeroPadding { offset, value } => DecodeError::NonZeroPadding { offset, value },
            Self::CrcMismatch { expected, found, .. } => DecodeError::CrcMismatch { expected, found, message: () },
        }
    }
}
