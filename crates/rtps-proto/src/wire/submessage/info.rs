//! The info family, which sets the context of the submessages that follow it: INFO_TS (their
//! source timestamp), INFO_DST (their destination), INFO_SRC (their source), INFO_REPLY and
//! INFO_REPLY_IP4 (where replies go, as a [`LocatorList`] or IPv4 locators); with their flags
//! and how their bodies are parsed and emitted.

use super::body::{Reader, flag};
use crate::types::{GuidPrefix, Locator, ProtocolVersion, Timestamp, VendorId};
use crate::wire::{Endianness, WireError};
use robowire_core::BufferTooSmall;
use robowire_core::le::LeWriter;

/// INFO_TS: the source timestamp of the submessages that follow (`None`: I flag, invalidate).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InfoTs {
    /// The timestamp.
    pub timestamp: Option<Timestamp>,
}

/// INFO_DST: the submessages that follow are for this participant (`UNKNOWN`: anyone).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InfoDst {
    /// The destination.
    pub guid_prefix: GuidPrefix,
}

/// INFO_SRC: the submessages that follow come from this participant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InfoSrc {
    /// Its protocol version.
    pub version: ProtocolVersion,
    /// Its vendor.
    pub vendor: VendorId,
    /// Its prefix.
    pub guid_prefix: GuidPrefix,
}

/// INFO_REPLY: where to send replies to the submessages that follow.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InfoReply<'a> {
    /// Unicast locators.
    pub unicast: LocatorList<'a>,
    /// Multicast locators (M flag).
    pub multicast: Option<LocatorList<'a>>,
}

/// INFO_REPLY_IP4: INFO_REPLY with one IPv4 unicast and an optional multicast locator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InfoReplyIp4 {
    /// The unicast locator (kind UDPv4).
    pub unicast: Locator,
    /// The multicast locator (M flag).
    pub multicast: Option<Locator>,
}

/// A list of locators as the wire has it (a count, then 24 bytes each), checked on parse: the
/// count fits the bytes. Iterating it decodes each locator; it never allocates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LocatorList<'a> {
    pub(crate) bytes: &'a [u8],
    pub(crate) endianness: Endianness,
}

impl<'a> LocatorList<'a> {
    /// How many locators.
    pub fn len(&self) -> usize {
        self.bytes.len() / 24
    }

    /// No locators.
    pub fn is_empty(&self) -> bool {
        self.bytes.len() < 24
    }

    /// The locators in order.
    pub fn iter(&self) -> impl Iterator<Item = Locator> + 'a {
        let e = self.endianness;
        self.bytes.chunks_exact(24).map(move |c| crate::wire::message::locator_at(c, e))
    }
}

/// I (INFO_TS): invalidate, no timestamp.
const INFO_TS_FLAG_I: u8 = 0x02;
/// M (INFO_REPLY, INFO_REPLY_IP4): multicast locators present.
const FLAG_M: u8 = 0x02;

impl<'a> LocatorList<'a> {
    /// A list over `bytes`, whole 24-byte locators (kind, port, address) in byte order
    /// `endianness`, without the count; `LocatorCount` when `bytes` is not whole locators.
    pub fn new(bytes: &'a [u8], endianness: Endianness) -> Result<Self, WireError> {
        if !bytes.len().is_multiple_of(24) {
            let count = u32::try_from(bytes.len().div_ceil(24)).unwrap_or(u32::MAX);
            return Err(WireError::LocatorCount { count, available: bytes.len() });
        }
        Ok(Self { bytes, endianness })
    }

    /// The byte order of the locators.
    pub fn endianness(&self) -> Endianness {
        self.endianness
    }

    /// The locators' bytes (without the count).
    pub fn as_bytes(&self) -> &'a [u8] {
        self.bytes
    }

    fn buffer_len(&self) -> usize {
        4 + self.bytes.len()
    }

    fn emit(&self, w: &mut LeWriter<'_>) -> Result<(), BufferTooSmall> {
        w.put_u32(u32::try_from(self.len()).unwrap_or(u32::MAX))?;
        for l in self.iter() {
            put_locator(w, &l)?;
        }
        Ok(())
    }
}

fn put_locator(w: &mut LeWriter<'_>, l: &Locator) -> Result<(), BufferTooSmall> {
    w.put_bytes(&l.kind.to_le_bytes())?;
    w.put_u32(l.port)?;
    w.put_bytes(&l.address)
}

impl InfoTs {
    /// Parses an INFO_TS body (flags: the submessage's).
    pub(super) fn parse(r: &mut Reader<'_>, flags: u8) -> Result<Self, WireError> {
        let timestamp = if flags & INFO_TS_FLAG_I != 0 {
            None
        } else {
            let seconds = r.i32()?;
            Some(Timestamp { seconds, fraction: r.u32()? })
        };
        Ok(InfoTs { timestamp })
    }

    /// The flags emitted, E aside.
    pub(super) fn flags(&self) -> u8 {
        flag(self.timestamp.is_none(), INFO_TS_FLAG_I)
    }

    /// Bytes of the body emitted.
    pub(super) fn body_len(&self) -> usize {
        if self.timestamp.is_some() { 8 } else { 0 }
    }

    /// Writes the body.
    pub(super) fn emit_body(&self, w: &mut LeWriter<'_>) -> Result<(), BufferTooSmall> {
        if let Some(ts) = self.timestamp {
            w.put_bytes(&ts.seconds.to_le_bytes())?;
            w.put_u32(ts.fraction)?;
        }
        Ok(())
    }
}

impl InfoDst {
    /// Parses an INFO_DST body.
    pub(super) fn parse(r: &mut Reader<'_>) -> Result<Self, WireError> {
        Ok(InfoDst { guid_prefix: GuidPrefix(r.array()?) })
    }

    /// Writes the body (12 bytes).
    pub(super) fn emit_body(&self, w: &mut LeWriter<'_>) -> Result<(), BufferTooSmall> {
        w.put_bytes(&self.guid_prefix.0)
    }
}

impl InfoSrc {
    /// Parses an INFO_SRC body.
    pub(super) fn parse(r: &mut Reader<'_>) -> Result<Self, WireError> {
        let _unused = r.u32()?;
        let [major, minor] = r.array()?;
        let vendor = VendorId(r.array()?);
        let guid_prefix = GuidPrefix(r.array()?);
        Ok(InfoSrc { version: ProtocolVersion { major, minor }, vendor, guid_prefix })
    }

    /// Writes the body (20 bytes).
    pub(super) fn emit_body(&self, w: &mut LeWriter<'_>) -> Result<(), BufferTooSmall> {
        w.put_u32(0)?;
        w.put_bytes(&[self.version.major, self.version.minor])?;
        w.put_bytes(&self.vendor.0)?;
        w.put_bytes(&self.guid_prefix.0)
    }
}

impl<'a> InfoReply<'a> {
    /// Parses an INFO_REPLY body (flags: the submessage's).
    pub(super) fn parse(r: &mut Reader<'a>, flags: u8) -> Result<Self, WireError> {
        let unicast = r.locators()?;
        let multicast = if flags & FLAG_M != 0 { Some(r.locators()?) } else { None };
        Ok(InfoReply { unicast, multicast })
    }

    /// The flags emitted, E aside.
    pub(super) fn flags(&self) -> u8 {
        flag(self.multicast.is_some(), FLAG_M)
    }

    /// Bytes of the body emitted.
    pub(super) fn body_len(&self) -> usize {
        self.unicast.buffer_len() + self.multicast.as_ref().map_or(0, LocatorList::buffer_len)
    }

    /// Writes the body.
    pub(super) fn emit_body(&self, w: &mut LeWriter<'_>) -> Result<(), BufferTooSmall> {
        self.unicast.emit(w)?;
        if let Some(m) = &self.multicast {
            m.emit(w)?;
        }
        Ok(())
    }
}

impl InfoReplyIp4 {
    /// Parses an INFO_REPLY_IP4 body (flags: the submessage's).
    pub(super) fn parse(r: &mut Reader<'_>, flags: u8) -> Result<Self, WireError> {
        let unicast = r.udpv4()?;
        let multicast = if flags & FLAG_M != 0 { Some(r.udpv4()?) } else { None };
        Ok(InfoReplyIp4 { unicast, multicast })
    }

    /// The flags emitted, E aside.
    pub(super) fn flags(&self) -> u8 {
        flag(self.multicast.is_some(), FLAG_M)
    }

    /// Bytes of the body emitted.
    pub(super) fn body_len(&self) -> usize {
        if self.multicast.is_some() { 16 } else { 8 }
    }

    /// Writes the body.
    pub(super) fn emit_body(&self, w: &mut LeWriter<'_>) -> Result<(), BufferTooSmall> {
        for l in core::iter::once(&self.unicast).chain(&self.multicast) {
            let address = robowire_core::le::array_at::<4>(&l.address, 12).unwrap_or_default();
            w.put_u32(u32::from_be_bytes(address))?;
            w.put_u32(l.port)?;
        }
        Ok(())
    }
}
