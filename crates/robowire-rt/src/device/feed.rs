//! [`StateFeed`]: what a device's receive loop publishes for its users: the latest state with
//! the time it arrived, every state in order, the connection, and counters.

use std::time::Duration;

use robowire_core::schedule::{Connection, Event, Time, WatchdogCounters};
use robowire_core::timing::LatenessSummary;
use tokio::sync::{broadcast, watch};

use crate::stats::{Counter, SharedLateness, micros};

/// A state and when it arrived, on the monotonic clock ([`crate::now`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stamped<S> {
    /// When it arrived.
    pub at: Time,
    /// The state.
    pub state: S,
}

impl<S> Stamped<S> {
    /// How long ago it arrived.
    pub fn age(&self) -> Duration {
        crate::now().saturating_duration_since(self.at)
    }
}

/// What a receive loop has seen.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FeedStats {
    /// States published.
    pub states: u64,
    /// Watchdog timeouts (and lost links).
    pub disconnects: u64,
    /// Returns to `Connected` after a disconnect.
    pub reconnects: u64,
    /// Time between consecutive signs of life, µs.
    pub state_gap: LatenessSummary,
}

/// How many states a reader of [`StateFeed::every_state`] may fall behind before it misses some
/// (and is told so).
pub const EVERY_STATE_CAPACITY: usize = 256;

/// The latest state and the connection of one device, written by its receive loop only, read by
/// anyone: a `watch` of the latest stamped state (coalescing: a slow reader sees the newest), a
/// `broadcast` of every state (for readers that must see each one), a `watch` of the connection,
/// and counters. Nothing here blocks the writer on a reader.
#[derive(Debug)]
pub struct StateFeed<S> {
    latest: watch::Sender<Option<Stamped<S>>>,
    every: broadcast::Sender<Stamped<S>>,
    /// Subscribed when the feed was made: handed to the first [`every_state`](Self::every_state)
    /// caller, so that it sees the states that arrived before it asked.
    since_open: std::sync::Mutex<Option<broadcast::Receiver<Stamped<S>>>>,
    connection: watch::Sender<Connection>,
    states: Counter,
    disconnects: Counter,
    reconnects: Counter,
    gaps: SharedLateness<1024>,
    last_sign_of_life: std::sync::atomic::AtomicU64,
}

impl<S: Clone> Default for StateFeed<S> {
    fn default() -> Self {
        Self::new()
    }
}

impl<S: Clone> StateFeed<S> {
    /// Nothing received yet; the connection `Waiting`.
    pub fn new() -> Self {
        let every = broadcast::Sender::new(EVERY_STATE_CAPACITY);
        Self {
            latest: watch::Sender::new(None),
            since_open: std::sync::Mutex::new(Some(every.subscribe())),
            every,
            connection: watch::Sender::new(Connection::Waiting),
            states: Counter::default(),
            disconnects: Counter::default(),
            reconnects: Counter::default(),
            gaps: SharedLateness::new(),
            last_sign_of_life: std::sync::atomic::AtomicU64::new(0),
        }
    }

    /// The latest state and when it arrived (`None` before the first).
    pub fn latest(&self) -> Option<Stamped<S>> {
        self.latest.borrow().clone()
    }

    /// The latest state as it changes (a `watch`: a reader that falls behind sees the newest).
    pub fn states(&self) -> watch::Receiver<Option<Stamped<S>>> {
        self.latest.subscribe()
    }

    /// Every state, in order: for the first caller, every state since the feed was made (the
    /// device opened); for later callers, from now on. A reader that falls more than
    /// [`EVERY_STATE_CAPACITY`] behind is told how many it missed (`RecvError::Lagged`).
    pub fn every_state(&self) -> broadcast::Receiver<Stamped<S>> {
        crate::lock(&self.since_open).take().unwrap_or_else(|| self.every.subscribe())
    }

    /// The connection now.
    pub fn connection(&self) -> Connection {
        *self.connection.borrow()
    }

    /// Connection events: `Waiting` → `Connected` → `Disconnected` → `Connected` ….
    pub fn connection_events(&self) -> watch::Receiver<Connection> {
        self.connection.subscribe()
    }

    /// Counters and the gaps between states.
    pub fn stats(&self) -> FeedStats {
        FeedStats {
            states: self.states.get(),
            disconnects: self.disconnects.get(),
            reconnects: self.reconnects.get(),
            state_gap: self.gaps.summary(),
        }
    }

    /// A sign of life at `now` (with the watchdog's event and counters after it), and the state
    /// it carried if any. The connection changes first: whoever wakes on the state sees it
    /// connected.
    pub(crate) fn on_sign_of_life(
        &self,
        now: Time,
        event: Option<Event>,
        counters: WatchdogCounters,
        state: Option<S>,
    ) {
        use std::sync::atomic::Ordering;
        let previous = self.last_sign_of_life.swap(now.as_nanos(), Ordering::Relaxed);
        if previous != 0 {
            self.gaps.record(micros(now.saturating_duration_since(Time::from_nanos(previous))));
        }
        if event.is_some() {
            self.reconnects.set(counters.reconnects);
            self.connection.send_replace(Connection::Connected);
        }
        if let Some(state) = state {
            self.publish(Stamped { at: now, state });
        }
    }

    /// Publishes a state outside a receive loop (a device whose state is made on the caller's
    /// side).
    pub fn publish(&self, stamped: Stamped<S>) {
        self.states.add(1);
        if self.every.receiver_count() > 0 {
            // No receiver left between the check and the send: nothing to deliver.
            let _ = self.every.send(stamped.clone());
        }
        self.latest.send_replace(Some(stamped));
    }

    /// The watchdog expired (or the link was lost).
    pub(crate) fn on_disconnected(&self, counters: WatchdogCounters) {
        self.disconnects.set(counters.disconnects);
        self.connection.send_replace(Connection::Disconnected);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_connection_changes_before_the_state_and_every_state_is_kept() {
        let feed: StateFeed<u32> = StateFeed::new();
        let mut connection = feed.connection_events();
        assert_eq!((feed.latest(), feed.connection()), (None, Connection::Waiting));
        let counters = WatchdogCounters::default();
        feed.on_sign_of_life(Time::from_nanos(10), Some(Event::Connected), counters, Some(1));
        // The first reader gets the states from the start, even those before it asked.
        let mut every = feed.every_state();
        let mut later = feed.every_state();
        feed.on_sign_of_life(Time::from_nanos(20), None, counters, None);
        feed.on_sign_of_life(Time::from_nanos(30), None, counters, Some(2));
        assert!(connection.has_changed().unwrap());
        assert_eq!(*connection.borrow_and_update(), Connection::Connected);
        assert_eq!(feed.latest(), Some(Stamped { at: Time::from_nanos(30), state: 2 }));
        assert_eq!(every.try_recv().map(|s| s.state), Ok(1));
        assert_eq!(every.try_recv().map(|s| s.state), Ok(2));
        assert_eq!(later.try_recv().map(|s| s.state), Ok(2), "a later reader from when it asked");
        feed.on_disconnected(WatchdogCounters { disconnects: 1, reconnects: 0 });
        let stats = feed.stats();
        assert_eq!((stats.states, stats.disconnects, stats.state_gap.count), (2, 1, 2));
        assert_eq!(feed.connection(), Connection::Disconnected);
        assert_eq!(feed.latest().map(|s| s.state), Some(2), "the last state stays; its age tells");
    }
}
