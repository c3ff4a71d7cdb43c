//! The RTPS header, a datagram's submessages in order, and a writer that emits a datagram.

use super::{Endianness, Submessage, WireError};
use crate::types::{GuidPrefix, Locator, ProtocolVersion, VendorId};
use robowire_core::BufferTooSmall;

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
        let _ = datagram;
        todo!()
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
        let _ = (self.rest, self.done);
        todo!()
    }
}

/// Emits a datagram (little-endian submessages) into a caller's buffer.
#[derive(Debug)]
pub struct MessageWriter<'b> {
    buf: &'b mut [u8],
    len: usize,
}

impl<'b> MessageWriter<'b> {
    /// Writes `header` at the start of `buf`.
    pub fn new(buf: &'b mut [u8], header: &Header) -> Result<Self, BufferTooSmall> {
        let _ = header;
        Ok(Self { buf, len: 0 })
    }

    /// Appends a submessage; on `BufferTooSmall` nothing is appended.
    pub fn push(&mut self, submessage: &Submessage<'_>) -> Result<(), BufferTooSmall> {
        let _ = (submessage, &mut self.buf);
        todo!()
    }

    /// Bytes written so far (header included).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Room left for submessages.
    pub fn remaining(&self) -> usize {
        self.buf.len() - self.len
    }

    /// The datagram's length.
    pub fn finish(self) -> usize {
        self.len
    }
}

/// The locator in the 24 bytes of `c` (kind, port, address).
pub(crate) fn locator_at(c: &[u8], e: Endianness) -> Locator {
    let _ = (c, e);
    todo!()
}
