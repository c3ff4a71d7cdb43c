#![doc = include_str!("../README.md")]

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::time::{SystemTime, UNIX_EPOCH};

/// Which way a frame went, seen from the link's owner.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Direction {
    /// Written by this side.
    Sent,
    /// Read by this side.
    Received,
}

impl Direction {
    /// `sent` or `received`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Sent => "sent",
            Self::Received => "received",
        }
    }
}

/// One frame as it was on the wire.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TappedFrame {
    /// The link, as the recorder numbered it.
    pub link: u16,
    /// Sent or received.
    pub direction: Direction,
    /// When, ns since the Unix epoch (`CLOCK_REALTIME`).
    pub unix_ns: u64,
    /// The bytes, exactly.
    pub bytes: Vec<u8>,
}

/// What the taps of one queue did.
#[derive(Debug, Default)]
pub struct TapCounters {
    recorded: AtomicU64,
    dropped: AtomicU64,
}

impl TapCounters {
    /// Frames queued for the recorder.
    pub fn recorded(&self) -> u64 {
        self.recorded.load(Ordering::Relaxed)
    }

    /// Frames dropped because the queue was full (or the recorder gone).
    pub fn dropped(&self) -> u64 {
        self.dropped.load(Ordering::Relaxed)
    }
}

/// The sending side of a recorder's queue; hands out a [`Tap`] per link.
#[derive(Debug, Clone)]
pub struct TapQueue {
    tx: SyncSender<TappedFrame>,
    counters: Arc<TapCounters>,
}

impl TapQueue {
    /// A queue of `capacity` frames and its receiving end.
    pub fn bounded(capacity: usize) -> (Self, Receiver<TappedFrame>) {
        let (tx, rx) = sync_channel(capacity);
        (Self { tx, counters: Arc::default() }, rx)
    }

    /// A tap for link number `link`.
    pub fn tap(&self, link: u16) -> Tap {
        Tap { link, tx: self.tx.clone(), counters: self.counters.clone() }
    }

    /// The counters of every tap of this queue.
    pub fn counters(&self) -> &TapCounters {
        &self.counters
    }
}

/// A link's tap: [`record`](Self::record) never blocks.
#[derive(Clone)]
pub struct Tap {
    link: u16,
    tx: SyncSender<TappedFrame>,
    counters: Arc<TapCounters>,
}

impl std::fmt::Debug for Tap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Tap").field("link", &self.link).finish_non_exhaustive()
    }
}

/// Two taps are equal when they feed the same queue as the same link.
impl PartialEq for Tap {
    fn eq(&self, other: &Self) -> bool {
        self.link == other.link && Arc::ptr_eq(&self.counters, &other.counters)
    }
}

impl Eq for Tap {}

impl Tap {
    /// The link number.
    pub fn link(&self) -> u16 {
        self.link
    }

    /// Hands a copy of `bytes` to the recorder, stamped now; drops it (counted) if the queue is
    /// full.
    pub fn record(&self, direction: Direction, bytes: &[u8]) {
        let unix_ns = SystemTime::now().duration_since(UNIX_EPOCH).map_or(0, |d| d.as_nanos() as u64);
        let frame = TappedFrame { link: self.link, direction, unix_ns, bytes: bytes.to_vec() };
        let counter = match self.tx.try_send(frame) {
            Ok(()) => &self.counters.recorded,
            Err(TrySendError::Full(_) | TrySendError::Disconnected(_)) => &self.counters.dropped,
        };
        counter.fetch_add(1, Ordering::Relaxed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gone_recorder_drops_and_counts() {
        let (queue, frames) = TapQueue::bounded(4);
        let tap = queue.tap(1);
        drop(frames);
        tap.record(Direction::Received, &[1]);
        assert_eq!(queue.counters().dropped(), 1);
    }

    #[test]
    fn frames_keep_their_link_direction_and_order() {
        let (queue, frames) = TapQueue::bounded(8);
        let (a, b) = (queue.tap(1), queue.tap(2));
        a.record(Direction::Sent, &[1]);
        b.record(Direction::Received, &[2, 2]);
        let got: Vec<_> = frames.try_iter().map(|f| (f.link, f.direction, f.bytes)).collect();
        assert_eq!(got, [(1, Direction::Sent, vec![1]), (2, Direction::Received, vec![2, 2])]);
        assert_ne!(a, b);
        assert_eq!(a, a.clone());
    }
}
