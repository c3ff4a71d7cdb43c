//! Why SPDP or SEDP data is refused.

use crate::wire::WireError;

/// Why discovery data is refused (the whole DATA is then ignored). `Copy`, no allocation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum DiscoveryError {
    /// No participant GUID (SPDP) or endpoint GUID and no key hash (SEDP).
    #[error("no GUID in the discovery data")]
    MissingGuid,
    /// A parameter the data cannot do without (a topic or type name) is absent.
    #[error("parameter {pid:#06x} is required and absent")]
    Missing {
        /// The PID.
        pid: u16,
    },
    /// The payload is shorter than its 4-byte encapsulation header.
    #[error("a {length}-byte payload has no encapsulation header")]
    ShortPayload {
        /// The payload's length in bytes.
        length: usize,
    },
    /// The encapsulation is neither PL_CDR_BE (00 02) nor PL_CDR_LE (00 03).
    #[error("encapsulation {0:02x?} is not a parameter list")]
    Encapsulation([u8; 2]),
    /// The parameter list is malformed.
    #[error("bad parameter list: {0}")]
    Wire(#[from] WireError),
    /// The parameter list is longer than `Limits::parameter_list_bytes`.
    #[error("a {length}-byte parameter list exceeds the limit of {limit} bytes")]
    ListTooLong {
        /// The list's length in bytes.
        length: usize,
        /// The limit.
        limit: usize,
    },
    /// A string's length does not fit its parameter, or the string lacks its NUL.
    #[error("parameter {pid:#06x}: string length {length} does not fit the value or lacks its NUL")]
    StringLength {
        /// The PID.
        pid: u16,
        /// The length the wire gave.
        length: u32,
    },
    /// A value is shorter than its type needs (or a sequence count exceeds the value).
    #[error("parameter {pid:#06x}: needs {expected} bytes, the value has {found}")]
    ValueLength {
        /// The PID.
        pid: u16,
        /// Bytes needed.
        expected: usize,
        /// Bytes the value has.
        found: usize,
    },
    /// A string, sequence or passed-through value exceeds `Limits::parameter_bytes`.
    #[error("parameter {pid:#06x}: {length} bytes exceed the limit of {limit}")]
    TooLong {
        /// The PID.
        pid: u16,
        /// Bytes the wire asked for.
        length: usize,
        /// The limit.
        limit: usize,
    },
    /// An unknown PID with the must-understand bit (0x4000): RTPS says to ignore the data.
    #[error("parameter {pid:#06x} must be understood and is not")]
    MustUnderstand {
        /// The PID.
        pid: u16,
    },
    /// A string is not UTF-8.
    #[error("parameter {pid:#06x}: string is not UTF-8")]
    NotUtf8 {
        /// The PID.
        pid: u16,
    },
    /// An enumerated kind out of range, or a KEEP_LAST depth below 1.
    #[error("parameter {pid:#06x}: value out of range")]
    InvalidValue {
        /// The PID.
        pid: u16,
    },
}
