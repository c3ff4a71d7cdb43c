//! What a participant sends: SPDP announcements, a write's DATA, pushes to late joiners,
//! answers to ACKNACKs and NACK_FRAGs, heartbeats and acknowledgements. Each `poll_transmit`
//! builds one datagram into the caller's buffer.

use super::Participant;
use crate::Time;
use crate::endpoint::{Change, ChangeKind, WriteError};
use crate::types::{EntityId, GuidPrefix, Locator, ProtocolVersion, SequenceNumber, SequenceNumberSet, VendorId};
use crate::wire::{
    AckNack, Data, DataFrag, Endianness, Gap, Header, Heartbeat, InfoDst, InfoTs, MessageWriter, NackFrag,
    ParameterList, ParameterWriter, Payload, Submessage, pid,
};
use robowire_core::BufferTooSmall;

/// Most destinations of one datagram; a writer with readers at more locators sends the same
/// sample in more datagrams.
pub const MAX_DESTINATIONS: usize = 8;

/// A datagram built in the caller's buffer and where to send it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Transmit {
    /// The datagram's length (the first `len` bytes of the buffer).
    pub len: usize,
    destinations: [Locator; MAX_DESTINATIONS],
    count: usize,
}

impl Transmit {
    fn new(len: usize) -> Self {
        Self { len, destinations: [Locator::INVALID; MAX_DESTINATIONS], count: 0 }
    }

    /// Adds a destination (once); false when full.
    fn add(&mut self, l: Locator) -> bool {
        if self.destinations[..self.count].contains(&l) {
            return true;
        }
        if self.count == MAX_DESTINATIONS {
            return false;
        }
        self.destinations[self.count] = l;
        self.count += 1;
        true
    }

    /// Whether every locator of `ls` is here or fits.
    fn fits(&self, ls: &[Locator]) -> bool {
        let new = ls.iter().filter(|l| !self.destinations[..self.count].contains(l)).count();
        self.count + new <= MAX_DESTINATIONS
    }

    fn add_unchecked(&mut self, l: Locator) {
        let _ = self.add(l);
    }

    /// A transmit to the locators of one endpoint (the first `MAX_DESTINATIONS`).
    fn to(ls: &[Locator]) -> Self {
        let mut t = Self::new(0);
        ls.iter().for_each(|l| t.add_unchecked(*l));
        t
    }

    /// Where to send it.
    pub fn destinations(&self) -> &[Locator] {
        &self.destinations[..self.count]
    }
}

/// Inline QoS of a DATA that robowire writes: key hash, status info, related sample identity
/// (both PIDs: 0x0083 standard, 0x800f as Fast DDS reads it).
fn inline_qos<'s>(change: &Change, scratch: &'s mut [u8; 128]) -> Option<ParameterList<'s>> {
    if change.key_hash.is_none() && change.related.is_none() && change.kind == ChangeKind::Alive {
        return None;
    }
    let len = {
        let mut w = ParameterWriter::new(&mut scratch[..]);
        if let Some(k) = change.key_hash {
            w.push(pid::KEY_HASH, &k).ok()?;
        }
        if change.kind != ChangeKind::Alive {
            w.push(pid::STATUS_INFO, &change.kind.status_info().to_be_bytes()).ok()?;
        }
        if let Some(r) = change.related {
            let mut v = [0u8; 24];
            v[..16].copy_from_slice(&r.writer.to_bytes());
            let (high, low) = r.sequence.to_parts();
            v[16..20].copy_from_slice(&high.to_le_bytes());
            v[20..].copy_from_slice(&low.to_le_bytes());
            w.push(pid::RELATED_SAMPLE_IDENTITY, &v).ok()?;
            w.push(pid::RELATED_SAMPLE_IDENTITY_LEGACY, &v).ok()?;
        }
        w.finish().ok()?
    };
    ParameterList::parse(&scratch[..len], Endianness::Little).ok().map(|(l, _)| l)
}

fn payload_of(change: &Change) -> Payload<'_> {
    match change.kind {
        ChangeKind::Alive => Payload::Data(&change.payload),
        _ if change.payload.is_empty() => Payload::None,
        _ => Payload::Key(&change.payload),
    }
}

impl Participant {
    fn header(&self) -> Header {
        Header { version: ProtocolVersion::V2_4, vendor: VendorId::ROBOWIRE, guid_prefix: self.config.guid_prefix }
    }

    /// The next datagram due at `now`, built into `buf` (1500 bytes hold every datagram but a
    /// sample near the fragment size; 64 KiB hold any). `None` when nothing is due.
    pub fn poll_transmit(&mut self, now: Time, buf: &mut [u8]) -> Option<Transmit> {
        if let Some(t) = self.poll_spdp(now, buf) {
            return Some(t);
        }
        for w in 0..self.writers.len() {
            if let Some(t) = self.poll_writer(now, w, buf) {
                return Some(t);
            }
        }
        for r in 0..self.readers.len() {
            if let Some(t) = self.poll_reader(now, r, buf) {
                return Some(t);
            }
        }
        None
    }

    fn poll_spdp(&mut self, now: Time, buf: &mut [u8]) -> Option<Transmit> {
        let destinations: alloc::vec::Vec<Locator> = if let Some(prefix) = self.spdp_unicast.pop() {
            let r = self.remote.iter().find(|r| r.data.guid_prefix == prefix)?;
            let l = &r.data.metatraffic_unicast_locators;
            if l.is_empty() { r.data.default_unicast_locators.clone() } else { l.clone() }
        } else if self.spdp_due <= now {
            self.spdp_due = now + self.config.announce_period;
            self.config.spdp_destinations.clone()
        } else {
            return None;
        };
        let change = Change {
            sequence: self.spdp_sequence,
            kind: ChangeKind::Alive,
            payload: self.spdp_payload(),
            source_timestamp: None,
            related: None,
            key_hash: Some(crate::types::Guid::new(self.config.guid_prefix, EntityId::PARTICIPANT).to_bytes()),
        };
        let len = self.build(buf, None, |w| {
            push_data(w, EntityId::SPDP_READER, EntityId::SPDP_WRITER, &change)?;
            Ok(())
        });
        let Some(len) = len else {
            self.counters.transmit_too_small += 1;
            return None;
        };
        let mut t = Transmit::new(len);
        for l in destinations {
            t.add(l);
        }
        Some(t)
    }

    /// The datagram that tells others this participant leaves (an SPDP dispose), to the SPDP
    /// destinations and the first known participants' discovery locators.
    pub fn leave(&mut self, buf: &mut [u8]) -> Option<Transmit> {
        let guid = crate::types::Guid::new(self.config.guid_prefix, EntityId::PARTICIPANT);
        // The key: PL_CDR_LE with PID_PARTICIPANT_GUID.
        let mut key = alloc::vec![0u8, 3, 0, 0];
        key.extend_from_slice(&pid::PARTICIPANT_GUID.to_le_bytes());
        key.extend_from_slice(&16u16.to_le_bytes());
        key.extend_from_slice(&guid.to_bytes());
        key.extend_from_slice(&[1, 0, 0, 0]);
        let change = Change {
            sequence: SequenceNumber(self.spdp_sequence.0 + 1),
            kind: ChangeKind::Disposed,
            payload: key,
            source_timestamp: None,
            related: None,
            key_hash: Some(guid.to_bytes()),
        };
        let len = self.build(buf, None, |w| push_data(w, EntityId::SPDP_READER, EntityId::SPDP_WRITER, &change))?;
        let mut t = Transmit::new(len);
        for l in &self.config.spdp_destinations {
            t.add(*l);
        }
        for r in &self.remote {
            for l in &r.data.metatraffic_unicast_locators {
                t.add(*l);
            }
        }
        Some(t)
    }

    /// Builds a datagram: header, INFO_DST when `to` is given, then what `fill` pushes.
    fn build(
        &self,
        buf: &mut [u8],
        to: Option<GuidPrefix>,
        fill: impl FnOnce(&mut MessageWriter<'_>) -> Result<(), BufferTooSmall>,
    ) -> Option<usize> {
        let mut w = MessageWriter::new(buf, &self.header()).ok()?;
        if let Some(prefix) = to {
            w.push(&Submessage::InfoDst(InfoDst { guid_prefix: prefix })).ok()?;
        }
        fill(&mut w).ok()?;
        Some(w.finish())
    }

    /// The DATA of a fresh write, to every matched reader due it whose locators fit in one
    /// transmit; those are marked sent (the others get it from `poll_transmit`).
    pub(super) fn build_data_to_all(
        &mut self,
        w: usize,
        sn: SequenceNumber,
        buf: &mut [u8],
    ) -> Result<Option<Transmit>, WriteError> {
        let header = self.header();
        let writer = &mut self.writers[w];
        let Some(change) = writer.history.get(sn) else { return Ok(None) };
        let mut t = Transmit::new(0);
        let mut any = false;
        for p in writer.readers.iter().filter(|p| p.next_unsent == sn) {
            if t.fits(&p.locators) {
                p.locators.iter().for_each(|l| t.add_unchecked(*l));
                any = true;
            }
        }
        if !any {
            return Ok(None);
        }
        let mut m = MessageWriter::new(buf, &header).map_err(|_| WriteError::BufferTooSmall)?;
        if let Some(ts) = change.source_timestamp {
            m.push(&Submessage::InfoTs(InfoTs { timestamp: Some(ts) })).map_err(|_| WriteError::BufferTooSmall)?;
        }
        push_data(&mut m, EntityId::UNKNOWN, writer.id, change).map_err(|_| WriteError::BufferTooSmall)?;
        t.len = m.finish();
        for p in writer.readers.iter_mut().filter(|p| p.next_unsent == sn) {
            if p.locators.iter().all(|l| t.destinations().contains(l)) {
                p.next_unsent = SequenceNumber(sn.0 + 1);
                if !p.reliable {
                    p.acked = p.next_unsent;
                }
            }
        }
        Ok(Some(t))
    }

    fn poll_writer(&mut self, now: Time, w: usize, buf: &mut [u8]) -> Option<Transmit> {
        let fragment_size = usize::from(self.config.fragment_size);
        // Fragments fill a datagram up to the message size (one at least: headers aside, a
        // fragment and its submessage header take under 256 bytes more than its data).
        let message_size = self.config.max_message_size.max(fragment_size + 256);
        let len = buf.len().min(message_size);
        let buf = &mut buf[..len];
        let prefix = self.config.guid_prefix;
        let header = self.header();
        let writer = &mut self.writers[w];
        let id = writer.id;
        let next = writer.history.next_sequence();
        // Answers to ACKNACKs: the changes asked for, GAPs for those no longer held.
        if let Some(i) = writer.readers.iter().position(|p| p.nack_due.is_some_and(|t| t <= now)) {
            let p = &mut writer.readers[i];
            p.nack_due = None;
            let requested = p.requested.take();
            let fragments = p.requested_fragments.take();
            let reader = p.guid;
            let mut t = Transmit::to(&p.locators);
            let mut m = MessageWriter::new(buf, &header).ok()?;
            m.push(&Submessage::InfoDst(InfoDst { guid_prefix: reader.prefix })).ok()?;
            let mut resent = 0;
            let mut gapped = 0;
            if let Some(set) = requested {
                let start = writer.readers[i].start;
                for sn in set.iter().filter(|&sn| sn < next) {
                    let held = if sn < start { None } else { writer.history.get(sn) };
                    match held {
                        Some(c) if c.payload.len() > fragment_size => {
                            // Sent again as fragments by the push below.
                            let p = &mut writer.readers[i];
                            if p.next_unsent > sn {
                                p.next_unsent = sn;
                                p.next_fragment = 1;
                            }
                        }
                        Some(c) => {
                            if push_data(&mut m, reader.entity, id, c).is_err() {
                                break;
                            }
                            resent += 1;
                        }
                        None => {
                            let Ok(list) = SequenceNumberSet::new(SequenceNumber(sn.0 + 1), 0) else { break };
                            let gap = Gap { reader_id: reader.entity, writer_id: id, gap_start: sn, gap_list: list };
                            if m.push(&Submessage::Gap(gap)).is_err() {
                                break;
                            }
                            gapped += 1;
                        }
                    }
                }
            }
            if let Some((c, set)) = fragments.and_then(|(sn, set)| Some((writer.history.get(sn)?, set))) {
                for n in set.iter() {
                    if push_fragment(&mut m, reader.entity, id, c, n, fragment_size).is_err() {
                        break;
                    }
                }
            }
            writer.counters.resent += resent;
            writer.counters.gapped += gapped;
            t.len = m.finish();
            return Some(t);
        }
        // Pushes: changes a reader has not been sent (late joiners, fragments, go-back).
        if let Some(i) = writer.readers.iter().position(|p| p.next_unsent < next) {
            let p = &writer.readers[i];
            let (reader, from, fragment) = (p.guid, p.next_unsent, p.next_fragment);
            let mut t = Transmit::to(&p.locators);
            let mut m = MessageWriter::new(buf, &header).ok()?;
            m.push(&Submessage::InfoDst(InfoDst { guid_prefix: reader.prefix })).ok()?;
            let change = writer.history.first_from(from);
            let upto = change.map_or(next, |c| c.sequence);
            if upto > from {
                let list = SequenceNumberSet::new(upto, 0).ok()?;
                m.push(&Submessage::Gap(Gap {
                    reader_id: reader.entity,
                    writer_id: id,
                    gap_start: from,
                    gap_list: list,
                }))
                .ok()?;
            }
            let p = &mut writer.readers[i];
            match change {
                Some(c) if c.payload.len() > fragment_size => {
                    let total = c.payload.len().div_ceil(fragment_size) as u32;
                    if let Some(ts) = c.source_timestamp {
                        m.push(&Submessage::InfoTs(InfoTs { timestamp: Some(ts) })).ok()?;
                    }
                    let mut n = fragment.max(1);
                    push_fragment(&mut m, reader.entity, id, c, n, fragment_size).ok()?;
                    while n < total && push_fragment(&mut m, reader.entity, id, c, n + 1, fragment_size).is_ok() {
                        n += 1;
                    }
                    if n >= total {
                        p.next_unsent = SequenceNumber(c.sequence.0 + 1);
                        p.next_fragment = 1;
                    } else {
                        p.next_unsent = c.sequence;
                        p.next_fragment = n + 1;
                    }
                }
                Some(c) => {
                    if let Some(ts) = c.source_timestamp {
                        m.push(&Submessage::InfoTs(InfoTs { timestamp: Some(ts) })).ok()?;
                    }
                    push_data(&mut m, reader.entity, id, c).ok()?;
                    p.next_unsent = SequenceNumber(c.sequence.0 + 1);
                }
                None => p.next_unsent = next,
            }
            if !p.reliable {
                p.acked = p.next_unsent;
            }
            t.len = m.finish();
            return Some(t);
        }
        // Heartbeats while anything is unacknowledged.
        if writer.heartbeat_due.is_some_and(|t| t <= now) {
            if !writer.readers.iter().any(|p| p.reliable) {
                writer.heartbeat_due = None;
                return None;
            }
            writer.heartbeat_sent(now);
            let hb = Heartbeat {
                reader_id: EntityId::UNKNOWN,
                writer_id: id,
                first_sn: writer.history.first_sequence(),
                last_sn: writer.history.last_sequence(),
                count: writer.heartbeat_count,
                final_flag: false,
                liveliness_flag: false,
            };
            let mut m = MessageWriter::new(buf, &header).ok()?;
            m.push(&Submessage::Heartbeat(hb)).ok()?;
            let mut t = Transmit::new(m.finish());
            for p in writer.readers.iter().filter(|p| p.reliable) {
                for l in &p.locators {
                    t.add(*l);
                }
            }
            let _ = prefix;
            return Some(t);
        }
        None
    }

    fn poll_reader(&mut self, now: Time, r: usize, buf: &mut [u8]) -> Option<Transmit> {
        let header = self.header();
        let reader = &mut self.readers[r];
        let id = reader.id;
        let proxy = reader.writers.iter_mut().find(|p| p.ack_due.is_some_and(|t| t <= now))?;
        proxy.ack_due = None;
        proxy.acknack_count = proxy.acknack_count.wrapping_add(1).max(1);
        let (state, final_flag) = proxy.acknack();
        let acknack = AckNack {
            reader_id: id,
            writer_id: proxy.guid.entity,
            reader_sn_state: state,
            count: proxy.acknack_count,
            final_flag,
        };
        let mut m = MessageWriter::new(buf, &header).ok()?;
        m.push(&Submessage::InfoDst(InfoDst { guid_prefix: proxy.guid.prefix })).ok()?;
        m.push(&Submessage::AckNack(acknack)).ok()?;
        if let Some((sn, set)) = proxy.nack_frag.take() {
            proxy.nack_frag_count = proxy.nack_frag_count.wrapping_add(1).max(1);
            let nack = NackFrag {
                reader_id: id,
                writer_id: proxy.guid.entity,
                writer_sn: sn,
                fragment_number_state: set,
                count: proxy.nack_frag_count,
            };
            m.push(&Submessage::NackFrag(nack)).ok()?;
        }
        let mut t = Transmit::new(m.finish());
        for l in &proxy.locators {
            t.add(*l);
        }
        Some(t)
    }
}

fn push_data(m: &mut MessageWriter<'_>, reader: EntityId, writer: EntityId, c: &Change) -> Result<(), BufferTooSmall> {
    let mut scratch = [0u8; 128];
    let data = Data {
        reader_id: reader,
        writer_id: writer,
        writer_sn: c.sequence,
        inline_qos: inline_qos(c, &mut scratch),
        payload: payload_of(c),
        non_standard_payload: false,
    };
    m.push(&Submessage::Data(data))
}

fn push_fragment(
    m: &mut MessageWriter<'_>,
    reader: EntityId,
    writer: EntityId,
    c: &Change,
    n: u32,
    fragment_size: usize,
) -> Result<(), BufferTooSmall> {
    let start = (n as usize).saturating_sub(1).saturating_mul(fragment_size);
    let end = start.saturating_add(fragment_size).min(c.payload.len());
    let Some(bytes) = c.payload.get(start..end) else { return Ok(()) };
    let mut scratch = [0u8; 128];
    let frag = DataFrag {
        reader_id: reader,
        writer_id: writer,
        writer_sn: c.sequence,
        fragment_starting_num: n,
        fragments_in_submessage: 1,
        fragment_size: fragment_size as u16,
        sample_size: c.payload.len() as u32,
        inline_qos: if n == 1 { inline_qos(c, &mut scratch) } else { None },
        key: c.kind != ChangeKind::Alive,
        non_standard_payload: false,
        payload: bytes,
    };
    m.push(&Submessage::DataFrag(frag))
}
