//! The data family: DATA (one sample, a key or a state change, with its [`Payload`]) and
//! DATA_FRAG (fragments of one sample), with their flags, their fixed fields' sizes, how their
//! bodies are parsed and emitted, and the rewriting of an inline QoS list to little-endian.

use super::body::{Reader, flag, put_sn};
use crate::types::{EntityId, SequenceNumber};
use crate::wire::{Endianness, ParameterList, WireError, pid};
use robowire_core::BufferTooSmall;
use robowire_core::le::LeWriter;

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

/// Bytes of DATA's fixed fields (extraFlags to writerSN).
const DATA_FIXED: usize = 20;
/// Bytes of DATA_FRAG's fixed fields (extraFlags to sampleSize).
const DATA_FRAG_FIXED: usize = 32;

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

impl<'a> Data<'a> {
    /// Parses a DATA body (flags: the submessage's).
    pub(super) fn parse(r: &mut Reader<'a>, flags: u8) -> Result<Self, WireError> {
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
        Ok(Data { reader_id, writer_id, writer_sn, inline_qos, payload, non_standard_payload })
    }

    /// The flags emitted, E aside.
    pub(super) fn flags(&self) -> u8 {
        flag(self.inline_qos.is_some(), FLAG_Q)
            | flag(matches!(self.payload, Payload::Data(_)), DATA_FLAG_D)
            | flag(matches!(self.payload, Payload::Key(_)), DATA_FLAG_K)
            | flag(self.non_standard_payload, DATA_FLAG_N)
    }

    /// Bytes of the body emitted.
    pub(super) fn body_len(&self) -> usize {
        let payload_len = match self.payload {
            Payload::None => 0,
            Payload::Data(b) | Payload::Key(b) => b.len(),
        };
        DATA_FIXED + self.inline_qos.as_ref().map_or(0, list_len) + payload_len
    }

    /// Writes the body.
    pub(super) fn emit_body(&self, w: &mut LeWriter<'_>) -> Result<(), BufferTooSmall> {
        w.put_u16(0)?;
        w.put_u16((DATA_FIXED - 4) as u16)?;
        w.put_bytes(&self.reader_id.0)?;
        w.put_bytes(&self.writer_id.0)?;
        put_sn(w, self.writer_sn)?;
        if let Some(list) = &self.inline_qos {
            emit_list(w, list)?;
        }
        match self.payload {
            Payload::None => {}
            Payload::Data(b) | Payload::Key(b) => w.put_bytes(b)?,
        }
        Ok(())
    }
}

impl<'a> DataFrag<'a> {
    /// Parses a DATA_FRAG body (flags: the submessage's).
    pub(super) fn parse(r: &mut Reader<'a>, flags: u8) -> Result<Self, WireError> {
        let kind = r.kind;
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
        Ok(frag)
    }

    /// The flags emitted, E aside.
    pub(super) fn flags(&self) -> u8 {
        flag(self.inline_qos.is_some(), FLAG_Q)
            | flag(self.key, DATAFRAG_FLAG_K)
            | flag(self.non_standard_payload, DATAFRAG_FLAG_N)
    }

    /// Bytes of the body emitted (the payload padded to a multiple of 4).
    pub(super) fn body_len(&self) -> usize {
        DATA_FRAG_FIXED + self.inline_qos.as_ref().map_or(0, list_len) + self.payload.len().next_multiple_of(4)
    }

    /// Writes the body, the payload padded with zeros to a multiple of 4.
    pub(super) fn emit_body(&self, w: &mut LeWriter<'_>) -> Result<(), BufferTooSmall> {
        w.put_u16(0)?;
        w.put_u16((DATA_FRAG_FIXED - 4) as u16)?;
        w.put_bytes(&self.reader_id.0)?;
        w.put_bytes(&self.writer_id.0)?;
        put_sn(w, self.writer_sn)?;
        w.put_u32(self.fragment_starting_num)?;
        w.put_u16(self.fragments_in_submessage)?;
        w.put_u16(self.fragment_size)?;
        w.put_u32(self.sample_size)?;
        if let Some(list) = &self.inline_qos {
            emit_list(w, list)?;
        }
        w.put_bytes(self.payload)?;
        w.put_bytes(&[0; 3][..self.payload.len().next_multiple_of(4) - self.payload.len()])?;
        Ok(())
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
