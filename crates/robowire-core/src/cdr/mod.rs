//! What a DDS transport needs of a codec: the CDR representations (spec `unitree-lowlevel.md`
//! §6) and [`CdrType`], a message with a DDS type name whose CDR body the codec writes and
//! reads. A DDS library writes and reads the 4-byte encapsulation header itself; the codec owns
//! every byte after it. The transport never has a type system of its own.

/// A CDR representation, little endian, with its 4-byte encapsulation header.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CdrEncoding {
    /// XCDR1, plain CDR_LE: `00 01 00 00`. What CycloneDDS 0.10 and Unitree's publishers write.
    Xcdr1,
    /// XCDR2, CDR2_LE: `00 07 00 00`.
    Xcdr2,
}

impl CdrEncoding {
    /// The encapsulation header.
    pub const fn header(self) -> [u8; 4] {
        match self {
            Self::Xcdr1 => [0x00, 0x01, 0x00, 0x00],
            Self::Xcdr2 => [0x00, 0x07, 0x00, 0x00],
        }
    }

    /// The representation identifier (the header's first two bytes).
    pub const fn identifier(self) -> [u8; 2] {
        let header = self.header();
        [header[0], header[1]]
    }

    /// The encoding a header announces.
    pub fn from_header(header: [u8; 4]) -> Option<Self> {
        Self::from_identifier([header[0], header[1]])
    }

    /// The encoding a representation identifier names (`00 01` or `00 07`).
    pub fn from_identifier(identifier: [u8; 2]) -> Option<Self> {
        [Self::Xcdr1, Self::Xcdr2].into_iter().find(|e| e.identifier() == identifier)
    }
}

/// A message a DDS topic carries: its type name on the wire and its CDR body, written in
/// [`CdrType::ENCODING`] and read in either representation.
///
/// ```
/// use robowire_core::BufferTooSmall;
/// use robowire_core::cdr::{CdrEncoding, CdrType};
///
/// /// `struct Tick_ { uint32 count; };`
/// #[derive(Debug, PartialEq)]
/// struct Tick(u32);
///
/// impl CdrType for Tick {
///     const TYPE_NAME: &'static str = "example::Tick_";
///     type Error = &'static str;
///     fn body_len(&self) -> usize {
///         4
///     }
///     fn encode_body(&self, out: &mut [u8]) -> Result<usize, BufferTooSmall> {
///         let available = out.len();
///         out.get_mut(..4).ok_or(BufferTooSmall { needed: 4, available })?.copy_from_slice(&self.0.to_le_bytes());
///         Ok(4)
///     }
///     fn decode_body(_: CdrEncoding, body: &[u8]) -> Result<Self, Self::Error> {
///         let bytes: [u8; 4] = body.try_into().map_err(|_| "not 4 bytes")?;
///         Ok(Tick(u32::from_le_bytes(bytes)))
///     }
/// }
///
/// let mut body = [0u8; 4];
/// let n = Tick(7).encode_body(&mut body).unwrap();
/// assert_eq!(Tick::decode_body(CdrEncoding::Xcdr1, &body[..n]), Ok(Tick(7)));
/// ```
pub trait CdrType: Sized {
    /// The DDS type name, e.g. `unitree_go::msg::dds_::LowCmd_`.
    const TYPE_NAME: &'static str;
    /// The representation written. Default XCDR1, what CycloneDDS 0.10 writes for final types.
    const ENCODING: CdrEncoding = CdrEncoding::Xcdr1;
    /// Why a body could not be read.
    type Error: core::fmt::Debug + core::fmt::Display;

    /// Length of this message's body in [`ENCODING`](Self::ENCODING), bytes.
    fn body_len(&self) -> usize;

    /// Writes the body in [`ENCODING`](Self::ENCODING) (no encapsulation header); its length.
    fn encode_body(&self, out: &mut [u8]) -> Result<usize, crate::BufferTooSmall>;

    /// Reads a body in `encoding` (the DDS library read the header).
    fn decode_body(encoding: CdrEncoding, body: &[u8]) -> Result<Self, Self::Error>;

    /// Whether `error` is an integrity check that failed (a CRC): a transport counts these apart
    /// from malformed bodies.
    fn is_checksum_error(error: &Self::Error) -> bool {
        let _ = error;
        false
    }
}

mod cursor;
pub use cursor::{CdrError, CdrReader, CdrWriter};
