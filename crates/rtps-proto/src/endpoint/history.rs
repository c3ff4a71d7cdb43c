//! A writer's history: the changes it still holds, in sequence order, bounded by a depth.
//! Payload buffers of removed changes are kept and reused, so a steady stream of writes of one
//! size allocates nothing.

use alloc::collections::VecDeque;
use alloc::vec::Vec;

use super::{SampleIdentity, WriteOptions};
use crate::types::{SequenceNumber, Timestamp};

/// What a change says about its instance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChangeKind {
    /// A sample.
    Alive,
    /// The instance is disposed (PID_STATUS_INFO 1; the payload is the key).
    Disposed,
    /// The instance is unregistered (PID_STATUS_INFO 2).
    Unregistered,
}

impl ChangeKind {
    /// The PID_STATUS_INFO flags (0 for a sample).
    pub fn status_info(self) -> u32 {
        match self {
            Self::Alive => 0,
            Self::Disposed => 1,
            Self::Unregistered => 2,
        }
    }
}

/// One change in a writer's history.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Change {
    /// Its number.
    pub sequence: SequenceNumber,
    /// Sample, dispose or unregister.
    pub kind: ChangeKind,
    /// The serialized payload (with its encapsulation header), or the key for a dispose.
    pub payload: Vec<u8>,
    /// The source timestamp.
    pub source_timestamp: Option<Timestamp>,
    /// The sample it answers.
    pub related: Option<SampleIdentity>,
    /// The instance's key hash.
    pub key_hash: Option<[u8; 16]>,
}

/// Changes `first ..= last` (with holes where changes were removed), at most `depth`.
#[derive(Debug, Clone)]
pub struct History {
    changes: VecDeque<Change>,
    depth: usize,
    next: SequenceNumber,
    spare: Vec<Vec<u8>>,
}

impl History {
    /// An empty history holding at most `depth` (≥ 1) changes.
    pub fn new(depth: usize) -> Self {
        let depth = depth.max(1);
        Self { changes: VecDeque::with_capacity(depth), depth, next: SequenceNumber::FIRST, spare: Vec::new() }
    }

    /// The most changes held.
    pub fn depth(&self) -> usize {
        self.depth
    }

    /// Changes held.
    pub fn len(&self) -> usize {
        self.changes.len()
    }

    /// No change held.
    pub fn is_empty(&self) -> bool {
        self.changes.is_empty()
    }

    /// Whether another change needs one removed first.
    pub fn is_full(&self) -> bool {
        self.changes.len() >= self.depth
    }

    /// The number the next change gets.
    pub fn next_sequence(&self) -> SequenceNumber {
        self.next
    }

    /// The oldest change's number (the next one's when empty).
    pub fn first_sequence(&self) -> SequenceNumber {
        self.changes.front().map_or(self.next, |c| c.sequence)
    }

    /// The newest number given (0 before the first change).
    pub fn last_sequence(&self) -> SequenceNumber {
        SequenceNumber(self.next.0 - 1)
    }

    /// Appends a change; the caller made room (`is_full` false). `None` once numbers run out.
    pub fn push(&mut self, kind: ChangeKind, payload: &[u8], options: &WriteOptions) -> Option<SequenceNumber> {
        let sequence = self.next;
        self.next = sequence.checked_next()?;
        let mut buffer = self.spare.pop().unwrap_or_default();
        buffer.clear();
        buffer.extend_from_slice(payload);
        self.changes.push_back(Change {
            sequence,
            kind,
            payload: buffer,
            source_timestamp: options.source_timestamp,
            related: options.related,
            key_hash: options.key_hash,
        });
        Some(sequence)
    }

    /// Removes the oldest change; its buffer is kept for reuse.
    pub fn remove_oldest(&mut self) -> Option<SequenceNumber> {
        let c = self.changes.pop_front()?;
        let sn = c.sequence;
        self.recycle(c.payload);
        Some(sn)
    }

    /// Removes change `sn` if held.
    pub fn remove(&mut self, sn: SequenceNumber) -> bool {
        match self.index(sn) {
            Some(i) => {
                if let Some(c) = self.changes.remove(i) {
                    self.recycle(c.payload);
                }
                true
            }
            None => false,
        }
    }

    fn recycle(&mut self, buffer: Vec<u8>) {
        if self.spare.len() < 4 {
            self.spare.push(buffer);
        }
    }

    fn index(&self, sn: SequenceNumber) -> Option<usize> {
        self.changes.binary_search_by(|c| c.sequence.cmp(&sn)).ok()
    }

    /// Change `sn`, if still held.
    pub fn get(&self, sn: SequenceNumber) -> Option<&Change> {
        self.index(sn).map(|i| &self.changes[i])
    }

    /// The first change held with a number ≥ `sn`.
    pub fn first_from(&self, sn: SequenceNumber) -> Option<&Change> {
        let i = self.changes.partition_point(|c| c.sequence < sn);
        self.changes.get(i)
    }

    /// The changes, oldest first.
    pub fn iter(&self) -> impl Iterator<Item = &Change> {
        self.changes.iter()
    }
}
