//! The datagrams a templated [`Step`] stands for: the peer's RTPS header, the INFO_DST and
//! INFO_TS its wrap byte asks for, then the one submessage with the endpoints its selector bytes
//! choose (`Ids`), in the byte order the wrap byte gives.

use alloc::vec::Vec;

use super::step::Step;
use super::world::{LOCAL_PREFIX, MAX_PAYLOAD, PEER_PREFIX};
use crate::EntityId;
use crate::wire::pid;

/// The endpoints a selector chooses among.
pub(super) struct Ids {
    pub(super) writer: EntityId,
    pub(super) reader: EntityId,
    pub(super) peer_writer: EntityId,
    pub(super) peer_reader: EntityId,
}

impl Ids {
    /// A reader for a writer's submessage (ours first).
    fn local_reader(&self, sel: u8) -> EntityId {
        [
            self.reader,
            EntityId::UNKNOWN,
            EntityId::SEDP_PUBLICATIONS_READER,
            EntityId::SEDP_SUBSCRIPTIONS_READER,
            EntityId::SPDP_READER,
            EntityId::P2P_MESSAGE_READER,
            self.writer,
            EntityId([0, 0, sel, 0x04]),
        ][usize::from(sel % 8)]
    }
    /// A writer sending a writer's submessage (the peer's first).
    fn remote_writer(&self, sel: u8) -> EntityId {
        [
            self.peer_writer,
            EntityId::SEDP_PUBLICATIONS_WRITER,
            EntityId::SEDP_SUBSCRIPTIONS_WRITER,
            EntityId::SPDP_WRITER,
            EntityId::P2P_MESSAGE_WRITER,
            EntityId::UNKNOWN,
            self.peer_reader,
            EntityId([0, 0, sel, 0x03]),
        ][usize::from(sel % 8)]
    }
    /// A writer of ours an ACKNACK or NACK_FRAG names.
    fn local_writer(&self, sel: u8) -> EntityId {
        [
            self.writer,
            EntityId::SEDP_PUBLICATIONS_WRITER,
            EntityId::SEDP_SUBSCRIPTIONS_WRITER,
            EntityId::SPDP_WRITER,
            EntityId::P2P_MESSAGE_WRITER,
            EntityId::UNKNOWN,
            self.reader,
            EntityId([0, 0, sel, 0x03]),
        ][usize::from(sel % 8)]
    }
    /// The remote reader sending an ACKNACK or NACK_FRAG.
    fn remote_reader(&self, sel: u8) -> EntityId {
        [
            self.peer_reader,
            EntityId::SEDP_PUBLICATIONS_READER,
            EntityId::SEDP_SUBSCRIPTIONS_READER,
            EntityId::SPDP_READER,
            EntityId::P2P_MESSAGE_READER,
            EntityId::UNKNOWN,
            self.peer_writer,
            EntityId([0, 0, sel, 0x04]),
        ][usize::from(sel % 8)]
    }
}

pub(super) fn fill(buf: &mut Vec<u8>, len: usize, byte: u8) {
    buf.clear();
    buf.extend_from_slice(&[0, 1, 0, 0]);
    buf.resize(4 + len, byte);
}

pub(super) fn header(d: &mut Vec<u8>) {
    d.extend_from_slice(b"RTPS\x02\x04\x01\x12");
    d.extend_from_slice(&PEER_PREFIX.0);
}

/// Little- or big-endian field writing for one submessage body.
struct Body<'v> {
    v: &'v mut Vec<u8>,
    little: bool,
}

impl Body<'_> {
    fn u16(&mut self, x: u16) {
        self.v.extend_from_slice(&if self.little { x.to_le_bytes() } else { x.to_be_bytes() });
    }
    fn u32(&mut self, x: u32) {
        self.v.extend_from_slice(&if self.little { x.to_le_bytes() } else { x.to_be_bytes() });
    }
    fn sn(&mut self, sn: i64) {
        self.u32((sn >> 32) as u32);
        self.u32(sn as u32);
    }
    fn ids(&mut self, reader: EntityId, writer: EntityId) {
        self.v.extend_from_slice(&reader.0);
        self.v.extend_from_slice(&writer.0);
    }
    fn set(&mut self, bits: u32, words: &[u32; 8]) {
        self.u32(bits);
        let n = (u64::from(bits).div_ceil(32)).min(8) as usize;
        words[..n].iter().for_each(|w| self.u32(*w));
    }
}

/// Appends a submessage: kind, flags (E added when little-endian), length, body.
fn submessage(d: &mut Vec<u8>, kind: u8, flags: u8, little: bool, body: impl FnOnce(&mut Body<'_>)) {
    d.extend_from_slice(&[kind, flags | u8::from(little), 0, 0]);
    let start = d.len();
    body(&mut Body { v: d, little });
    let len = u16::try_from(d.len() - start).unwrap_or(0);
    let len = if little { len.to_le_bytes() } else { len.to_be_bytes() };
    d[start - 2..start].copy_from_slice(&len);
}

/// Builds a templated step's datagram into `d`; returns its wrap byte.
pub(super) fn templated_datagram(d: &mut Vec<u8>, step: &Step<'_>, ids: &Ids, payload: &mut Vec<u8>) -> u8 {
    let wrap = match *step {
        Step::Data { wrap, .. }
        | Step::DataFrag { wrap, .. }
        | Step::Heartbeat { wrap, .. }
        | Step::HeartbeatFrag { wrap, .. }
        | Step::AckNack { wrap, .. }
        | Step::Gap { wrap, .. }
        | Step::NackFrag { wrap, .. } => wrap,
        _ => 0,
    };
    let little = wrap & 8 == 0;
    header(d);
    if wrap & 1 != 0 {
        submessage(d, 0x0e, 0, little, |b| b.v.extend_from_slice(&LOCAL_PREFIX.0));
    }
    if wrap & 2 != 0 {
        submessage(d, 0x0e, 0, little, |b| b.v.extend_from_slice(&[0x42; 12]));
    }
    if wrap & 4 != 0 {
        submessage(d, 0x09, 0, little, |b| {
            b.u32(1_700_000_000);
            b.u32(0x8000_0000);
        });
    }
    match *step {
        Step::Data { to, from, sn, len, flags, .. } => {
            let (qos, key, none) = (flags & 1 != 0, flags & 2 != 0, flags & 4 != 0);
            let payload_flag = match (none, key) {
                (true, _) => 0,
                (false, true) => 8,
                (false, false) => 4,
            };
            let f = u8::from(qos) << 1 | payload_flag;
            fill(payload, usize::from(len) % (MAX_PAYLOAD + 1), 0xa5);
            submessage(d, 0x15, f, little, |b| {
                b.u16(0);
                b.u16(16);
                b.ids(ids.local_reader(to), ids.remote_writer(from));
                b.sn(sn);
                if qos {
                    b.u16(pid::STATUS_INFO);
                    b.u16(4);
                    b.v.extend_from_slice(&[0, 0, 0, flags >> 4]);
                    b.u16(pid::SENTINEL);
                    b.u16(0);
                }
                if !none {
                    b.v.extend_from_slice(payload);
                }
            });
        }
        Step::DataFrag { to, from, sn, start, count, size, sample, len, .. } => {
            let n = if len == 0 {
                let offset = u64::from(start.saturating_sub(1)) * u64::from(size);
                let want = u64::from(count) * u64::from(size);
                want.min(u64::from(sample).saturating_sub(offset))
            } else {
                u64::from(len - 1)
            };
            payload.clear();
            payload.resize(n.min(MAX_PAYLOAD as u64) as usize, 0x3c);
            submessage(d, 0x16, 0, little, |b| {
                b.u16(0);
                b.u16(28);
                b.ids(ids.local_reader(to), ids.remote_writer(from));
                b.sn(sn);
                b.u32(start);
                b.u16(count);
                b.u16(size);
                b.u32(sample);
                b.v.extend_from_slice(payload);
            });
        }
        Step::Heartbeat { to, from, first, last, count, flags, .. } => {
            submessage(d, 0x07, (flags & 3) << 1, little, |b| {
                b.ids(ids.local_reader(to), ids.remote_writer(from));
                b.sn(first);
                b.sn(last);
                b.u32(count as u32);
            });
        }
        Step::HeartbeatFrag { to, from, sn, last, count, .. } => {
            submessage(d, 0x13, 0, little, |b| {
                b.ids(ids.local_reader(to), ids.remote_writer(from));
                b.sn(sn);
                b.u32(last);
                b.u32(count as u32);
            });
        }
        Step::AckNack { from, to, base, bits, ref words, count, final_flag, .. } => {
            submessage(d, 0x06, u8::from(final_flag) << 1, little, |b| {
                b.ids(ids.remote_reader(from), ids.local_writer(to));
                b.sn(base);
                b.set(bits, words);
                b.u32(count as u32);
            });
        }
        Step::Gap { to, from, start, base, bits, ref words, .. } => {
            submessage(d, 0x08, 0, little, |b| {
                b.ids(ids.local_reader(to), ids.remote_writer(from));
                b.sn(start);
                b.sn(base);
                b.set(bits, words);
            });
        }
        Step::NackFrag { from, to, sn, base, bits, ref words, count, .. } => {
            submessage(d, 0x12, 0, little, |b| {
                b.ids(ids.remote_reader(from), ids.local_writer(to));
                b.sn(sn);
                b.u32(base);
                b.set(bits, words);
                b.u32(count as u32);
            });
        }
        _ => {}
    }
    wrap
}
