//! The connection watchdog (spec §3.2, decision 3), sans-IO: any accepted datagram re-arms it;
//! silence for the timeout disconnects; the next datagram reconnects.

use core::time::Duration;

use robowire_core::schedule::Time;

/// The connection as the watchdog sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Connection {
    /// Nothing received yet since the start.
    Waiting,
    /// A datagram arrived within the watchdog timeout.
    Connected,
    /// Nothing for the watchdog timeout: the latched motion is stopped; the next datagram
    /// reconnects.
    Disconnected,
}

/// A change of the connection.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Event {
    /// The first datagram arrived.
    Connected,
    /// The watchdog expired: stop the latched motion ([`CommandStream::handle_disconnect`](super::CommandStream::handle_disconnect)).
    Disconnected,
    /// A datagram arrived again after a disconnect.
    Reconnected,
}

/// What the watchdog has seen.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct WatchdogCounters {
    /// Timeouts.
    pub disconnects: u64,
    /// Returns to `Connected` after a timeout.
    pub reconnects: u64,
}

/// The vendor's watchdog timeout: 3 s.
pub const WATCHDOG_TIMEOUT: Duration = Duration::from_secs(3);

/// The connection watchdog (spec §3.2, decision 3): any accepted datagram re-arms it; silence
/// for the timeout disconnects; the next datagram reconnects.
///
/// ```
/// use core::time::Duration;
/// use robowire_core::schedule::Time;
/// use zsl_proto::stream::{Event, Watchdog};
///
/// let t0 = Time::from_nanos(1_000_000_000);
/// let mut watchdog = Watchdog::new(t0, Duration::from_secs(3));
/// assert_eq!(watchdog.handle_datagram(t0 + Duration::from_millis(2)), Some(Event::Connected));
/// assert_eq!(watchdog.poll_timeout(), Some(t0 + Duration::from_millis(3002)));
/// assert_eq!(watchdog.poll_event(t0 + Duration::from_secs(4)), Some(Event::Disconnected));
/// assert_eq!(watchdog.handle_datagram(t0 + Duration::from_secs(9)), Some(Event::Reconnected));
/// ```
#[derive(Debug, Clone)]
pub struct Watchdog {
    timeout: Duration,
    /// When it expires; `None` while disconnected (nothing left to expire).
    deadline: Option<Time>,
    connection: Connection,
    counters: WatchdogCounters,
}

impl Watchdog {
    /// Started at `now`: it expires `timeout` from now if nothing ever arrives (like the
    /// vendor's).
    pub fn new(now: Time, timeout: Duration) -> Self {
        Self {
            timeout,
            deadline: Some(now + timeout),
            connection: Connection::Waiting,
            counters: WatchdogCounters::default(),
        }
    }

    /// A datagram was accepted at `now` (any length, 0 bytes included): re-arms the watchdog;
    /// the connection event, if any.
    pub fn handle_datagram(&mut self, now: Time) -> Option<Event> {
        self.deadline = Some(now + self.timeout);
        let event = match self.connection {
            Connection::Connected => None,
            Connection::Waiting => Some(Event::Connected),
            Connection::Disconnected => {
                self.counters.reconnects += 1;
                Some(Event::Reconnected)
            }
        };
        self.connection = Connection::Connected;
        event
    }

    /// [`Event::Disconnected`] if the watchdog has expired at `now` (once per silence).
    pub fn poll_event(&mut self, now: Time) -> Option<Event> {
        if self.deadline.is_none_or(|deadline| now < deadline) {
            return None;
        }
        self.deadline = None;
        self.connection = Connection::Disconnected;
        self.counters.disconnects += 1;
        Some(Event::Disconnected)
    }

    /// When it expires; `None` while disconnected.
    pub fn poll_timeout(&self) -> Option<Time> {
        self.deadline
    }

    /// The connection now.
    pub fn connection(&self) -> Connection {
        self.connection
    }

    /// What it has seen.
    pub fn counters(&self) -> WatchdogCounters {
        self.counters
    }
}
