//! Every submessage kind as a repr: parsed from a body with its flags and endianness, emitted
//! little-endian. Reprs borrow payloads, parameter lists and locator lists from the datagram.
//!
//! This module holds the submessage ids ([`SubmessageKind`]), the [`Submessage`] enum and its
//! dispatch (parse, flags, length, emission, the 4-byte header); each family's reprs and bodies
//! sit in their own module: `data` (DATA, DATA_FRAG), `ack` (HEARTBEAT, HEARTBEAT_FRAG, ACKNACK,
//! NACK_FRAG, GAP), `info` (INFO_TS, INFO_DST, INFO_SRC, INFO_REPLY, INFO_REPLY_IP4), on the
//! field reader and writers of `body`.

mod ack;
mod body;
mod data;
mod info;

pub use ack::{AckNack, Gap, Heartbeat, HeartbeatFrag, NackFrag};
pub use data::{Data, DataFrag, Payload};
pub use info::{InfoDst, InfoReply, InfoReplyIp4, InfoSrc, InfoTs, LocatorList};

use super::WireError;
use body::Reader;
use robowire_core::BufferTooSmall;
use robowire_core::le::LeWriter;

/// Submessage ids (RTPS 2.5 table 9.13).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SubmessageKind {
    /// 0x01.
    Pad,
    /// 0x06.
    AckNack,
    /// 0x07.
    Heartbeat,
    /// 0x08.
    Gap,
    /// 0x09.
    InfoTs,
    /// 0x0c.
    InfoSrc,
    /// 0x0d.
    InfoReplyIp4,
    /// 0x0e.
    InfoDst,
    /// 0x0f.
    InfoReply,
    /// 0x12.
    NackFrag,
    /// 0x13.
    HeartbeatFrag,
    /// 0x15.
    Data,
    /// 0x16.
    DataFrag,
    /// Any other id (vendor-specific 0x80..=0xff included): skipped by its length.
    Unknown(u8),
}

/// A submessage, parsed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Submessage<'a> {
    /// DATA.
    Data(Data<'a>),
    /// DATA_FRAG.
    DataFrag(DataFrag<'a>),
    /// HEARTBEAT.
    Heartbeat(Heartbeat),
    /// HEARTBEAT_FRAG.
    HeartbeatFrag(HeartbeatFrag),
    /// ACKNACK.
    AckNack(AckNack),
    /// NACK_FRAG.
    NackFrag(NackFrag),
    /// GAP.
    Gap(Gap),
    /// INFO_TS.
    InfoTs(InfoTs),
    /// INFO_DST.
    InfoDst(InfoDst),
    /// INFO_SRC.
    InfoSrc(InfoSrc),
    /// INFO_REPLY.
    InfoReply(InfoReply<'a>),
    /// INFO_REPLY_IP4.
    InfoReplyIp4(InfoReplyIp4),
    /// PAD.
    Pad,
    /// An id this crate does not interpret, kept with its flags and body.
    Unknown {
        /// The submessage id.
        kind: u8,
        /// Its flags.
        flags: u8,
        /// Its body.
        body: &'a [u8],
    },
}

/// E: the submessage is little-endian.
const FLAG_E: u8 = 0x01;

impl SubmessageKind {
    /// The kind of submessage id `id`.
    pub const fn from_id(id: u8) -> Self {
        match id {
            0x01 => Self::Pad,
            0x06 => Self::AckNack,
            0x07 => Self::Heartbeat,
            0x08 => Self::Gap,
            0x09 => Self::InfoTs,
            0x0c => Self::InfoSrc,
            0x0d => Self::InfoReplyIp4,
            0x0e => Self::InfoDst,
            0x0f => Self::InfoReply,
            0x12 => Self::NackFrag,
            0x13 => Self::HeartbeatFrag,
            0x15 => Self::Data,
            0x16 => Self::DataFrag,
            other => Self::Unknown(other),
        }
    }

    /// The submessage id.
    pub const fn id(self) -> u8 {
        match self {
            Self::Pad => 0x01,
            Self::AckNack => 0x06,
            Self::Heartbeat => 0x07,
            Self::Gap => 0x08,
            Self::InfoTs => 0x09,
            Self::InfoSrc => 0x0c,
            Self::InfoReplyIp4 => 0x0d,
            Self::InfoDst => 0x0e,
            Self::InfoReply => 0x0f,
            Self::NackFrag => 0x12,
            Self::HeartbeatFrag => 0x13,
            Self::Data => 0x15,
            Self::DataFrag => 0x16,
            Self::Unknown(id) => id,
        }
    }
}

impl<'a> Submessage<'a> {
    /// Parses the body of a submessage of id `kind` with `flags` (bit 0: E, little-endian).
    pub fn parse(kind: u8, flags: u8, body: &'a [u8]) -> Result<Self, WireError> {
        let mut r = Reader::new(kind, flags, body);
        Ok(match SubmessageKind::from_id(kind) {
            SubmessageKind::Pad => Self::Pad,
            SubmessageKind::Data => Self::Data(Data::parse(&mut r, flags)?),
            SubmessageKind::DataFrag => Self::DataFrag(DataFrag::parse(&mut r, flags)?),
            SubmessageKind::Heartbeat => Self::Heartbeat(Heartbeat::parse(&mut r, flags)?),
            SubmessageKind::HeartbeatFrag => Self::HeartbeatFrag(HeartbeatFrag::parse(&mut r)?),
            SubmessageKind::AckNack => Self::AckNack(AckNack::parse(&mut r, flags)?),
            SubmessageKind::NackFrag => Self::NackFrag(NackFrag::parse(&mut r)?),
            SubmessageKind::Gap => Self::Gap(Gap::parse(&mut r)?),
            SubmessageKind::InfoTs => Self::InfoTs(InfoTs::parse(&mut r, flags)?),
            SubmessageKind::InfoDst => Self::InfoDst(InfoDst::parse(&mut r)?),
            SubmessageKind::InfoSrc => Self::InfoSrc(InfoSrc::parse(&mut r)?),
            SubmessageKind::InfoReply => Self::InfoReply(InfoReply::parse(&mut r, flags)?),
            SubmessageKind::InfoReplyIp4 => Self::InfoReplyIp4(InfoReplyIp4::parse(&mut r, flags)?),
            SubmessageKind::Unknown(kind) => Self::Unknown { kind, flags, body },
        })
    }

    /// The submessage's kind.
    pub fn kind(&self) -> SubmessageKind {
        match self {
            Self::Data(_) => SubmessageKind::Data,
            Self::DataFrag(_) => SubmessageKind::DataFrag,
            Self::Heartbeat(_) => SubmessageKind::Heartbeat,
            Self::HeartbeatFrag(_) => SubmessageKind::HeartbeatFrag,
            Self::AckNack(_) => SubmessageKind::AckNack,
            Self::NackFrag(_) => SubmessageKind::NackFrag,
            Self::Gap(_) => SubmessageKind::Gap,
            Self::InfoTs(_) => SubmessageKind::InfoTs,
            Self::InfoDst(_) => SubmessageKind::InfoDst,
            Self::InfoSrc(_) => SubmessageKind::InfoSrc,
            Self::InfoReply(_) => SubmessageKind::InfoReply,
            Self::InfoReplyIp4(_) => SubmessageKind::InfoReplyIp4,
            Self::Pad => SubmessageKind::Pad,
            Self::Unknown { kind, .. } => SubmessageKind::from_id(*kind),
        }
    }

    /// The flags [`Submessage::emit`] writes (E set; an `Unknown`'s flags as they came).
    pub fn flags(&self) -> u8 {
        FLAG_E
            | match self {
                Self::Data(d) => d.flags(),
                Self::DataFrag(d) => d.flags(),
                Self::Heartbeat(h) => h.flags(),
                Self::AckNack(a) => a.flags(),
                Self::InfoTs(t) => t.flags(),
                Self::InfoReply(r) => r.flags(),
                Self::InfoReplyIp4(r) => r.flags(),
                Self::Unknown { flags, .. } => return *flags,
                Self::HeartbeatFrag(_)
                | Self::NackFrag(_)
                | Self::Gap(_)
                | Self::InfoDst(_)
                | Self::InfoSrc(_)
                | Self::Pad => 0,
            }
    }

    fn body_len(&self) -> usize {
        match self {
            Self::Data(d) => d.body_len(),
            Self::DataFrag(d) => d.body_len(),
            Self::Heartbeat(_) => 28,
            Self::HeartbeatFrag(_) => 24,
            Self::AckNack(a) => a.body_len(),
            Self::NackFrag(n) => n.body_len(),
            Self::Gap(g) => g.body_len(),
            Self::InfoTs(t) => t.body_len(),
            Self::InfoDst(_) => 12,
            Self::InfoSrc(_) => 20,
            Self::InfoReply(r) => r.body_len(),
            Self::InfoReplyIp4(r) => r.body_len(),
            Self::Pad => 0,
            Self::Unknown { body, .. } => body.len(),
        }
    }

    /// Bytes [`Submessage::emit`] writes, the 4-byte submessage header included.
    pub fn buffer_len(&self) -> usize {
        4 + self.body_len()
    }

    /// Writes the submessage (header and body, little-endian, E set; an `Unknown` with its own
    /// flags and body, its length in the byte order its E flag gives) at the start of `buf`;
    /// returns [`Submessage::buffer_len`]. Nothing is written when `buf` is too small.
    ///
    /// A body over 65535 bytes gets octetsToNextHeader 0 (it must end the message). A DATA_FRAG's
    /// payload is padded with zeros to a multiple of 4; a DATA's payload is written as given
    /// (its serializer pads it and says so in the encapsulation options).
    pub fn emit(&self, buf: &mut [u8]) -> Result<usize, BufferTooSmall> {
        let needed = self.buffer_len();
        let available = buf.len();
        let dst = buf.get_mut(..needed).ok_or(BufferTooSmall { needed, available })?;
        let mut w = LeWriter::new(dst);
        w.put_u8(self.kind().id())?;
        let flags = self.flags();
        w.put_u8(flags)?;
        // The length is in the submessage's byte order: an `Unknown`'s flags may say big-endian.
        let length = u16::try_from(needed - 4).unwrap_or(0);
        w.put_bytes(&if flags & FLAG_E != 0 { length.to_le_bytes() } else { length.to_be_bytes() })?;
        match self {
            Self::Data(d) => d.emit_body(&mut w)?,
            Self::DataFrag(d) => d.emit_body(&mut w)?,
            Self::Heartbeat(h) => h.emit_body(&mut w)?,
            Self::HeartbeatFrag(h) => h.emit_body(&mut w)?,
            Self::AckNack(a) => a.emit_body(&mut w)?,
            Self::NackFrag(n) => n.emit_body(&mut w)?,
            Self::Gap(g) => g.emit_body(&mut w)?,
            Self::InfoTs(t) => t.emit_body(&mut w)?,
            Self::InfoDst(d) => d.emit_body(&mut w)?,
            Self::InfoSrc(s) => s.emit_body(&mut w)?,
            Self::InfoReply(r) => r.emit_body(&mut w)?,
            Self::InfoReplyIp4(r) => r.emit_body(&mut w)?,
            Self::Pad => {}
            Self::Unknown { body, .. } => w.put_bytes(body)?,
        }
        Ok(w.written())
    }
}
