//! A writer: its history, the readers matched to it and what each has acknowledged. Reliable
//! readers get HEARTBEATs while anything is unacknowledged, their ACKNACKs and NACK_FRAGs are
//! answered after the NACK response delay with the changes (or GAPs for changes no longer held).

use alloc::vec::Vec;
use core::time::Duration;

use super::{ChangeKind, History, WriteError, WriteMode, WriteOptions};
use crate::Time;
use crate::types::{EntityId, FragmentNumberSet, Guid, Locator, SequenceNumber, SequenceNumberSet};
use crate::wire::{AckNack, NackFrag};

/// A matched reader, as its writer sees it.
#[derive(Debug, Clone)]
pub(crate) struct ReaderProxy {
    pub(crate) guid: Guid,
    pub(crate) reliable: bool,
    pub(crate) locators: Vec<Locator>,
    /// Whether it asked for the writer's history (transient-local or stronger).
    wants_history: bool,
    /// The first change relevant to it: changes before it (written before the match, for a
    /// volatile reader) are answered with GAPs.
    pub(crate) start: SequenceNumber,
    /// Every number below is acknowledged (reliable) or was sent (best effort).
    pub(crate) acked: SequenceNumber,
    /// The next change to push to this reader.
    pub(crate) next_unsent: SequenceNumber,
    /// The next fragment of `next_unsent` to push, when it is fragmented (from 1).
    pub(crate) next_fragment: u32,
    /// Numbers the reader asked for again, not yet answered.
    pub(crate) requested: Option<SequenceNumberSet>,
    /// Fragments asked for again.
    pub(crate) requested_fragments: Option<(SequenceNumber, FragmentNumberSet)>,
    /// When the requests are answered.
    pub(crate) nack_due: Option<Time>,
    /// The last ACKNACK count taken.
    last_acknack: Option<i32>,
    last_nack_frag: Option<i32>,
}

impl ReaderProxy {
    pub(crate) fn new(guid: Guid, reliable: bool, wants_history: bool, locators: Vec<Locator>) -> Self {
        Self {
            guid,
            reliable,
            locators,
            wants_history,
            start: SequenceNumber::FIRST,
            acked: SequenceNumber::FIRST,
            next_unsent: SequenceNumber::FIRST,
            next_fragment: 1,
            requested: None,
            requested_fragments: None,
            nack_due: None,
            last_acknack: None,
            last_nack_frag: None,
        }
    }
}

/// How a writer behaves (from its QoS).
#[derive(Debug, Clone, Copy)]
pub(crate) struct WriterConfig {
    pub(crate) transient_local: bool,
    pub(crate) depth: usize,
    pub(crate) mode: WriteMode,
    pub(crate) heartbeat_period: Duration,
    pub(crate) nack_response_delay: Duration,
    pub(crate) max_readers: usize,
}

/// A local writer.
#[derive(Debug, Clone)]
pub(crate) struct Writer {
    pub(crate) id: EntityId,
    pub(crate) config: WriterConfig,
    pub(crate) history: History,
    pub(crate) readers: Vec<ReaderProxy>,
    pub(crate) heartbeat_count: i32,
    pub(crate) heartbeat_due: Option<Time>,
    pub(crate) counters: WriterCounters,
}

/// A writer's counters.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct WriterCounters {
    /// Samples written.
    pub written: u64,
    /// Samples removed before every reliable reader acknowledged them (KEEP_LAST overwrote).
    pub replaced_unacknowledged: u64,
    /// Writes refused because the history was full.
    pub refused_full: u64,
    /// Changes sent again on request.
    pub resent: u64,
    /// Numbers answered with a GAP (no longer held).
    pub gapped: u64,
    /// ACKNACKs taken.
    pub acknacks: u64,
    /// ACKNACKs or NACK_FRAGs ignored (old count, unknown reader).
    pub stale_acknacks: u64,
}

impl Writer {
    pub(crate) fn new(id: EntityId, config: WriterConfig) -> Self {
        Self {
            id,
            history: History::new(config.depth),
            config,
            readers: Vec::new(),
            heartbeat_count: 0,
            heartbeat_due: None,
            counters: WriterCounters::default(),
        }
    }

    /// Matches a reader. A transient-local writer pushes its whole history to a reader that
    /// asks for it; others start at the next change.
    pub(crate) fn add_reader(&mut self, mut proxy: ReaderProxy, now: Time) -> bool {
        if let Some(p) = self.readers.iter_mut().find(|p| p.guid == proxy.guid) {
            p.locators = proxy.locators;
            return true;
        }
        if self.readers.len() >= self.config.max_readers {
            return false;
        }
        let start = if self.config.transient_local && proxy.wants_history {
            self.history.first_sequence()
        } else {
            self.history.next_sequence()
        };
        proxy.start = start;
        proxy.next_unsent = start;
        proxy.acked = start;
        if proxy.reliable {
            // Tell the reader where the history stands at once.
            self.heartbeat_due = Some(now);
        }
        self.readers.push(proxy);
        true
    }

    pub(crate) fn remove_reader(&mut self, guid: Guid) -> bool {
        let before = self.readers.len();
        self.readers.retain(|p| p.guid != guid);
        before != self.readers.len()
    }

    fn unacknowledged(&self, sn: SequenceNumber) -> bool {
        self.readers.iter().any(|p| p.reliable && p.acked <= sn)
    }

    /// Adds a change to the history (making room as the mode says). The caller sends it.
    pub(crate) fn write(
        &mut self,
        now: Time,
        kind: ChangeKind,
        payload: &[u8],
        options: &WriteOptions,
    ) -> Result<SequenceNumber, WriteError> {
        if self.history.is_full() {
            let oldest = self.history.first_sequence();
            let unacked = self.unacknowledged(oldest);
            if unacked && self.config.mode == WriteMode::RefuseWhenFull {
                self.counters.refused_full += 1;
                return Err(WriteError::HistoryFull { depth: self.history.depth() });
            }
            if unacked {
                self.counters.replaced_unacknowledged += 1;
            }
            self.history.remove_oldest();
        }
        let sn = self.history.push(kind, payload, options).ok_or(WriteError::SequenceNumbersExhausted)?;
        self.counters.written += 1;
        if self.readers.iter().any(|p| p.reliable) && self.heartbeat_due.is_none() {
            self.heartbeat_due = Some(now + self.config.heartbeat_period);
        }
        Ok(sn)
    }

    pub(crate) fn handle_acknack(&mut self, now: Time, reader: Guid, acknack: &AckNack) -> bool {
        let next = self.history.next_sequence();
        let delay = self.config.nack_response_delay;
        let Some(p) = self.readers.iter_mut().find(|p| p.guid == reader && p.reliable) else {
            self.counters.stale_acknacks += 1;
            return false;
        };
        if p.last_acknack.is_some_and(|c| acknack.count <= c) {
            self.counters.stale_acknacks += 1;
            return false;
        }
        p.last_acknack = Some(acknack.count);
        self.counters.acknacks += 1;
        let base = acknack.reader_sn_state.base().min(next);
        if base > p.acked {
            p.acked = base;
        }
        if p.next_unsent < p.acked {
            p.next_unsent = p.acked;
        }
        if !acknack.reader_sn_state.is_empty() {
            p.requested = Some(acknack.reader_sn_state);
            p.nack_due.get_or_insert(now + delay);
        } else if !acknack.final_flag && p.acked < next {
            // The reader has a hole it did not name: send it everything from its base again.
            p.next_unsent = p.next_unsent.min(p.acked);
        }
        true
    }

    pub(crate) fn handle_nack_frag(&mut self, now: Time, reader: Guid, nack: &NackFrag) -> bool {
        let delay = self.config.nack_response_delay;
        let Some(p) = self.readers.iter_mut().find(|p| p.guid == reader && p.reliable) else {
            self.counters.stale_acknacks += 1;
            return false;
        };
        if p.last_nack_frag.is_some_and(|c| nack.count <= c) {
            self.counters.stale_acknacks += 1;
            return false;
        }
        p.last_nack_frag = Some(nack.count);
        p.requested_fragments = Some((nack.writer_sn, nack.fragment_number_state));
        p.nack_due.get_or_insert(now + delay);
        true
    }

    /// Whether any reliable reader has not acknowledged every change.
    pub(crate) fn has_unacknowledged(&self) -> bool {
        let next = self.history.next_sequence();
        self.readers.iter().any(|p| p.reliable && p.acked < next)
    }

    pub(crate) fn poll_timeout(&self) -> Option<Time> {
        let nack = self.readers.iter().filter_map(|p| p.nack_due).min();
        let push = self.readers.iter().any(|p| p.next_unsent < self.history.next_sequence()).then_some(Time::ZERO);
        [self.heartbeat_due, nack, push].into_iter().flatten().min()
    }

    /// Schedules the next periodic heartbeat after one was sent.
    pub(crate) fn heartbeat_sent(&mut self, now: Time) {
        self.heartbeat_count = self.heartbeat_count.wrapping_add(1).max(1);
        self.heartbeat_due = self.has_unacknowledged().then(|| now + self.config.heartbeat_period);
    }
}
