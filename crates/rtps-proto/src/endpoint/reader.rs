//! A reader: for each matched writer, the lowest number not yet delivered, samples that came
//! early (reliable), fragments in reassembly, and the ACKNACK or NACK_FRAG it owes. Samples are
//! delivered in order to a callback; in-order DATA straight from the datagram, without a copy.

use alloc::collections::BTreeMap;
use alloc::vec::Vec;
use core::time::Duration;

use super::{Reassembly, ReassemblyError, SampleInfo};
use crate::Time;
use crate::types::{EntityId, FragmentNumberSet, Guid, Locator, SequenceNumber, SequenceNumberSet};
use crate::wire::{DataFrag, Gap, Heartbeat, HeartbeatFrag};

/// A sample that came before its turn, or a number a GAP made irrelevant.
#[derive(Debug, Clone)]
enum Pending {
    Sample(SampleInfo, Vec<u8>),
    Irrelevant,
}

/// What happened to a DATA or DATA_FRAG.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Delivery {
    /// Delivered (with any samples it released).
    Delivered,
    /// Kept until the samples before it arrive.
    Held,
    /// A fragment taken; the sample is not complete yet.
    Fragment,
    /// Already delivered or irrelevant.
    Duplicate,
    /// Dropped: the reader's bound on held samples or reassemblies is reached.
    Dropped,
    /// Refused: the fragmented sample exceeds the reassembly limit or is inconsistent.
    Refused(ReassemblyError),
}

/// A matched writer, as its reader sees it.
#[derive(Debug, Clone)]
pub(crate) struct WriterProxy {
    pub(crate) guid: Guid,
    pub(crate) reliable: bool,
    pub(crate) locators: Vec<Locator>,
    /// Every number below was delivered or is irrelevant.
    next: SequenceNumber,
    /// Whether anything (a sample, a heartbeat) came from the writer yet.
    started: bool,
    /// The base of the ACKNACK sent before anything came (a pre-emptive one, asking for a
    /// heartbeat): 0 for Fast DDS (the only base its writers answer at once), else 1.
    preemptive_base: i64,
    /// The highest number the writer said it has.
    available: SequenceNumber,
    pending: BTreeMap<SequenceNumber, Pending>,
    reassembly: Vec<Reassembly>,
    last_heartbeat: Option<i32>,
    last_heartbeat_frag: Option<i32>,
    /// When the ACKNACK (and NACK_FRAG) is due.
    pub(crate) ack_due: Option<Time>,
    /// A NACK_FRAG to send with it.
    pub(crate) nack_frag: Option<(SequenceNumber, FragmentNumberSet)>,
    pub(crate) acknack_count: i32,
    pub(crate) nack_frag_count: i32,
}

impl WriterProxy {
    pub(crate) fn new(guid: Guid, reliable: bool, locators: Vec<Locator>, preemptive_base: i64) -> Self {
        Self {
            guid,
            reliable,
            locators,
            preemptive_base,
            next: SequenceNumber::FIRST,
            started: false,
            available: SequenceNumber(0),
            pending: BTreeMap::new(),
            reassembly: Vec::new(),
            last_heartbeat: None,
            last_heartbeat_frag: None,
            ack_due: None,
            nack_frag: None,
            acknack_count: 0,
            nack_frag_count: 0,
        }
    }

    /// The ACKNACK to send: its set and its final flag. Before anything came from the writer, a
    /// pre-emptive one (empty, not final: the writer answers with a heartbeat); else base = next
    /// expected, members = what is missing up to what the writer has (at most 256 numbers),
    /// final when nothing is.
    pub(crate) fn acknack(&self) -> (SequenceNumberSet, bool) {
        if !self.started
            && let Ok(set) = SequenceNumberSet::new(SequenceNumber(self.preemptive_base), 0)
        {
            return (set, false);
        }
        let set = self.acknack_state();
        (set, set.is_empty())
    }

    fn acknack_state(&self) -> SequenceNumberSet {
        let base = self.next;
        let span = self.available.0.saturating_sub(base.0).saturating_add(1).clamp(0, 256);
        let mut set = SequenceNumberSet::new(base, span as u32)
            .or_else(|_| SequenceNumberSet::new(base, 0))
            .unwrap_or_else(|_| SequenceNumberSet::new(SequenceNumber::FIRST, 0).expect("1/0 is a valid set"));
        for i in 0..span {
            let sn = SequenceNumber(base.0 + i);
            if !self.pending.contains_key(&sn) {
                set.insert(sn);
            }
        }
        set
    }

    fn missing(&self) -> bool {
        self.available >= self.next
    }
}

/// How a reader behaves (from its QoS).
#[derive(Debug, Clone, Copy)]
pub(crate) struct ReaderConfig {
    pub(crate) depth: usize,
    pub(crate) heartbeat_response_delay: Duration,
    pub(crate) reassemblies: usize,
    pub(crate) reassembly_bytes: usize,
    pub(crate) reassembly_timeout: Duration,
    pub(crate) max_writers: usize,
}

/// A reader's counters.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ReaderCounters {
    /// Samples delivered.
    pub delivered: u64,
    /// Duplicates dropped.
    pub duplicates: u64,
    /// Numbers skipped: lost on a best-effort link, or no longer held by a reliable writer.
    pub lost: u64,
    /// Samples or fragments dropped at a bound (held samples, reassemblies).
    pub dropped_at_limit: u64,
    /// Fragmented samples refused (too large, inconsistent).
    pub refused_fragments: u64,
    /// Reassemblies given up after the timeout.
    pub reassembly_timeouts: u64,
}

/// A local reader.
#[derive(Debug, Clone)]
pub(crate) struct Reader {
    pub(crate) id: EntityId,
    pub(crate) config: ReaderConfig,
    pub(crate) writers: Vec<WriterProxy>,
    pub(crate) counters: ReaderCounters,
    spare: Vec<Vec<u8>>,
}

impl Reader {
    pub(crate) fn new(id: EntityId, config: ReaderConfig) -> Self {
        Self { id, config, writers: Vec::new(), counters: ReaderCounters::default(), spare: Vec::new() }
    }

    /// Matches a writer; a reliable one is sent a pre-emptive ACKNACK at once, so that it
    /// answers with a heartbeat (and a late joiner's history comes) without waiting for its
    /// period.
    pub(crate) fn add_writer(&mut self, mut proxy: WriterProxy, now: Time) -> bool {
        if let Some(w) = self.writers.iter_mut().find(|w| w.guid == proxy.guid) {
            w.locators = proxy.locators;
            return true;
        }
        if self.writers.len() >= self.config.max_writers {
            return false;
        }
        if proxy.reliable {
            proxy.ack_due = Some(now);
        }
        self.writers.push(proxy);
        true
    }

    pub(crate) fn remove_writer(&mut self, guid: Guid) -> bool {
        let before = self.writers.len();
        self.writers.retain(|w| w.guid != guid);
        before != self.writers.len()
    }

    pub(crate) fn writer_index(&self, guid: Guid) -> Option<usize> {
        self.writers.iter().position(|w| w.guid == guid)
    }

    fn buffer(&mut self) -> Vec<u8> {
        self.spare.pop().unwrap_or_default()
    }

    fn recycle(&mut self, b: Vec<u8>) {
        keep_spare(&mut self.spare, b);
    }

    /// A DATA from matched writer `w` (an index from [`writer_index`](Self::writer_index)).
    pub(crate) fn handle_data(
        &mut self,
        w: usize,
        info: SampleInfo,
        payload: &[u8],
        deliver: &mut dyn FnMut(&SampleInfo, &[u8]),
    ) -> Delivery {
        let Some(proxy) = self.writers.get_mut(w) else { return Delivery::Dropped };
        let sn = info.sequence;
        if !proxy.started && !proxy.reliable {
            // Best effort starts at the first sample heard; reliable expects every number from 1
            // until a heartbeat or GAP says otherwise.
            proxy.next = proxy.next.max(sn);
        }
        proxy.started = true;
        if sn < proxy.next || proxy.pending.contains_key(&sn) {
            self.counters.duplicates += 1;
            return Delivery::Duplicate;
        }
        if sn == proxy.next || !proxy.reliable {
            if sn > proxy.next {
                self.counters.lost += u64::try_from(sn.0 - proxy.next.0).unwrap_or(u64::MAX);
            }
            proxy.next = SequenceNumber(sn.0 + 1);
            proxy.available = proxy.available.max(sn);
            self.counters.delivered += 1;
            deliver(&info, payload);
            self.release(w, deliver);
            return Delivery::Delivered;
        }
        // Reliable and early: hold it, within the bound.
        if proxy.pending.len() >= self.config.depth {
            self.counters.dropped_at_limit += 1;
            return Delivery::Dropped;
        }
        let mut b = self.buffer();
        b.extend_from_slice(payload);
        if let Some(proxy) = self.writers.get_mut(w) {
            proxy.available = proxy.available.max(sn);
            proxy.pending.insert(sn, Pending::Sample(info, b));
        }
        Delivery::Held
    }

    /// Delivers the held samples that are now in order.
    fn release(&mut self, w: usize, deliver: &mut dyn FnMut(&SampleInfo, &[u8])) {
        let Self { writers, spare, counters, .. } = self;
        let Some(proxy) = writers.get_mut(w) else { return };
        loop {
            // Anything held below `next` is stale.
            while let Some(entry) = proxy.pending.first_entry() {
                if *entry.key() >= proxy.next {
                    break;
                }
                if let Pending::Sample(_, b) = entry.remove() {
                    keep_spare(spare, b);
                }
            }
            let next = proxy.next;
            match proxy.pending.remove(&next) {
                Some(Pending::Sample(info, b)) => {
                    proxy.next = SequenceNumber(next.0 + 1);
                    counters.delivered += 1;
                    deliver(&info, &b);
                    keep_spare(spare, b);
                }
                Some(Pending::Irrelevant) => proxy.next = SequenceNumber(next.0 + 1),
                None => return,
            }
        }
    }

    /// Bytes held in reassembly.
    pub(crate) fn reassembly_bytes(&self) -> usize {
        self.writers.iter().flat_map(|w| &w.reassembly).map(Reassembly::bytes).sum()
    }

    /// A DATA_FRAG from matched writer `w`; delivers the sample once complete. A new
    /// reassembly takes its sample size from `budget` (the participant's bytes left for
    /// reassembly), and is refused when that is not enough.
    pub(crate) fn handle_data_frag(
        &mut self,
        now: Time,
        w: usize,
        info: SampleInfo,
        frag: &DataFrag<'_>,
        budget: &mut usize,
        deliver: &mut dyn FnMut(&SampleInfo, &[u8]),
    ) -> Delivery {
        let Some(proxy) = self.writers.get(w) else { return Delivery::Dropped };
        let sn = frag.writer_sn;
        if (proxy.started && sn < proxy.next) || proxy.pending.contains_key(&sn) {
            self.counters.duplicates += 1;
            return Delivery::Duplicate;
        }
        let index = proxy.reassembly.iter().position(|r| r.sequence() == sn);
        let index = match index {
            Some(i) => i,
            None => {
                let size = usize::try_from(frag.sample_size).unwrap_or(usize::MAX);
                if proxy.reassembly.len() >= self.config.reassemblies
                    || (size <= self.config.reassembly_bytes && size > *budget)
                {
                    self.counters.dropped_at_limit += 1;
                    return Delivery::Dropped;
                }
                let buffer = self.buffer();
                let expires = now + self.config.reassembly_timeout;
                match Reassembly::new(frag, self.config.reassembly_bytes, expires, buffer) {
                    Ok(r) => {
                        let Some(proxy) = self.writers.get_mut(w) else { return Delivery::Dropped };
                        *budget = budget.saturating_sub(r.bytes());
                        proxy.reassembly.push(r);
                        proxy.reassembly.len() - 1
                    }
                    Err(e) => {
                        self.counters.refused_fragments += 1;
                        return Delivery::Refused(e);
                    }
                }
            }
        };
        let Some(proxy) = self.writers.get_mut(w) else { return Delivery::Dropped };
        match proxy.reassembly[index].insert(frag) {
            Ok(false) => Delivery::Fragment,
            Ok(true) => {
                let data = proxy.reassembly.swap_remove(index).into_data();
                let d = self.handle_data(w, info, &data, deliver);
                self.recycle(data);
                d
            }
            Err(e) => {
                self.counters.refused_fragments += 1;
                Delivery::Refused(e)
            }
        }
    }

    /// A HEARTBEAT from matched writer `w`: what it has; an ACKNACK is owed unless it is final
    /// and nothing is missing.
    pub(crate) fn handle_heartbeat(
        &mut self,
        now: Time,
        w: usize,
        hb: &Heartbeat,
        deliver: &mut dyn FnMut(&SampleInfo, &[u8]),
    ) {
        let delay = self.config.heartbeat_response_delay;
        let Some(proxy) = self.writers.get_mut(w) else { return };
        if !proxy.reliable || proxy.last_heartbeat.is_some_and(|c| hb.count <= c) {
            return;
        }
        proxy.last_heartbeat = Some(hb.count);
        if hb.first_sn > proxy.next {
            // The writer no longer has these (or never had them for this reader, before it
            // heard anything).
            if proxy.started {
                let lost = hb.first_sn.0 - proxy.next.0;
                let held = proxy.pending.range(..hb.first_sn).count() as i64;
                self.counters.lost += u64::try_from(lost - held).unwrap_or(0);
            }
            proxy.next = hb.first_sn;
        }
        proxy.started = true;
        proxy.available = proxy.available.max(hb.last_sn);
        if !hb.final_flag || proxy.missing() {
            proxy.ack_due.get_or_insert(now + delay);
            // A sample the writer has and of which some fragments came: its missing fragments
            // are asked for by number. CycloneDDS answers an ACKNACK of a fragmented sample with
            // its first fragment alone and sends the rest on a NACK_FRAG, so an ACKNACK alone
            // would get that fragment again and again.
            let partial = proxy
                .reassembly
                .iter()
                .filter(|r| r.sequence() >= proxy.next && r.sequence() <= hb.last_sn)
                .min_by_key(|r| r.sequence());
            if let Some(set) = partial.and_then(|r| r.missing(u32::MAX).map(|set| (r.sequence(), set))) {
                proxy.nack_frag = Some(set);
            }
        }
        self.release(w, deliver);
    }

    /// A HEARTBEAT_FRAG: fragments up to `last_fragment_num` exist; a NACK_FRAG is owed for the
    /// ones missing from that sample's reassembly.
    pub(crate) fn handle_heartbeat_frag(&mut self, now: Time, w: usize, hb: &HeartbeatFrag) {
        let delay = self.config.heartbeat_response_delay;
        let Some(proxy) = self.writers.get_mut(w) else { return };
        if !proxy.reliable || proxy.last_heartbeat_frag.is_some_and(|c| hb.count <= c) {
            return;
        }
        proxy.last_heartbeat_frag = Some(hb.count);
        let missing = proxy
            .reassembly
            .iter()
            .find(|r| r.sequence() == hb.writer_sn)
            .and_then(|r| r.missing(hb.last_fragment_num));
        if let Some(set) = missing {
            proxy.nack_frag = Some((hb.writer_sn, set));
            proxy.ack_due.get_or_insert(now + delay);
        }
    }

    /// A GAP: `gap_start .. gap_list.base()` and the list's members are irrelevant. Handled by
    /// arithmetic on the range, never number by number.
    pub(crate) fn handle_gap(&mut self, w: usize, gap: &Gap, deliver: &mut dyn FnMut(&SampleInfo, &[u8])) {
        let Some(proxy) = self.writers.get_mut(w) else { return };
        if !proxy.reliable {
            return;
        }
        let end = gap.gap_list.base();
        if gap.gap_start <= proxy.next && end > proxy.next {
            proxy.next = end;
        }
        let bound = self.config.depth;
        for sn in gap.gap_list.iter() {
            if sn >= proxy.next && proxy.pending.len() < bound {
                proxy.pending.entry(sn).or_insert(Pending::Irrelevant);
            }
        }
        self.release(w, deliver);
    }

    /// Gives up reassemblies past their time.
    pub(crate) fn expire(&mut self, now: Time) {
        let Self { writers, spare, counters, .. } = self;
        for proxy in writers.iter_mut() {
            let mut i = 0;
            while i < proxy.reassembly.len() {
                if proxy.reassembly[i].expires_at() <= now {
                    keep_spare(spare, proxy.reassembly.swap_remove(i).into_data());
                    counters.reassembly_timeouts += 1;
                } else {
                    i += 1;
                }
            }
        }
    }

    pub(crate) fn poll_timeout(&self) -> Option<Time> {
        self.writers
            .iter()
            .flat_map(|w| w.ack_due.into_iter().chain(w.reassembly.iter().map(Reassembly::expires_at)))
            .min()
    }
}

/// Keeps a few emptied buffers for reuse.
fn keep_spare(spare: &mut Vec<Vec<u8>>, mut b: Vec<u8>) {
    if spare.len() < 8 {
        b.clear();
        spare.push(b);
    }
}

#[cfg(test)]
mod tests;
