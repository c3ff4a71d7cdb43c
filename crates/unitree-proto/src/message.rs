//! What every low-level message can do: struct image with CRC, CDR, both ways.

use robowire_core::BufferTooSmall;
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout};

use crate::cdr::CdrEncoding;
use crate::crc::crc32_words_masked;
use crate::field::{FieldError, FieldPlace, FieldValue};
use crate::layout::{PadRange, StructLayout, padding_count, padding_mask, padding_ranges};
use crate::plan::{CdrPlan, cdr_plan};
use crate::{DecodeError, go2, hg};

/// Largest struct image (HG `LowState_`).
pub const MAX_IMAGE_LEN: usize = 2092;

/// The CRC a message carries and the one its zero-padded image gives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct CrcCheck {
    /// CRC computed over the zero-padded image.
    pub computed: u32,
    /// The message's `crc` field.
    pub received: u32,
}

impl CrcCheck {
    /// Do they agree?
    pub fn is_ok(&self) -> bool {
        self.computed == self.received
    }
}

/// A message decoded without verification, with what verification would have found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Unverified<M> {
    /// The message, padding zeroed.
    pub message: M,
    /// CRC agreement.
    pub crc: CrcCheck,
    /// Offset and value of the first non-zero padding byte in a struct image, if any.
    pub padding: Option<(usize, u8)>,
}

mod sealed {
    pub trait Sealed {}
}

/// A Unitree low-level message: Go2 [`LowCmd`](crate::LowCmd) / [`LowState`](crate::LowState),
/// HG [`HgLowCmd`](crate::HgLowCmd) / [`HgLowState`](crate::HgLowState).
///
/// Encoding always zeroes the padding and writes the CRC; decoding verifies both (use the
/// `_unverified` variants to look at a broken message).
pub trait Message: sealed::Sealed + FromBytes + IntoBytes + KnownLayout + Immutable + Copy + Default {
    /// Field table.
    const FIELDS: &'static StructLayout;
    /// DDS type name on the wire.
    const DDS_TYPE_NAME: &'static str;
    /// DDS topic.
    const TOPIC: &'static str;
    /// Struct image length in bytes.
    const IMAGE_LEN: usize = size_of::<Self>();
    /// The image's padding, `(offset, len)`, flattened from [`FIELDS`](Self::FIELDS) at compile
    /// time.
    const PADDING: &'static [PadRange];
    /// The image's padding as a mask (0x00 on padding), from the same table.
    const PADDING_MASK: &'static [u8];
    /// The XCDR1 copy plan, from the same table at compile time.
    const XCDR1: CdrPlan;
    /// The XCDR2 copy plan.
    const XCDR2: CdrPlan;

    /// The copy plan of `encoding`.
    fn cdr_plan(encoding: CdrEncoding) -> &'static CdrPlan {
        match encoding {
            CdrEncoding::Xcdr1 => &Self::XCDR1,
            CdrEncoding::Xcdr2 => &Self::XCDR2,
        }
    }

    /// Sets every padding byte to zero (one AND pass with [`PADDING_MASK`](Self::PADDING_MASK)).
    fn zero_padding(&mut self) {
        for (byte, mask) in self.as_mut_bytes().iter_mut().zip(Self::PADDING_MASK) {
            *byte &= *mask;
        }
    }

    /// The scalar field `path` names (`"motor_cmd[3].q"`, `"imu_state.rpy[0]"`, `"head[1]"`; see
    /// [`FieldPlace::path`]).
    fn field(&self, path: &str) -> Result<FieldValue, FieldError> {
        FieldPlace::of::<Self>().path(path)?.get(self.as_bytes())
    }

    /// Writes the scalar field `path` names; `value` must be of the field's IDL type. Only that
    /// field's bytes change (a written `crc` is overwritten again by every encoder).
    fn set_field(&mut self, path: &str, value: FieldValue) -> Result<(), FieldError> {
        FieldPlace::of::<Self>().path(path)?.set(self.as_mut_bytes(), value)
    }

    /// The `crc` field (the last 4 bytes).
    fn crc(&self) -> u32 {
        let bytes = self.as_bytes();
        let n = bytes.len();
        u32::from_le_bytes([bytes[n - 4], bytes[n - 3], bytes[n - 2], bytes[n - 1]])
    }

    /// The CRC of the zero-padded image (what [`seal`](Self::seal) writes).
    fn computed_crc(&self) -> u32 {
        let bytes = self.as_bytes();
        crc32_words_masked(&bytes[..bytes.len() - 4], Self::PADDING_MASK).unwrap_or(0)
    }

    /// Zeroes the padding and writes the CRC: the message as it must be sent.
    fn seal(&mut self) {
        self.zero_padding();
        let crc = self.computed_crc();
        let bytes = self.as_mut_bytes();
        let n = bytes.len();
        bytes[n - 4..].copy_from_slice(&crc.to_le_bytes());
    }

    /// A sealed copy.
    fn sealed(&self) -> Self {
        let mut copy = *self;
        copy.seal();
        copy
    }

    /// Writes the sealed struct image (zero padding, CRC) into `out`; returns its length.
    fn encode_image(&self, out: &mut [u8]) -> Result<usize, BufferTooSmall> {
        let (needed, available) = (Self::IMAGE_LEN, out.len());
        let dst = out.get_mut(..needed).ok_or(BufferTooSmall { needed, available })?;
        dst.copy_from_slice(self.sealed().as_bytes());
        Ok(needed)
    }

    /// Decodes a struct image without verifying padding or CRC.
    fn decode_image_unverified(bytes: &[u8]) -> Result<Unverified<Self>, DecodeError<Self>> {
        let mut message = Self::read_from_bytes(bytes)
            .map_err(|_| DecodeError::Length { expected: Self::IMAGE_LEN, found: bytes.len() })?;
        message.zero_padding();
        // Zeroing changed a byte only if that padding byte was not zero.
        let padding = if bytes == message.as_bytes() {
            None
        } else {
            bytes.iter().zip(message.as_bytes()).position(|(a, b)| a != b).map(|i| (i, bytes[i]))
        };
        let crc = CrcCheck { computed: message.computed_crc(), received: message.crc() };
        Ok(Unverified { message, crc, padding })
    }

    /// Decodes a struct image: exact length, zero padding, matching CRC.
    fn decode_image(bytes: &[u8]) -> Result<Self, DecodeError<Self>> {
        Self::decode_image_unverified(bytes)?.verify()
    }

    /// Length of the CDR payload, header included.
    fn cdr_len(encoding: CdrEncoding) -> usize {
        4 + Self::cdr_plan(encoding).body_len
    }

    /// Writes the CDR payload of the sealed message (header, body) into `out`; returns its length.
    fn encode_cdr(&self, encoding: CdrEncoding, out: &mut [u8]) -> Result<usize, BufferTooSmall> {
        let (needed, available) = (Self::cdr_len(encoding), out.len());
        let dst = out.get_mut(..needed).ok_or(BufferTooSmall { needed, available })?;
        dst[..4].copy_from_slice(&encoding.header());
        Self::cdr_plan(encoding).encode(self.sealed().as_bytes(), &mut dst[4..]);
        Ok(needed)
    }

    /// Writes the CDR body of the sealed message (no encapsulation header: for a DDS library
    /// that writes the header itself) into `out`; returns its length.
    fn encode_cdr_body(&self, encoding: CdrEncoding, out: &mut [u8]) -> Result<usize, BufferTooSmall> {
        Self::cdr_plan(encoding).encode_into(self.sealed().as_bytes(), out)
    }

    /// Decodes a CDR payload (XCDR1 or XCDR2) without verifying the CRC.
    fn decode_cdr_unverified(bytes: &[u8]) -> Result<(Unverified<Self>, CdrEncoding), DecodeError<Self>> {
        let header: [u8; 4] = bytes
            .get(..4)
            .and_then(|h| h.try_into().ok())
            .ok_or(DecodeError::NoEncapsulation { found: bytes.len() })?;
        let encoding = CdrEncoding::from_header(header).ok_or(DecodeError::Encapsulation { found: header })?;
        let (unverified, _) = Self::decode_cdr_body_unverified(encoding, &bytes[4..]).map_err(|e| match e {
            // The length in the error counts the header, as the caller's bytes do.
            DecodeError::CdrLength { encoding, expected, found } => {
                DecodeError::CdrLength { encoding, expected: expected + 4, found: found + 4 }
            }
            other => other,
        })?;
        Ok((unverified, encoding))
    }

    /// The zero-padded image a CDR body in `encoding` describes, CRC not checked.
    #[inline]
    fn image_of_cdr_body(encoding: CdrEncoding, body: &[u8]) -> Result<Self, DecodeError<Self>> {
        let mut message = Self::new_zeroed();
        Self::cdr_plan(encoding).decode_from(encoding, body, message.as_mut_bytes())?;
        // Alignment bytes of the body landed on the image's padding: zero it.
        message.zero_padding();
        Ok(message)
    }

    /// Decodes a CDR body in `encoding` (no encapsulation header: a DDS library read it) without
    /// verifying the CRC.
    fn decode_cdr_body_unverified(
        encoding: CdrEncoding,
        body: &[u8],
    ) -> Result<(Unverified<Self>, CdrEncoding), DecodeError<Self>> {
        let message = Self::image_of_cdr_body(encoding, body)?;
        let crc = CrcCheck { computed: message.computed_crc(), received: message.crc() };
        Ok((Unverified { message, crc, padding: None }, encoding))
    }

    /// Decodes a CDR body in `encoding` and verifies the CRC over the rebuilt image (without the
    /// [`Unverified`] detour: the hot path of a DDS reader).
    #[inline]
    fn decode_cdr_body(encoding: CdrEncoding, body: &[u8]) -> Result<Self, DecodeError<Self>> {
        let message = Self::image_of_cdr_body(encoding, body)?;
        let (computed, received) = (message.computed_crc(), message.crc());
        if computed != received && !cfg!(fuzzing) {
            return Err(DecodeError::CrcMismatch { expected: computed, found: received, message });
        }
        Ok(message)
    }

    /// Decodes a CDR payload (XCDR1 or XCDR2) and verifies the CRC over the rebuilt image.
    #[inline]
    fn decode_cdr(bytes: &[u8]) -> Result<(Self, CdrEncoding), DecodeError<Self>> {
        let header: [u8; 4] = bytes
            .get(..4)
            .and_then(|h| h.try_into().ok())
            .ok_or(DecodeError::NoEncapsulation { found: bytes.len() })?;
        let encoding = CdrEncoding::from_header(header).ok_or(DecodeError::Encapsulation { found: header })?;
        match Self::decode_cdr_body(encoding, &bytes[4..]) {
            Ok(message) => Ok((message, encoding)),
            // The length in the error counts the header, as the caller's bytes do.
            Err(DecodeError::CdrLength { encoding, expected, found }) => {
                Err(DecodeError::CdrLength { encoding, expected: expected + 4, found: found + 4 })
            }
            Err(e) => Err(e),
        }
    }
}

impl<M: Message> Unverified<M> {
    /// The message if padding and CRC are right, else the error (carrying the message).
    ///
    /// Built with `cfg(fuzzing)`, both checks pass, so that fuzzers reach the parser.
    pub fn verify(self) -> Result<M, DecodeError<M>> {
        if cfg!(fuzzing) {
            return Ok(self.message);
        }
        if let Some((offset, value)) = self.padding {
            return Err(DecodeError::NonZeroPadding { offset, value });
        }
        if !self.crc.is_ok() {
            return Err(DecodeError::CrcMismatch {
                expected: self.crc.computed,
                found: self.crc.received,
                message: self.message,
            });
        }
        Ok(self.message)
    }
}

macro_rules! message {
    ($ty:ty, $layout:expr, $dds:literal, $topic:literal, $len:literal) => {
        impl sealed::Sealed for $ty {}
        impl Message for $ty {
            const FIELDS: &'static StructLayout = &$layout;
            const DDS_TYPE_NAME: &'static str = $dds;
            const TOPIC: &'static str = $topic;
            const PADDING: &'static [PadRange] = &padding_ranges::<{ padding_count(&$layout) }>(&$layout);
            const PADDING_MASK: &'static [u8] = &padding_mask::<$len, { padding_count(&$layout) }>(&$layout);
            const XCDR1: CdrPlan = cdr_plan!($layout, false);
            const XCDR2: CdrPlan = cdr_plan!($layout, true);
        }
        impl $ty {
            #[doc = concat!("The sealed ", stringify!($len), "-byte struct image (zero padding, CRC).")]
            pub fn to_image(&self) -> [u8; $len] {
                let mut out = [0u8; $len];
                out.copy_from_slice(self.sealed().as_bytes());
                out
            }
        }
        impl robowire_core::cdr::CdrType for $ty {
            const TYPE_NAME: &'static str = $dds;
            type Error = DecodeError<()>;
            fn body_len(&self) -> usize {
                Self::XCDR1.body_len
            }
            /// The sealed message (zero padding, CRC) in XCDR1.
            fn encode_body(&self, out: &mut [u8]) -> Result<usize, BufferTooSmall> {
                self.encode_cdr_body(CdrEncoding::Xcdr1, out)
            }
            /// Decodes and verifies the CRC.
            fn decode_body(encoding: CdrEncoding, body: &[u8]) -> Result<Self, DecodeError<()>> {
                Self::decode_cdr_body(encoding, body).map_err(DecodeError::without_message)
            }
            fn is_checksum_error(error: &DecodeError<()>) -> bool {
                matches!(error, DecodeError::CrcMismatch { .. })
            }
        }
        const _: () = assert!(size_of::<$ty>() == $len && $len <= MAX_IMAGE_LEN);
    };
}

message!(go2::LowCmd, go2::LOW_CMD_LAYOUT, "unitree_go::msg::dds_::LowCmd_", "rt/lowcmd", 812);
message!(go2::LowState, go2::LOW_STATE_LAYOUT, "unitree_go::msg::dds_::LowState_", "rt/lowstate", 1180);
message!(hg::HgLowCmd, hg::HG_LOW_CMD_LAYOUT, "unitree_hg::msg::dds_::LowCmd_", "rt/lowcmd", 1004);
message!(hg::HgLowState, hg::HG_LOW_STATE_LAYOUT, "unitree_hg::msg::dds_::LowState_", "rt/lowstate", 2092);
