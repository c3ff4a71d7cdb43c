//! Periodic schedules with caller-supplied time: the sans-IO part of every periodic stream
//! (a command stream, its polls, a watchdog: [`Watchdog`]). Nothing here reads a clock or sleeps; a runner
//! asks for the next deadline, sleeps until then, and hands `now` back.
//!
//! **Missed-tick policy.** A [`Periodic`] keeps the absolute grid `first + k · period`. Served
//! late by less than a period, the tick counts as on time (its lateness is reported); later than
//! that, the slots that passed are skipped and counted, and the next deadline is the next slot
//! of the grid after `now`. A late stream never sends a burst of catch-up frames, and never
//! drifts.
//!
//! ```
//! use core::time::Duration;
//! use robowire_core::schedule::{Periodic, Time};
//!
//! let start = Time::from_nanos(1_000_000);
//! let mut control = Periodic::new(start, Duration::from_millis(10));
//! assert_eq!(control.poll(start).map(|t| t.lateness), Some(Duration::ZERO));
//! assert_eq!(control.deadline(), start + Duration::from_millis(10));
//! assert!(control.poll(start + Duration::from_millis(5)).is_none(), "not due yet");
//! // 35 ms later than the deadline: the tick runs once, three slots are skipped.
//! let tick = control.poll(start + Duration::from_millis(45)).unwrap();
//! assert_eq!((tick.lateness, tick.skipped), (Duration::from_millis(35), 3));
//! assert_eq!(control.deadline(), start + Duration::from_millis(50), "still on the grid");
//! assert_eq!((control.ticks(), control.missed()), (2, 3));
//! ```

use core::ops::{Add, Sub};
use core::time::Duration;

/// A point on the caller's monotonic clock, ns from an arbitrary epoch (on Linux,
/// `CLOCK_MONOTONIC`). Tests use any epoch they like: a fake clock is a counter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct Time(u64);

impl Time {
    /// The epoch itself.
    pub const ZERO: Self = Self(0);

    /// `ns` nanoseconds after the epoch.
    pub const fn from_nanos(ns: u64) -> Self {
        Self(ns)
    }

    /// Nanoseconds after the epoch.
    pub const fn as_nanos(self) -> u64 {
        self.0
    }

    /// Time from `earlier` to `self`, zero if `earlier` is later.
    pub const fn saturating_duration_since(self, earlier: Time) -> Duration {
        Duration::from_nanos(self.0.saturating_sub(earlier.0))
    }
}

fn nanos(d: Duration) -> u64 {
    u64::try_from(d.as_nanos()).unwrap_or(u64::MAX)
}

impl Add<Duration> for Time {
    type Output = Time;
    /// Saturates at the end of time rather than overflowing.
    fn add(self, d: Duration) -> Time {
        Time(self.0.saturating_add(nanos(d)))
    }
}

impl Sub<Duration> for Time {
    type Output = Time;
    /// Saturates at the epoch.
    fn sub(self, d: Duration) -> Time {
        Time(self.0.saturating_sub(nanos(d)))
    }
}

/// A tick a [`Periodic`] found due.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Tick {
    /// The deadline this tick was due at.
    pub deadline: Time,
    /// How late it is served: `now − deadline`.
    pub lateness: Duration,
    /// Slots of the grid that passed unserved before this one (0 on time).
    pub skipped: u64,
}

/// An absolute deadline grid, `first + k · period`, with the missed-tick policy of the
/// [module](self): skip and count, never catch up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Periodic {
    next: Time,
    period: Duration,
    ticks: u64,
    missed: u64,
}

impl Periodic {
    /// A grid whose first tick is due at `first`. A zero period is taken as 1 ns.
    pub fn new(first: Time, period: Duration) -> Self {
        Self { next: first, period: period.max(Duration::from_nanos(1)), ticks: 0, missed: 0 }
    }

    /// The grid at `hz` ticks per second (`None` unless finite and positive).
    pub fn at_rate(first: Time, hz: f64) -> Option<Self> {
        (hz.is_finite() && hz > 0.0).then(|| Self::new(first, Duration::from_secs_f64(1.0 / hz)))
    }

    /// When the next tick is due.
    pub fn deadline(&self) -> Time {
        self.next
    }

    /// The period.
    pub fn period(&self) -> Duration {
        self.period
    }

    /// The tick due at `now`, if one is, and the grid moved past `now`.
    pub fn poll(&mut self, now: Time) -> Option<Tick> {
        if now < self.next {
            return None;
        }
        let deadline = self.next;
        let behind = nanos(now.saturating_duration_since(deadline));
        let period = nanos(self.period);
        let skipped = behind / period;
        self.next = deadline + Duration::from_nanos(period.saturating_mul(skipped.saturating_add(1)));
        self.ticks += 1;
        self.missed += skipped;
        Some(Tick { deadline, lateness: now.saturating_duration_since(deadline), skipped })
    }

    /// Starts the grid again at `first` (after a reconnect, say); the counters stay.
    pub fn restart(&mut self, first: Time) {
        self.next = first;
    }

    /// Ticks served.
    pub fn ticks(&self) -> u64 {
        self.ticks
    }

    /// Slots skipped because a tick was served more than a period late.
    pub fn missed(&self) -> u64 {
        self.missed
    }
}

/// The earliest of some deadlines, if any.
pub fn earliest(deadlines: impl IntoIterator<Item = Option<Time>>) -> Option<Time> {
    deadlines.into_iter().flatten().min()
}

/// The connection as the watchdog sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Connection {
    /// Nothing heard yet since the start.
    Waiting,
    /// Heard from within the watchdog timeout.
    Connected,
    /// Nothing for the watchdog timeout; the next sign of life reconnects.
    Disconnected,
}

impl Connection {
    /// `"waiting"`, `"connected"` or `"disconnected"`: as status lines, JSON and Python say it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Waiting => "waiting",
            Self::Connected => "connected",
            Self::Disconnected => "disconnected",
        }
    }
}

/// A change of the connection.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Event {
    /// The first sign of life.
    Connected,
    /// The watchdog expired.
    Disconnected,
    /// A sign of life again after a disconnect.
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

/// A watchdog on a peer: any sign of life re-arms it; silence for the timeout disconnects; the
/// next sign of life reconnects. Sans-IO: the caller hands it time.
///
/// ```
/// use core::time::Duration;
/// use robowire_core::schedule::{Event, Time, Watchdog};
///
/// let t0 = Time::from_nanos(1_000_000_000);
/// let mut watchdog = Watchdog::new(t0, Duration::from_secs(3));
/// assert_eq!(watchdog.feed(t0 + Duration::from_millis(2)), Some(Event::Connected));
/// assert_eq!(watchdog.poll_timeout(), Some(t0 + Duration::from_millis(3002)));
/// assert_eq!(watchdog.poll_event(t0 + Duration::from_secs(4)), Some(Event::Disconnected));
/// assert_eq!(watchdog.feed(t0 + Duration::from_secs(9)), Some(Event::Reconnected));
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
        Self::waiting_until(now + timeout, timeout)
    }

    /// Waiting for a first sign of life until `first_deadline` (a peer that takes longer to
    /// appear than to fall silent: DDS discovery), then `timeout` between signs of life.
    pub fn waiting_until(first_deadline: Time, timeout: Duration) -> Self {
        Self {
            timeout,
            deadline: Some(first_deadline),
            connection: Connection::Waiting,
            counters: WatchdogCounters::default(),
        }
    }

    /// A sign of life at `now` (a datagram, a sample): re-arms the watchdog; the connection
    /// event, if any.
    pub fn feed(&mut self, now: Time) -> Option<Event> {
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

#[cfg(test)]
mod tests {
    use super::*;

    const MS: Duration = Duration::from_millis(1);

    #[test]
    fn on_time_ticks_stay_on_the_grid_and_late_ones_do_not_drift() {
        let t0 = Time::from_nanos(5);
        let mut p = Periodic::new(t0, 2 * MS);
        for k in 0..5u32 {
            // Each tick 300 µs late: the grid does not move.
            let now = t0 + 2 * MS * k + Duration::from_micros(300);
            let tick = p.poll(now).unwrap();
            assert_eq!((tick.deadline, tick.skipped), (t0 + 2 * MS * k, 0));
            assert!(p.poll(now).is_none(), "one tick per slot");
        }
        assert_eq!((p.ticks(), p.missed()), (5, 0));
    }

    #[test]
    fn exactly_one_period_late_skips_one_slot() {
        let mut p = Periodic::new(Time::ZERO, 10 * MS);
        let tick = p.poll(Time::ZERO + 10 * MS).unwrap();
        assert_eq!((tick.deadline, tick.skipped), (Time::ZERO, 1));
        assert_eq!(p.deadline(), Time::ZERO + 20 * MS);
        assert!(p.poll(Time::ZERO + 19 * MS).is_none());
    }

    #[test]
    fn rates_and_edges() {
        assert!(Periodic::at_rate(Time::ZERO, 0.0).is_none());
        assert!(Periodic::at_rate(Time::ZERO, f64::NAN).is_none());
        assert_eq!(Periodic::at_rate(Time::ZERO, 100.0).map(|p| p.period()), Some(10 * MS));
        assert_eq!(Periodic::new(Time::ZERO, Duration::ZERO).period(), Duration::from_nanos(1));
        assert_eq!(Time::from_nanos(u64::MAX) + MS, Time::from_nanos(u64::MAX), "saturates");
        assert_eq!(Time::ZERO - MS, Time::ZERO);
        assert_eq!(earliest([None, Some(Time::from_nanos(7)), Some(Time::from_nanos(3))]), Some(Time::from_nanos(3)));
        assert_eq!(earliest([None]), None);
    }
}
