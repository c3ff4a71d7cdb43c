//! Counters of a link, shared by its halves and readable from any thread.

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

/// Counters of one link, since it was bound.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LinkStats {
    /// Datagrams sent.
    pub sent: u64,
    /// Sends that failed, socket errors and encode errors alike (the message was not sent).
    pub send_errors: u64,
    /// Datagrams received from the peer (decode errors included).
    pub received: u64,
    /// Datagrams from the peer that did not decode.
    pub decode_errors: u64,
    /// Datagrams from anyone else: dropped, never decoded.
    pub foreign_dropped: u64,
    /// Socket errors while receiving.
    pub receive_errors: u64,
}

#[derive(Debug, Default)]
pub(crate) struct Counters {
    pub(crate) sent: AtomicU64,
    pub(crate) send_errors: AtomicU64,
    pub(crate) received: AtomicU64,
    pub(crate) decode_errors: AtomicU64,
    pub(crate) foreign_dropped: AtomicU64,
    pub(crate) receive_errors: AtomicU64,
}

impl Counters {
    pub(crate) fn bump(counter: &AtomicU64) {
        counter.fetch_add(1, Ordering::Relaxed);
    }

    pub(crate) fn snapshot(&self) -> LinkStats {
        LinkStats {
            sent: self.sent.load(Ordering::Relaxed),
            send_errors: self.send_errors.load(Ordering::Relaxed),
            received: self.received.load(Ordering::Relaxed),
            decode_errors: self.decode_errors.load(Ordering::Relaxed),
            foreign_dropped: self.foreign_dropped.load(Ordering::Relaxed),
            receive_errors: self.receive_errors.load(Ordering::Relaxed),
        }
    }
}

/// A read-only view of a link's counters, cheap to clone and to read from any thread.
#[derive(Debug, Clone)]
pub struct StatsHandle(pub(crate) Arc<Counters>);

impl StatsHandle {
    /// The counters now.
    pub fn get(&self) -> LinkStats {
        self.0.snapshot()
    }
}
