//! The acknowledgement family, what writers and readers say about which numbers exist and which
//! arrived: HEARTBEAT and HEARTBEAT_FRAG (a writer's available samples and fragments), ACKNACK
//! and NACK_FRAG (what a reader has and misses), GAP (numbers that will never come); with their
//! flags and how their bodies are parsed and emitted.

use super::body::{Reader, flag, put_sn, put_words};
use crate::types::{EntityId, FragmentNumberSet, SequenceNumber, SequenceNumberSet};
use crate::wire::WireError;
use robowire_core::BufferTooSmall;
use robowire_core::le::LeWriter;

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

/// F (HEARTBEAT, ACKNACK): final.
const FLAG_F: u8 = 0x02;
/// L (HEARTBEAT): liveliness.
const HEARTBEAT_FLAG_L: u8 = 0x04;

impl Heartbeat {
    /// Parses a HEARTBEAT body (flags: the submessage's).
    pub(super) fn parse(r: &mut Reader<'_>, flags: u8) -> Result<Self, WireError> {
        let reader_id = r.entity()?;
        let writer_id = r.entity()?;
        let first_sn = r.sample_sn()?;
        let last_sn = r.sn()?;
        let count = r.i32()?;
        // first_sn ≥ 1, so first_sn - 1 cannot overflow.
        if last_sn.0 < first_sn.0 - 1 {
            return Err(WireError::HeartbeatRange { first: first_sn.0, last: last_sn.0 });
        }
        Ok(Heartbeat {
            reader_id,
            writer_id,
            first_sn,
            last_sn,
            count,
            final_flag: flags & FLAG_F != 0,
            liveliness_flag: flags & HEARTBEAT_FLAG_L != 0,
        })
    }

    /// The flags emitted, E aside.
    pub(super) fn flags(&self) -> u8 {
        flag(self.final_flag, FLAG_F) | flag(self.liveliness_flag, HEARTBEAT_FLAG_L)
    }

    /// Writes the body (28 bytes).
    pub(super) fn emit_body(&self, w: &mut LeWriter<'_>) -> Result<(), BufferTooSmall> {
        w.put_bytes(&self.reader_id.0)?;
        w.put_bytes(&self.writer_id.0)?;
        put_sn(w, self.first_sn)?;
        put_sn(w, self.last_sn)?;
        w.put_bytes(&self.count.to_le_bytes())
    }
}

impl HeartbeatFrag {
    /// Parses a HEARTBEAT_FRAG body.
    pub(super) fn parse(r: &mut Reader<'_>) -> Result<Self, WireError> {
        let reader_id = r.entity()?;
        let writer_id = r.entity()?;
        let writer_sn = r.sample_sn()?;
        let last_fragment_num = r.u32()?;
        let count = r.i32()?;
        if last_fragment_num == 0 {
            return Err(WireError::FragmentNumberZero { kind: r.kind });
        }
        Ok(HeartbeatFrag { reader_id, writer_id, writer_sn, last_fragment_num, count })
    }

    /// Writes the body (24 bytes).
    pub(super) fn emit_body(&self, w: &mut LeWriter<'_>) -> Result<(), BufferTooSmall> {
        w.put_bytes(&self.reader_id.0)?;
        w.put_bytes(&self.writer_id.0)?;
        put_sn(w, self.writer_sn)?;
        w.put_u32(self.last_fragment_num)?;
        w.put_bytes(&self.count.to_le_bytes())
    }
}

impl AckNack {
    /// Parses an ACKNACK body (flags: the submessage's).
    pub(super) fn parse(r: &mut Reader<'_>, flags: u8) -> Result<Self, WireError> {
        let reader_id = r.entity()?;
        let writer_id = r.entity()?;
        let reader_sn_state = r.sn_set()?;
        let count = r.i32()?;
        Ok(AckNack { reader_id, writer_id, reader_sn_state, count, final_flag: flags & FLAG_F != 0 })
    }

    /// The flags emitted, E aside.
    pub(super) fn flags(&self) -> u8 {
        flag(self.final_flag, FLAG_F)
    }

    /// Bytes of the body emitted.
    pub(super) fn body_len(&self) -> usize {
        8 + 12 + 4 * self.reader_sn_state.words().len() + 4
    }

    /// Writes the body.
    pub(super) fn emit_body(&self, w: &mut LeWriter<'_>) -> Result<(), BufferTooSmall> {
        w.put_bytes(&self.reader_id.0)?;
        w.put_bytes(&self.writer_id.0)?;
        put_sn(w, self.reader_sn_state.base())?;
        w.put_u32(self.reader_sn_state.num_bits())?;
        put_words(w, self.reader_sn_state.words())?;
        w.put_bytes(&self.count.to_le_bytes())
    }
}

impl NackFrag {
    /// Parses a NACK_FRAG body.
    pub(super) fn parse(r: &mut Reader<'_>) -> Result<Self, WireError> {
        let reader_id = r.entity()?;
        let writer_id = r.entity()?;
        let writer_sn = r.sample_sn()?;
        let fragment_number_state = r.fragment_set()?;
        let count = r.i32()?;
        Ok(NackFrag { reader_id, writer_id, writer_sn, fragment_number_state, count })
    }

    /// Bytes of the body emitted.
    pub(super) fn body_len(&self) -> usize {
        8 + 8 + 8 + 4 * self.fragment_number_state.words().len() + 4
    }

    /// Writes the body.
    pub(super) fn emit_body(&self, w: &mut LeWriter<'_>) -> Result<(), BufferTooSmall> {
        w.put_bytes(&self.reader_id.0)?;
        w.put_bytes(&self.writer_id.0)?;
        put_sn(w, self.writer_sn)?;
        w.put_u32(self.fragment_number_state.base())?;
        w.put_u32(self.fragment_number_state.num_bits())?;
        put_words(w, self.fragment_number_state.words())?;
        w.put_bytes(&self.count.to_le_bytes())
    }
}

impl Gap {
    /// Parses a GAP body.
    pub(super) fn parse(r: &mut Reader<'_>) -> Result<Self, WireError> {
        let reader_id = r.entity()?;
        let writer_id = r.entity()?;
        let gap_start = r.sample_sn()?;
        let gap_list = r.sn_set()?;
        if gap_list.base() < gap_start {
            return Err(WireError::GapRange { start: gap_start.0, base: gap_list.base().0 });
        }
        // With the G flag, group info follows (RTPS 2.4+); not interpreted here.
        Ok(Gap { reader_id, writer_id, gap_start, gap_list })
    }

    /// Bytes of the body emitted.
    pub(super) fn body_len(&self) -> usize {
        8 + 8 + 12 + 4 * self.gap_list.words().len()
    }

    /// Writes the body.
    pub(super) fn emit_body(&self, w: &mut LeWriter<'_>) -> Result<(), BufferTooSmall> {
        w.put_bytes(&self.reader_id.0)?;
        w.put_bytes(&self.writer_id.0)?;
        put_sn(w, self.gap_start)?;
        put_sn(w, self.gap_list.base())?;
        w.put_u32(self.gap_list.num_bits())?;
        put_words(w, self.gap_list.words())
    }
}
