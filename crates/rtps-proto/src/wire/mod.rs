//! RTPS messages on the wire, as smoltcp's `wire` module does it: checked parsing of borrowed
//! bytes into owned (or borrowing) reprs, and emission into a caller's buffer.
//!
//! No-panic contract: `Message::parse`, the `Submessages` iterator, `ParameterList::parse` and
//! every accessor on their results never panic and never allocate, on any input. Every length,
//! count, range and offset is checked before it is used; a refusal is a [`WireError`] (`Copy`),
//! whose [`WireError::kind`] indexes the counters ([`WireErrorCounts`]).
//!
//! Receive accepts both endiannesses (each submessage's E flag); emission is little-endian.

mod error;
mod message;
mod parameter;
pub mod pid;
mod submessage;

pub use error::{WireError, WireErrorCounts, WireErrorKind};
pub use message::{Header, Message, MessageWriter, Submessages};
pub use parameter::{Parameter, ParameterList, ParameterWriter};
pub use submessage::{
    AckNack, Data, DataFrag, Gap, Heartbeat, HeartbeatFrag, InfoDst, InfoReply, InfoReplyIp4, InfoSrc, InfoTs,
    LocatorList, NackFrag, Payload, Submessage, SubmessageKind,
};

/// Byte order of a submessage (its E flag) or parameter list.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Endianness {
    /// E = 0.
    Big,
    /// E = 1 (what robowire sends).
    Little,
}
