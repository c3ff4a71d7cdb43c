//! Every submessage kind as a repr: parsed from a body with its flags and endianness, emitted
//! little-endian. Reprs borrow payloads, parameter lists and locator lists from the datagram.

use super::{Endianness, ParameterList, WireError};
use crate::types::{
    EntityId, FragmentNumberSet, GuidPrefix, Locator, ProtocolVersion, SequenceNumber, SequenceNumberSet, Timestamp,
    VendorId,
};

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

/// What a DATA carries after its inline QoS: nothing, a serialized sample, or a serialized key
/// (D and K flags). Both include the 4-byte encapsulation header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Payload<'a> {
    /// Neither D nor K (a state change in the inline QoS alone).
    None,
    /// D: the serialized sample.
    Data(&'a [u8]),
    /// K: the serialized key.
    Key(&'a [u8]),
}

/// DATA: one sample (or a key and a status change) from a writer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Data<'a> {
    /// The reader it is for (`EntityId::UNKNOWN`: every matched reader).
    pub reader_id: EntityId,
    /// The writer.
    pub writer_id: EntityId,
    /// The sample's number (≥ 1).
    pub writer_sn: SequenceNumber,
    /// Inline QoS (Q flag): key hash, status info, related sample identity, …
    pub inline_qos: Option<ParameterList<'a>>,
    /// The payload (D or K flag).
    pub payload: Payload<'a>,
    /// N flag: the payload is not CDR-encapsulated.
    pub non_standard_payload: bool,
}

/// DATA_FRAG: fragments `fragment_starting_num ..` of one sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DataFrag<'a> {
    /// The reader it is for.
    pub reader_id: EntityId,
    /// The writer.
    pub writer_id: EntityId,
    /// The sample's number (≥ 1).
    pub writer_sn: SequenceNumber,
    /// The first fragment here (≥ 1).
    pub fragment_starting_num: u32,
    /// How many fragments follow (≥ 1).
    pub fragments_in_submessage: u16,
    /// Bytes per fragment (≥ 1; the last fragment of the sample may be shorter).
    pub fragment_size: u16,
    /// Bytes of the whole sample.
    pub sample_size: u32,
    /// Inline QoS (Q flag).
    pub inline_qos: Option<ParameterList<'a>>,
    /// K flag: the fragments are of a serialized key.
    pub key: bool,
    /// N flag: not CDR-encapsulated.
    pub non_standard_payload: bool,
    /// The fragments' bytes (checked against the fragment count, size and sample size).
    pub payload: &'a [u8],
}

impl DataFrag<'_> {
    /// Fragments of the whole sample: `sample_size / fragment_size`, rounded up.
    pub fn total_fragments(&self) -> u32 {
        self.sample_size.div_ceil(u32::from(self.fragment_size.max(1)))
    }
}

/// HEARTBEAT: a writer's available range `first_sn ..= last_sn`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Heartbeat {
    /// The reader it is for.
    pub reader_id: EntityId,
    /// The writer.
    pub writer_id: EntityId,
    /// The first available number (≥ 1).
    pub first_sn: SequenceNumber,
    /// The last available number (≥ first − 1: empty when first_sn = last_sn + 1).
    pub last_sn: SequenceNumber,
    /// The heartbeat's count (later heartbeats have larger counts).
    pub count: i32,
    /// F: no response required.
    pub final_flag: bool,
    /// L: a liveliness assertion.
    pub liveliness_flag: bool,
}

/// HEARTBEAT_FRAG: fragments `1 ..= last_fragment_num` of a sample are available.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HeartbeatFrag {
    /// The reader it is for.
    pub reader_id: EntityId,
    /// The writer.
    pub writer_id: EntityId,
    /// The sample.
    pub writer_sn: SequenceNumber,
    /// The last fragment available (≥ 1).
    pub last_fragment_num: u32,
    /// The count.
    pub count: i32,
}

/// ACKNACK: the reader has every number below the set's base and misses the set's members.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AckNack {
    /// The reader.
    pub reader_id: EntityId,
    /// The writer it is for.
    pub writer_id: EntityId,
    /// Base: first number not yet received; members: numbers requested again.
    pub reader_sn_state: SequenceNumberSet,
    /// The count.
    pub count: i32,
    /// F: the writer need not answer with a heartbeat.
    pub final_flag: bool,
}

/// NACK_FRAG: the fragments of one sample the reader misses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NackFrag {
    /// The reader.
    pub reader_id: EntityId,
    /// The writer it is for.
    pub writer_id: EntityId,
    /// The sample.
    pub writer_sn: SequenceNumber,
    /// The missing fragments (base ≥ 1).
    pub fragment_number_state: FragmentNumberSet,
    /// The count.
    pub count: i32,
}

/// GAP: numbers `gap_start .. gap_list.base()` and the list's members are irrelevant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Gap {
    /// The reader it is for.
    pub reader_id: EntityId,
    /// The writer.
    pub writer_id: EntityId,
    /// The first irrelevant number (≥ 1).
    pub gap_start: SequenceNumber,
    /// `base` ≥ `gap_start`: every number from `gap_start` up to it is irrelevant, and so are
    /// the members.
    pub gap_list: SequenceNumberSet,
}

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
        self.bytes.chunks_exact(24).map(move |c| super::message::locator_at(c, e))
    }
}

// Parse and emit (in message.rs and here) are written against these reprs:
// `Submessage::parse(kind: u8, flags: u8, body: &'a [u8]) -> Result<Submessage<'a>, WireError>`,
// `Submessage::buffer_len(&self) -> usize` (header included), `Submessage::emit(&self, buf)`.
#[allow(dead_code)]
fn _contract(_: WireError) {}
