//! The RTPS header, a datagram's submessages in order, and a writer that emits a datagram.

use super::{Endianness, Submessage, SubmessageKind, WireError};
use crate::types::{GuidPrefix, Locator, ProtocolVersion, VendorId};
use robowire_core::BufferTooSmall;
use robowire_core::le::array_at;

/// The 20-byte RTPS header: "RTPS", version, vendor, the sender's GUID prefix.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Header {
    /// Protocol version (major 2).
    pub version: ProtocolVersion,
    /// The sender's implementation.
    pub vendor: VendorId,
    /// The sending participant.
    pub guid_prefix: GuidPrefix,
}

impl Header {
    /// Bytes on the wire.
    pub const LEN: usize = 20;
}

/// A datagram with a valid header; its submessages are parsed as they are iterated.
#[derive(Debug, Clone, Copy)]
pub struct Message<'a> {
    header: Header,
    body: &'a [u8],
}

impl<'a> Message<'a> {
    /// Checks the header ("RTPS", major version 2).
    pub fn parse(datagram: &'a [u8]) -> Result<Self, WireError> {
        let (Some(header), Some(body)) = (array_at::<{ Header::LEN }>(datagram, 0), datagram.get(Header::LEN..)) else {
            return Err(WireError::NotRtps);
        };
        let [b'R', b'T', b'P', b'S', major, minor, v0, v1, prefix @ ..] = header else {
            return Err(WireError::NotRtps);
        };
        if major != 2 {
            return Err(WireError::Version { major, minor });
        }
        let header = Header {
            version: ProtocolVersion { major, minor },
            vendor: VendorId([v0, v1]),
            guid_prefix: GuidPrefix(prefix),
        };
        Ok(Self { header, body })
    }

    /// The bytes after the header (the submessages).
    pub fn body(&self) -> &'a [u8] {
        self.body
    }

    /// The header.
    pub fn header(&self) -> Header {
        self.header
    }

    /// The submessages in order. Unknown kinds are yielded as `Submessage::Unknown`; the first
    /// invalid submessage is yielded as an error and ends the iteration (RTPS 8.3.4.1: the rest
    /// of the message is ignored).
    pub fn submessages(&self) -> Submessages<'a> {
        Submessages { rest: self.body, done: false }
    }
}

/// Iterator over a message's submessages.
#[derive(Debug, Clone)]
pub struct Submessages<'a> {
    rest: &'a [u8],
    done: bool,
}

impl<'a> Iterator for Submessages<'a> {
    type Item = Result<Submessage<'a>, WireError>;
    fn next(&mut self) -> Option<Self::Item> {
        if self.done || self.rest.is_empty() {
            return None;
        }
        let result = self.next_submessage();
        self.done = result.is_err();
        Some(result)
    }
}

impl<'a> Submessages<'a> {
    fn next_submessage(&mut self) -> Result<Submessage<'a>, WireError> {
        let [kind, flags, l0, l1] =
            array_at::<4>(self.rest, 0).ok_or(WireError::SubmessageHeader { available: self.rest.len() })?;
        let length = if flags & 1 == 1 { u16::from_le_bytes([l0, l1]) } else { u16::from_be_bytes([l0, l1]) };
        let after = self.rest.get(4..).unwrap_or_default();
        // octetsToNextHeader 0: the submessage runs to the end of the message, except for PAD
        // and INFO_TS, where it is an empty body (RTPS 2.5 §9.4.5.1.3).
        let to_end =
            length == 0 && !matches!(SubmessageKind::from_id(kind), SubmessageKind::Pad | SubmessageKind::InfoTs);
        let (body, rest) = if to_end {
            (after, &[][..])
        } else {
            let available = after.len();
            match (after.get(..usize::from(length)), after.get(usize::from(length)..)) {
                (Some(body), Some(rest)) => (body, rest),
                _ => return Err(WireError::SubmessageLength { kind, length, available }),
            }
        };
        self.rest = rest;
        Submessage::parse(kind, flags, body)
    }
}

/// Emits a datagram (little-endian submessages) into a caller's buffer.
#[derive(Debug)]
pub struct MessageWriter<'b> {
    buf: &'b mut [u8],
    len: usize,
}

// Never empty (`new` writes the header), so no `is_empty`.
#[allow(clippy::len_without_is_empty)]
impl<'b> MessageWriter<'b> {
    /// Writes `header` at the start of `buf`.
    pub fn new(buf: &'b mut [u8], header: &Header) -> Result<Self, BufferTooSmall> {
        let available = buf.len();
        let dst = buf.get_mut(..Header::LEN).ok_or(BufferTooSmall { needed: Header::LEN, available })?;
        let (magic, rest) = dst.split_at_mut(4);
        magic.copy_from_slice(b"RTPS");
        let (version, rest) = rest.split_at_mut(2);
        version.copy_from_slice(&[header.version.major, header.version.minor]);
        let (vendor, prefix) = rest.split_at_mut(2);
        vendor.copy_from_slice(&header.vendor.0);
        prefix.copy_from_slice(&header.guid_prefix.0);
        Ok(Self { buf, len: Header::LEN })
    }

    /// Appends a submessage; on `BufferTooSmall` nothing is appended.
    ///
    /// A submessage whose body is over 65535 bytes is written with octetsToNextHeader 0 ("to the
    /// end of the message"), so it must be the last one pushed.
    pub fn push(&mut self, submessage: &Submessage<'_>) -> Result<(), BufferTooSmall> {
        let available = self.buf.len();
        let needed = self.len.saturating_add(submessage.buffer_len());
        let dst = self.buf.get_mut(self.len..).ok_or(BufferTooSmall { needed, available })?;
        let written = submessage.emit(dst).map_err(|_| BufferTooSmall { needed, available })?;
        self.len += written;
        Ok(())
    }

    /// Bytes written so far (header included).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Room left for submessages.
    pub fn remaining(&self) -> usize {
        self.buf.len().saturating_sub(self.len)
    }

    /// The datagram's length.
    pub fn finish(self) -> usize {
        self.len
    }
}

/// The locator in the 24 bytes of `c` (kind, port, address).
/// Bytes short of 24 read as zeros (`LocatorList` only hands whole locators).
pub(crate) fn locator_at(c: &[u8], e: Endianness) -> Locator {
    let word = |at: usize| {
        let b = array_at::<4>(c, at).unwrap_or_default();
        match e {
            Endianness::Little => u32::from_le_bytes(b),
            Endianness::Big => u32::from_be_bytes(b),
        }
    };
    Locator { kind: word(0) as i32, port: word(4), address: array_at::<16>(c, 8).unwrap_or_default() }
}
