//! Every submessage kind as a repr: parsed from a body with its flags and endianness, emitted
//! little-endian. Reprs borrow payloads, parameter lists and locator lists from the datagram.

use super::{Endianness, ParameterList, WireError, pid};
use crate::types::{
    EntityId, FragmentNumberSet, GuidPrefix, Locator, ProtocolVersion, SequenceNumber, SequenceNumberSet, SetError,
    Timestamp, VendorId,
};
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

/// E: the submessage is little-endian.
const FLAG_E: u8 = 0x01;
/// Q (DATA, DATA_FRAG): inline QoS present.
const FLAG_Q: u8 = 0x02;
/// D (DATA): serialized data.
const DATA_FLAG_D: u8 = 0x04;
/// K (DATA): serialized key.
const DATA_FLAG_K: u8 = 0x08;
/// N (DATA): non-standard payload.
const DATA_FLAG_N: u8 = 0x10;
/// K (DATA_FRAG, RTPS 2.5 §9.4.5.4; CycloneDDS `DDSI_DATAFRAG_FLAG_KEYFLAG`).
const DATAFRAG_FLAG_K: u8 = 0x04;
/// N (DATA_FRAG, RTPS 2.5 §9.4.5.4).
const DATAFRAG_FLAG_N: u8 = 0x08;
/// F (HEARTBEAT, ACKNACK): final.
const FLAG_F: u8 = 0x02;
/// L (HEARTBEAT): liveliness.
const HEARTBEAT_FLAG_L: u8 = 0x04;
/// I (INFO_TS): invalidate, no timestamp.
const INFO_TS_FLAG_I: u8 = 0x02;
/// M (INFO_REPLY, INFO_REPLY_IP4): multicast locators present.
const FLAG_M: u8 = 0x02;

/// Bytes of DATA's fixed fields (extraFlags to writerSN).
const DATA_FIXED: usize = 20;
/// Bytes of DATA_FRAG's fixed fields (extraFlags to sampleSize).
const DATA_FRAG_FIXED: usize = 32;

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

/// Reads a submessage body's fields in order, each checked to be there.
struct Reader<'a> {
    kind: u8,
    body: &'a [u8],
    at: usize,
    e: Endianness,
}

impl<'a> Reader<'a> {
    fn new(kind: u8, flags: u8, body: &'a [u8]) -> Self {
        let e = if flags & FLAG_E != 0 { Endianness::Little } else { Endianness::Big };
        Self { kind, body, at: 0, e }
    }

    fn too_short(&self, needed: usize) -> WireError {
        WireError::SubmessageTooShort { kind: self.kind, length: self.body.len(), needed }
    }

    fn bytes(&mut self, n: usize) -> Result<&'a [u8], WireError> {
        let end = self.at.saturating_add(n);
        let b = self.body.get(self.at..end).ok_or_else(|| self.too_short(end))?;
        self.at = end;
        Ok(b)
    }

    fn array<const N: usize>(&mut self) -> Result<[u8; N], WireError> {
        let b = self.bytes(N)?;
        <[u8; N]>::try_from(b).map_err(|_| self.too_short(self.at))
    }

    fn u16(&mut self) -> Result<u16, WireError> {
        let b = self.array()?;
        Ok(match self.e {
            Endianness::Little => u16::from_le_bytes(b),
            Endianness::Big => u16::from_be_bytes(b),
        })
    }

    fn u32(&mut self) -> Result<u32, WireError> {
        let b = self.array()?;
        Ok(match self.e {
            Endianness::Little => u32::from_le_bytes(b),
            Endianness::Big => u32::from_be_bytes(b),
        })
    }

    fn i32(&mut self) -> Result<i32, WireError> {
        self.u32().map(|v| v as i32)
    }

    fn entity(&mut self) -> Result<EntityId, WireError> {
        self.array().map(EntityId)
    }

    fn sn(&mut self) -> Result<SequenceNumber, WireError> {
        let high = self.i32()?;
        Ok(SequenceNumber::from_parts(high, self.u32()?))
    }

    /// A sequence number that names a sample (≥ 1).
    fn sample_sn(&mut self) -> Result<SequenceNumber, WireError> {
        let sn = self.sn()?;
        if !sn.is_valid() {
            return Err(WireError::SequenceNumber { kind: self.kind, sn: sn.0 });
        }
        Ok(sn)
    }

    fn words(&mut self, num_bits: u32) -> Result<[u32; 8], WireError> {
        let mut words = [0u32; 8];
        for w in words.iter_mut().take(num_bits.div_ceil(32) as usize) {
            *w = self.u32()?;
        }
        Ok(words)
    }

    fn sn_set(&mut self) -> Result<SequenceNumberSet, WireError> {
        let base = self.sn()?;
        let num_bits = self.u32()?;
        let refused = WireError::SequenceNumberSet { base: base.0, num_bits };
        if num_bits > 256 {
            return Err(refused);
        }
        let words = self.words(num_bits)?;
        SequenceNumberSet::from_words(base, num_bits, &words).map_err(|_| refused)
    }

    fn fragment_set(&mut self) -> Result<FragmentNumberSet, WireError> {
        let base = self.u32()?;
        let num_bits = self.u32()?;
        let refused = WireError::FragmentNumberSet { base, num_bits };
        if num_bits > 256 {
            return Err(refused);
        }
        let words = self.words(num_bits)?;
        FragmentNumberSet::from_words(base, num_bits, &words).map_err(|e| match e {
            SetError::Base => WireError::FragmentNumberZero { kind: self.kind },
            SetError::NumBits | SetError::Overflow => refused,
        })
    }

    fn locators(&mut self) -> Result<LocatorList<'a>, WireError> {
        let count = self.u32()?;
        let available = self.body.len().saturating_sub(self.at);
        let len = u64::from(count) * 24;
        if len > available as u64 {
            return Err(WireError::LocatorCount { count, available });
        }
        Ok(LocatorList { bytes: self.bytes(len as usize)?, endianness: self.e })
    }

    fn udpv4(&mut self) -> Result<Locator, WireError> {
        let address = self.u32()?;
        let port = self.u32()?;
        let mut a = [0; 16];
        if let Some(last) = a.get_mut(12..) {
            last.copy_from_slice(&address.to_be_bytes());
        }
        Ok(Locator { kind: Locator::KIND_UDPV4, port, address: a })
    }

    /// Moves to `4 + octets_to_inline_qos`, which must be past the `fixed` fields and in the body.
    fn seek_inline_qos(&mut self, octets: u16, fixed: usize) -> Result<(), WireError> {
        let at = 4 + usize::from(octets);
        if at < fixed || at > self.body.len() {
            return Err(WireError::InlineQosOffset { kind: self.kind, octets, length: self.body.len() });
        }
        self.at = at;
        Ok(())
    }

    fn inline_qos(&mut self, present: bool) -> Result<Option<ParameterList<'a>>, WireError> {
        if !present {
            return Ok(None);
        }
        let (list, used) = ParameterList::parse(self.rest(), self.e)?;
        self.at = self.at.saturating_add(used);
        Ok(Some(list))
    }

    fn rest(&self) -> &'a [u8] {
        self.body.get(self.at..).unwrap_or_default()
    }
}

/// Bytes of an inline QoS list as emitted (little-endian; a big-endian list is rewritten
/// without its PID_PADs and with a zero-length sentinel).
fn list_len(list: &ParameterList<'_>) -> usize {
    match list.endianness() {
        Endianness::Little => list.as_bytes().len(),
        Endianness::Big => list.iter().map(|p| 4 + p.value.len()).sum::<usize>() + 4,
    }
}

fn emit_list(w: &mut LeWriter<'_>, list: &ParameterList<'_>) -> Result<(), BufferTooSmall> {
    match list.endianness() {
        Endianness::Little => w.put_bytes(list.as_bytes()),
        Endianness::Big => {
            for p in list.iter() {
                w.put_u16(p.pid)?;
                w.put_u16(u16::try_from(p.value.len()).unwrap_or(u16::MAX))?;
                w.put_bytes(p.value)?;
            }
            w.put_u16(pid::SENTINEL)?;
            w.put_u16(0)
        }
    }
}

fn put_sn(w: &mut LeWriter<'_>, sn: SequenceNumber) -> Result<(), BufferTooSmall> {
    let (high, low) = sn.to_parts();
    w.put_bytes(&high.to_le_bytes())?;
    w.put_u32(low)
}

fn put_words(w: &mut LeWriter<'_>, words: &[u32]) -> Result<(), BufferTooSmall> {
    words.iter().try_for_each(|&v| w.put_u32(v))
}

fn flag(set: bool, bit: u8) -> u8 {
    if set { bit } else { 0 }
}

impl DataFrag<'_> {
    /// Payload bytes fragments `fragment_starting_num ..+ fragments_in_submessage` occupy
    /// (the sample's last fragment may be short); `None` when the range is not in the sample.
    pub fn fragment_bytes(&self) -> Option<u64> {
        let size = u64::from(self.fragment_size);
        let first = u64::from(self.fragment_starting_num).checked_sub(1)?;
        let end = first + u64::from(self.fragments_in_submessage);
        if self.fragment_size == 0 || self.fragments_in_submessage == 0 || end > u64::from(self.total_fragments()) {
            return None;
        }
        Some(u64::from(self.sample_size).min(end * size) - first * size)
    }
}

impl<'a> Submessage<'a> {
    /// Parses the body of a submessage of id `kind` with `flags` (bit 0: E, little-endian).
    pub fn parse(kind: u8, flags: u8, body: &'a [u8]) -> Result<Self, WireError> {
        let mut r = Reader::new(kind, flags, body);
        Ok(match SubmessageKind::from_id(kind) {
            SubmessageKind::Pad => Self::Pad,
            SubmessageKind::Data => {
                let _extra_flags = r.u16()?;
                let octets_to_inline_qos = r.u16()?;
                let reader_id = r.entity()?;
                let writer_id = r.entity()?;
                let writer_sn = r.sample_sn()?;
                if flags & DATA_FLAG_D != 0 && flags & DATA_FLAG_K != 0 {
                    return Err(WireError::DataFlags);
                }
                r.seek_inline_qos(octets_to_inline_qos, DATA_FIXED)?;
                let inline_qos = r.inline_qos(flags & FLAG_Q != 0)?;
                let payload = if flags & DATA_FLAG_D != 0 {
                    Payload::Data(r.rest())
                } else if flags & DATA_FLAG_K != 0 {
                    Payload::Key(r.rest())
                } else {
                    Payload::None
                };
                let non_standard_payload = flags & DATA_FLAG_N != 0;
                Self::Data(Data { reader_id, writer_id, writer_sn, inline_qos, payload, non_standard_payload })
            }
            SubmessageKind::DataFrag => {
                let _extra_flags = r.u16()?;
                let octets_to_inline_qos = r.u16()?;
                let reader_id = r.entity()?;
                let writer_id = r.entity()?;
                let writer_sn = r.sample_sn()?;
                let fragment_starting_num = r.u32()?;
                let fragments_in_submessage = r.u16()?;
                let fragment_size = r.u16()?;
                let sample_size = r.u32()?;
                if fragment_starting_num == 0 {
                    return Err(WireError::FragmentNumberZero { kind });
                }
                if fragment_size == 0 || sample_size == 0 {
                    return Err(WireError::FragmentSize { fragment_size, sample_size });
                }
                let mut frag = DataFrag {
                    reader_id,
                    writer_id,
                    writer_sn,
                    fragment_starting_num,
                    fragments_in_submessage,
                    fragment_size,
                    sample_size,
                    inline_qos: None,
                    key: flags & DATAFRAG_FLAG_K != 0,
                    non_standard_payload: flags & DATAFRAG_FLAG_N != 0,
                    payload: &[],
                };
                let needed = frag.fragment_bytes().ok_or(WireError::FragmentRange {
                    start: fragment_starting_num,
                    count: fragments_in_submessage,
                    total: frag.total_fragments(),
                })?;
                r.seek_inline_qos(octets_to_inline_qos, DATA_FRAG_FIXED)?;
                frag.inline_qos = r.inline_qos(flags & FLAG_Q != 0)?;
                let rest = r.rest();
                // Exactly the fragments' bytes, tolerating up to 3 bytes of alignment padding.
                let fits = (rest.len() as u64).checked_sub(needed).is_some_and(|pad| pad <= 3);
                frag.payload = match rest.get(..needed as usize) {
                    Some(payload) if fits => payload,
                    _ => return Err(WireError::FragmentPayload { needed, available: rest.len() }),
                };
                Self::DataFrag(frag)
            }
            SubmessageKind::Heartbeat => {
                let reader_id = r.entity()?;
                let writer_id = r.entity()?;
                let first_sn = r.sample_sn()?;
                let last_sn = r.sn()?;
                let count = r.i32()?;
                // first_sn ≥ 1, so first_sn - 1 cannot overflow.
                if last_sn.0 < first_sn.0 - 1 {
                    return Err(WireError::HeartbeatRange { first: first_sn.0, last: last_sn.0 });
                }
                Self::Heartbeat(Heartbeat {
                    reader_id,
                    writer_id,
                    first_sn,
                    last_sn,
                    count,
                    final_flag: flags & FLAG_F != 0,
                    liveliness_flag: flags & HEARTBEAT_FLAG_L != 0,
                })
            }
            SubmessageKind::HeartbeatFrag => {
                let reader_id = r.entity()?;
                let writer_id = r.entity()?;
                let writer_sn = r.sample_sn()?;
                let last_fragment_num = r.u32()?;
                let count = r.i32()?;
                if last_fragment_num == 0 {
                    return Err(WireError::FragmentNumberZero { kind });
                }
                Self::HeartbeatFrag(HeartbeatFrag { reader_id, writer_id, writer_sn, last_fragment_num, count })
            }
            SubmessageKind::AckNack => {
                let reader_id = r.entity()?;
                let writer_id = r.entity()?;
                let reader_sn_state = r.sn_set()?;
                let count = r.i32()?;
                Self::AckNack(AckNack { reader_id, writer_id, reader_sn_state, count, final_flag: flags & FLAG_F != 0 })
            }
            SubmessageKind::NackFrag => {
                let reader_id = r.entity()?;
                let writer_id = r.entity()?;
                let writer_sn = r.sample_sn()?;
                let fragment_number_state = r.fragment_set()?;
                let count = r.i32()?;
                Self::NackFrag(NackFrag { reader_id, writer_id, writer_sn, fragment_number_state, count })
            }
            SubmessageKind::Gap => {
                let reader_id = r.entity()?;
                let writer_id = r.entity()?;
                let gap_start = r.sample_sn()?;
                let gap_list = r.sn_set()?;
                if gap_list.base() < gap_start {
                    return Err(WireError::GapRange { start: gap_start.0, base: gap_list.base().0 });
                }
                // With the G flag, group info follows (RTPS 2.4+); not interpreted here.
                Self::Gap(Gap { reader_id, writer_id, gap_start, gap_list })
            }
            SubmessageKind::InfoTs => {
                let timestamp = if flags & INFO_TS_FLAG_I != 0 {
                    None
                } else {
                    let seconds = r.i32()?;
                    Some(Timestamp { seconds, fraction: r.u32()? })
                };
                Self::InfoTs(InfoTs { timestamp })
            }
            SubmessageKind::InfoDst => Self::InfoDst(InfoDst { guid_prefix: GuidPrefix(r.array()?) }),
            SubmessageKind::InfoSrc => {
                let _unused = r.u32()?;
                let [major, minor] = r.array()?;
                let vendor = VendorId(r.array()?);
                let guid_prefix = GuidPrefix(r.array()?);
                Self::InfoSrc(InfoSrc { version: ProtocolVersion { major, minor }, vendor, guid_prefix })
            }
            SubmessageKind::InfoReply => {
                let unicast = r.locators()?;
                let multicast = if flags & FLAG_M != 0 { Some(r.locators()?) } else { None };
                Self::InfoReply(InfoReply { unicast, multicast })
            }
            SubmessageKind::InfoReplyIp4 => {
                let unicast = r.udpv4()?;
                let multicast = if flags & FLAG_M != 0 { Some(r.udpv4()?) } else { None };
                Self::InfoReplyIp4(InfoReplyIp4 { unicast, multicast })
            }
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
                Self::Data(d) => {
                    flag(d.inline_qos.is_some(), FLAG_Q)
                        | flag(matches!(d.payload, Payload::Data(_)), DATA_FLAG_D)
                        | flag(matches!(d.payload, Payload::Key(_)), DATA_FLAG_K)
                        | flag(d.non_standard_payload, DATA_FLAG_N)
                }
                Self::DataFrag(d) => {
                    flag(d.inline_qos.is_some(), FLAG_Q)
                        | flag(d.key, DATAFRAG_FLAG_K)
                        | flag(d.non_standard_payload, DATAFRAG_FLAG_N)
                }
                Self::Heartbeat(h) => flag(h.final_flag, FLAG_F) | flag(h.liveliness_flag, HEARTBEAT_FLAG_L),
                Self::AckNack(a) => flag(a.final_flag, FLAG_F),
                Self::InfoTs(t) => flag(t.timestamp.is_none(), INFO_TS_FLAG_I),
                Self::InfoReply(r) => flag(r.multicast.is_some(), FLAG_M),
                Self::InfoReplyIp4(r) => flag(r.multicast.is_some(), FLAG_M),
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
        let payload_len = |p: &Payload<'_>| match p {
            Payload::None => 0,
            Payload::Data(b) | Payload::Key(b) => b.len(),
        };
        match self {
            Self::Data(d) => DATA_FIXED + d.inline_qos.as_ref().map_or(0, list_len) + payload_len(&d.payload),
            Self::DataFrag(d) => {
                DATA_FRAG_FIXED + d.inline_qos.as_ref().map_or(0, list_len) + d.payload.len().next_multiple_of(4)
            }
            Self::Heartbeat(_) => 28,
            Self::HeartbeatFrag(_) => 24,
            Self::AckNack(a) => 8 + 12 + 4 * a.reader_sn_state.words().len() + 4,
            Self::NackFrag(n) => 8 + 8 + 8 + 4 * n.fragment_number_state.words().len() + 4,
            Self::Gap(g) => 8 + 8 + 12 + 4 * g.gap_list.words().len(),
            Self::InfoTs(t) => {
                if t.timestamp.is_some() {
                    8
                } else {
                    0
                }
            }
            Self::InfoDst(_) => 12,
            Self::InfoSrc(_) => 20,
            Self::InfoReply(r) => r.unicast.buffer_len() + r.multicast.as_ref().map_or(0, LocatorList::buffer_len),
            Self::InfoReplyIp4(r) => {
                if r.multicast.is_some() {
                    16
                } else {
                    8
                }
            }
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
            Self::Data(d) => {
                w.put_u16(0)?;
                w.put_u16((DATA_FIXED - 4) as u16)?;
                w.put_bytes(&d.reader_id.0)?;
                w.put_bytes(&d.writer_id.0)?;
                put_sn(&mut w, d.writer_sn)?;
                if let Some(list) = &d.inline_qos {
                    emit_list(&mut w, list)?;
                }
                match d.payload {
                    Payload::None => {}
                    Payload::Data(b) | Payload::Key(b) => w.put_bytes(b)?,
                }
            }
            Self::DataFrag(d) => {
                w.put_u16(0)?;
                w.put_u16((DATA_FRAG_FIXED - 4) as u16)?;
                w.put_bytes(&d.reader_id.0)?;
                w.put_bytes(&d.writer_id.0)?;
                put_sn(&mut w, d.writer_sn)?;
                w.put_u32(d.fragment_starting_num)?;
                w.put_u16(d.fragments_in_submessage)?;
                w.put_u16(d.fragment_size)?;
                w.put_u32(d.sample_size)?;
                if let Some(list) = &d.inline_qos {
                    emit_list(&mut w, list)?;
                }
                w.put_bytes(d.payload)?;
                w.put_bytes(&[0; 3][..d.payload.len().next_multiple_of(4) - d.payload.len()])?;
            }
            Self::Heartbeat(h) => {
                w.put_bytes(&h.reader_id.0)?;
                w.put_bytes(&h.writer_id.0)?;
                put_sn(&mut w, h.first_sn)?;
                put_sn(&mut w, h.last_sn)?;
                w.put_bytes(&h.count.to_le_bytes())?;
            }
            Self::HeartbeatFrag(h) => {
                w.put_bytes(&h.reader_id.0)?;
                w.put_bytes(&h.writer_id.0)?;
                put_sn(&mut w, h.writer_sn)?;
                w.put_u32(h.last_fragment_num)?;
                w.put_bytes(&h.count.to_le_bytes())?;
            }
            Self::AckNack(a) => {
                w.put_bytes(&a.reader_id.0)?;
                w.put_bytes(&a.writer_id.0)?;
                put_sn(&mut w, a.reader_sn_state.base())?;
                w.put_u32(a.reader_sn_state.num_bits())?;
                put_words(&mut w, a.reader_sn_state.words())?;
                w.put_bytes(&a.count.to_le_bytes())?;
            }
            Self::NackFrag(n) => {
                w.put_bytes(&n.reader_id.0)?;
                w.put_bytes(&n.writer_id.0)?;
                put_sn(&mut w, n.writer_sn)?;
                w.put_u32(n.fragment_number_state.base())?;
                w.put_u32(n.fragment_number_state.num_bits())?;
                put_words(&mut w, n.fragment_number_state.words())?;
                w.put_bytes(&n.count.to_le_bytes())?;
            }
            Self::Gap(g) => {
                w.put_bytes(&g.reader_id.0)?;
                w.put_bytes(&g.writer_id.0)?;
                put_sn(&mut w, g.gap_start)?;
                put_sn(&mut w, g.gap_list.base())?;
                w.put_u32(g.gap_list.num_bits())?;
                put_words(&mut w, g.gap_list.words())?;
            }
            Self::InfoTs(t) => {
                if let Some(ts) = t.timestamp {
                    w.put_bytes(&ts.seconds.to_le_bytes())?;
                    w.put_u32(ts.fraction)?;
                }
            }
            Self::InfoDst(d) => w.put_bytes(&d.guid_prefix.0)?,
            Self::InfoSrc(s) => {
                w.put_u32(0)?;
                w.put_bytes(&[s.version.major, s.version.minor])?;
                w.put_bytes(&s.vendor.0)?;
                w.put_bytes(&s.guid_prefix.0)?;
            }
            Self::InfoReply(r) => {
                r.unicast.emit(&mut w)?;
                if let Some(m) = &r.multicast {
                    m.emit(&mut w)?;
                }
            }
            Self::InfoReplyIp4(r) => {
                for l in core::iter::once(&r.unicast).chain(&r.multicast) {
                    let address = robowire_core::le::array_at::<4>(&l.address, 12).unwrap_or_default();
                    w.put_u32(u32::from_be_bytes(address))?;
                    w.put_u32(l.port)?;
                }
            }
            Self::Pad => {}
            Self::Unknown { body, .. } => w.put_bytes(body)?,
        }
        Ok(w.written())
    }
}
