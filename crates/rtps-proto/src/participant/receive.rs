//! A received datagram, submessage by submessage: the receiver's state (source, destination,
//! timestamp), SPDP to the builtin handler, everything else to the local endpoint it names.

use alloc::vec::Vec;
use core::net::SocketAddr;

use super::event::push_event;
use super::{Counters, Event, Participant, Sample};
use crate::Time;
use crate::endpoint::{SampleIdentity, SampleInfo};
use crate::types::{EntityId, Guid, GuidPrefix, SequenceNumber, Timestamp};
use crate::wire::{Endianness, Message, ParameterList, Payload, Submessage, pid};

/// Whether a datagram came to a unicast or a multicast address.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Destination {
    /// Sent to this participant's own address.
    Unicast,
    /// Sent to a multicast group it joined.
    Multicast,
}

/// What the inline QoS of a DATA says.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct InlineQos {
    pub(crate) key_hash: Option<[u8; 16]>,
    pub(crate) status_info: u32,
    pub(crate) related: Option<SampleIdentity>,
}

impl InlineQos {
    pub(crate) fn parse(list: Option<&ParameterList<'_>>) -> Self {
        let mut q = Self::default();
        let Some(list) = list else { return q };
        for p in list.iter() {
            match p.pid {
                pid::KEY_HASH => q.key_hash = p.value.get(..16).and_then(|b| b.try_into().ok()),
                // The flags are in the last of four bytes, whatever the list's endianness.
                pid::STATUS_INFO => q.status_info = p.value.get(..4).map_or(0, |b| u32::from(b[3])),
                pid::RELATED_SAMPLE_IDENTITY | pid::RELATED_SAMPLE_IDENTITY_LEGACY => {
                    q.related = related_identity(p.value, list.endianness())
                }
                _ => {}
            }
        }
        q
    }
}

fn related_identity(v: &[u8], e: Endianness) -> Option<SampleIdentity> {
    let guid: [u8; 16] = v.get(..16)?.try_into().ok()?;
    let word = |b: &[u8]| -> Option<u32> {
        let b: [u8; 4] = b.try_into().ok()?;
        Some(match e {
            Endianness::Little => u32::from_le_bytes(b),
            Endianness::Big => u32::from_be_bytes(b),
        })
    };
    let high = word(v.get(16..20)?)? as i32;
    let low = word(v.get(20..24)?)?;
    Some(SampleIdentity { writer: Guid::from_bytes(guid), sequence: SequenceNumber::from_parts(high, low) })
}

impl Participant {
    /// Takes a datagram received from `source` at a unicast or multicast address. Refusals are
    /// counted ([`counters`](Self::counters)); what follows shows in events and transmits.
    pub fn handle_datagram(&mut self, now: Time, source: SocketAddr, destination: Destination, datagram: &[u8]) {
        self.counters.datagrams += 1;
        let message = match Message::parse(datagram) {
            Ok(m) => m,
            Err(e) => return self.counters.wire.count(e),
        };
        let header = message.header();
        if header.guid_prefix == self.config.guid_prefix {
            return; // our own announcement looped back
        }
        let mut source_prefix = header.guid_prefix;
        let mut for_us = true;
        let mut timestamp: Option<Timestamp> = None;
        let _ = destination;
        self.heard_from(now, source_prefix, source);
        for sub in message.submessages() {
            let sub = match sub {
                Ok(s) => s,
                Err(e) => {
                    self.counters.wire.count(e);
                    break;
                }
            };
            match sub {
                Submessage::InfoDst(d) => {
                    for_us = d.guid_prefix == GuidPrefix::UNKNOWN || d.guid_prefix == self.config.guid_prefix
                }
                Submessage::InfoSrc(s) => {
                    source_prefix = s.guid_prefix;
                    self.heard_from(now, source_prefix, source);
                }
                Submessage::InfoTs(t) => timestamp = t.timestamp,
                _ if !for_us => self.counters.not_for_us += 1,
                Submessage::Data(d) if d.writer_id == EntityId::SPDP_WRITER => {
                    let q = InlineQos::parse(d.inline_qos.as_ref());
                    self.handle_spdp(now, source_prefix, &d, q);
                }
                Submessage::Data(d) => {
                    let q = InlineQos::parse(d.inline_qos.as_ref());
                    let payload = match d.payload {
                        Payload::Data(b) | Payload::Key(b) => b,
                        Payload::None => &[],
                    };
                    let info = info(Guid::new(source_prefix, d.writer_id), d.writer_sn, timestamp, q);
                    self.route(now, d.reader_id, info, |r, w, info, deliver| r.handle_data(w, info, payload, deliver));
                }
                Submessage::DataFrag(f) => {
                    let q = InlineQos::parse(f.inline_qos.as_ref());
                    let info = info(Guid::new(source_prefix, f.writer_id), f.writer_sn, timestamp, q);
                    let used: usize = self.readers.iter().map(|r| r.reassembly_bytes()).sum();
                    let mut budget = self.config.limits.reassembly_bytes_total.saturating_sub(used);
                    self.route(now, f.reader_id, info, |r, w, info, deliver| {
                        r.handle_data_frag(now, w, info, &f, &mut budget, deliver)
                    });
                }
                Submessage::Heartbeat(hb) => {
                    let writer = Guid::new(source_prefix, hb.writer_id);
                    self.route_control(hb.reader_id, writer, |r, w, deliver| r.handle_heartbeat(now, w, &hb, deliver));
                }
                Submessage::HeartbeatFrag(hb) => {
                    let writer = Guid::new(source_prefix, hb.writer_id);
                    self.route_control(hb.reader_id, writer, |r, w, _| r.handle_heartbeat_frag(now, w, &hb));
                }
                Submessage::Gap(gap) => {
                    let writer = Guid::new(source_prefix, gap.writer_id);
                    self.route_control(gap.reader_id, writer, |r, w, deliver| r.handle_gap(w, &gap, deliver));
                }
                Submessage::AckNack(a) => {
                    let reader = Guid::new(source_prefix, a.reader_id);
                    let taken = self
                        .writers
                        .iter_mut()
                        .find(|w| w.id == a.writer_id)
                        .map(|w| w.handle_acknack(now, reader, &a));
                    if taken != Some(true) {
                        self.counters.unmatched_source += 1;
                    }
                }
                Submessage::NackFrag(n) => {
                    let reader = Guid::new(source_prefix, n.reader_id);
                    let taken = self
                        .writers
                        .iter_mut()
                        .find(|w| w.id == n.writer_id)
                        .map(|w| w.handle_nack_frag(now, reader, &n));
                    if taken != Some(true) {
                        self.counters.unmatched_source += 1;
                    }
                }
                Submessage::InfoReply(_)
                | Submessage::InfoReplyIp4(_)
                | Submessage::Pad
                | Submessage::Unknown { .. } => {}
            }
        }
        self.process_discovery_inbox(now);
    }

    /// Hands a DATA or DATA_FRAG to every local reader matched with its writer.
    fn route(
        &mut self,
        now: Time,
        reader_id: EntityId,
        info: SampleInfo,
        mut handle: impl FnMut(
            &mut crate::endpoint::Reader,
            usize,
            SampleInfo,
            &mut dyn FnMut(&SampleInfo, &[u8]),
        ) -> crate::endpoint::Delivery,
    ) {
        let _ = now;
        let Self { readers, events, counters, spare, config, discovery_inbox, .. } = self;
        let limit = config.limits.events;
        let mut matched = false;
        for r in readers.iter_mut() {
            if reader_id != EntityId::UNKNOWN && reader_id != r.id {
                continue;
            }
            let Some(w) = r.writer_index(info.writer) else { continue };
            matched = true;
            let info = SampleInfo { reader: r.id, ..info };
            if r.id.is_builtin() {
                let mut deliver = |i: &SampleInfo, b: &[u8]| discovery_inbox.push((*i, b.to_vec()));
                handle(r, w, info, &mut deliver);
            } else {
                let mut deliver = |i: &SampleInfo, b: &[u8]| deliver_sample(events, counters, spare, limit, i, b);
                handle(r, w, info, &mut deliver);
            }
        }
        if !matched {
            counters.unmatched_source += 1;
        }
    }

    /// Hands a HEARTBEAT, HEARTBEAT_FRAG or GAP to every local reader matched with its writer.
    fn route_control(
        &mut self,
        reader_id: EntityId,
        writer: Guid,
        mut handle: impl FnMut(&mut crate::endpoint::Reader, usize, &mut dyn FnMut(&SampleInfo, &[u8])),
    ) {
        let Self { readers, events, counters, spare, config, discovery_inbox, .. } = self;
        let limit = config.limits.events;
        let mut matched = false;
        for r in readers.iter_mut() {
            if reader_id != EntityId::UNKNOWN && reader_id != r.id {
                continue;
            }
            let Some(w) = r.writer_index(writer) else { continue };
            matched = true;
            if r.id.is_builtin() {
                let mut deliver = |i: &SampleInfo, b: &[u8]| discovery_inbox.push((*i, b.to_vec()));
                handle(r, w, &mut deliver);
            } else {
                let mut deliver = |i: &SampleInfo, b: &[u8]| deliver_sample(events, counters, spare, limit, i, b);
                handle(r, w, &mut deliver);
            }
        }
        if !matched {
            counters.unmatched_source += 1;
        }
    }
}

fn info(writer: Guid, sequence: SequenceNumber, source_timestamp: Option<Timestamp>, q: InlineQos) -> SampleInfo {
    SampleInfo {
        reader: EntityId::UNKNOWN,
        writer,
        sequence,
        source_timestamp,
        related: q.related,
        key_hash: q.key_hash,
        status_info: q.status_info,
    }
}

/// Queues a user sample in a reused buffer.
fn deliver_sample(
    events: &mut alloc::collections::VecDeque<Event>,
    counters: &mut Counters,
    spare: &mut Vec<Vec<u8>>,
    limit: usize,
    info: &SampleInfo,
    bytes: &[u8],
) {
    if events.len() >= limit {
        counters.events_at_limit += 1;
        return;
    }
    let mut payload = spare.pop().unwrap_or_default();
    payload.extend_from_slice(bytes);
    push_event(events, counters, limit, Event::Sample(Sample { info: *info, payload }));
}
