//! The client's command stream (spec §3, §9; decisions 3 and 6), sans-IO: the latched command,
//! sent at once when a call changes it and again every 2 ms, with the vendor sender's
//! per-datagram rules; and the [`Watchdog`] that notices a silent robot.
//!
//! Neither reads a clock, sleeps or sends: a caller hands them calls, received states and
//! `now`, and takes the datagrams to send ([`CommandStream::poll_transmit`]) and the connection
//! events ([`Watchdog::poll_event`]). They are two machines because they run apart: the
//! stream wherever sends must be on time, the watchdog wherever datagrams arrive; a
//! [`Event::Disconnected`] of the watchdog is handed to the stream
//! ([`CommandStream::handle_disconnect`]), which stops the latched motion. What differs between
//! HighLevel and LowLevel is an [`Interface`].
//!
//! ```
//! use core::time::Duration;
//! use robowire_core::schedule::Time;
//! use zsl_proto::stream::{Cause, CommandStream, HighLevelInterface};
//! use zsl_proto::udp::HighLevelCommand;
//!
//! let t0 = Time::from_nanos(1_000_000_000);
//! let mut stream = CommandStream::<HighLevelInterface>::new(t0, Duration::from_millis(2));
//! // The idle command goes out at once, then every 2 ms.
//! assert_eq!(stream.poll_transmit(t0).map(|t| t.cause), Some(Cause::Call));
//! assert_eq!(stream.poll_timeout(), Some(t0 + Duration::from_millis(2)));
//! // A call is sent at once, not at the next tick.
//! stream.handle_call(HighLevelCommand::stand_up()).unwrap();
//! let now = t0 + Duration::from_micros(500);
//! assert_eq!(stream.poll_transmit(now).map(|t| t.command), Some(HighLevelCommand::stand_up()));
//! // The watchdog expired elsewhere: the motion stops.
//! stream.handle_call(HighLevelCommand::move_velocity(0.5, 0.0, 0.0)).unwrap();
//! stream.handle_disconnect();
//! assert_eq!(stream.latched().vx.get(), 0.0);
//! ```

mod interface;

use core::time::Duration;

use robowire_core::schedule::{Periodic, Tick, Time};

pub use interface::{HighLevelInterface, HighLevelObserved, Interface, LowLevelInterface};
pub use robowire_core::schedule::{Connection, Event, Watchdog, WatchdogCounters};

/// The vendor's watchdog timeout (spec §3.2): 3 s.
pub const WATCHDOG_TIMEOUT: Duration = Duration::from_secs(3);

/// The vendor's command period: 2 ms.
pub const COMMAND_PERIOD: Duration = Duration::from_millis(2);

/// Why a datagram goes out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cause {
    /// A call changed the command (or the stream just started): sent at once.
    Call,
    /// The periodic refresh.
    Refresh(Tick),
}

/// A command datagram to send now.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transmit<C> {
    /// The command, after the per-datagram rules.
    pub command: C,
    /// Why now.
    pub cause: Cause,
}

/// The robot raised "SDK mismatch": the stream stopped for good, as the vendor's does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Halted;

/// What the stream has sent.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StreamCounters {
    /// Datagrams sent because a call changed the command.
    pub calls: u64,
    /// Periodic refreshes.
    pub refreshes: u64,
    /// Refresh slots skipped because a tick was served more than a period late.
    pub missed_ticks: u64,
}

/// The client's command stream; see the [module](self).
#[derive(Debug, Clone)]
pub struct CommandStream<I: Interface> {
    refresh: Periodic,
    latched: I::Command,
    memory: I::Memory,
    observed: Option<I::Observed>,
    send_now: bool,
    halted: bool,
    counters: StreamCounters,
}

impl<I: Interface> CommandStream<I> {
    /// A stream started at `now`: the idle command goes out at once (like the vendor's), the
    /// refresh grid starts one `period` later.
    pub fn new(now: Time, period: Duration) -> Self {
        Self {
            refresh: Periodic::new(now + period, period),
            latched: I::Command::default(),
            memory: I::Memory::default(),
            observed: None,
            send_now: true,
            halted: false,
            counters: StreamCounters::default(),
        }
    }

    /// Latches `command`; it goes out at the next [`poll_transmit`](Self::poll_transmit), at
    /// once, and every period after. Refused once the stream halted.
    pub fn handle_call(&mut self, command: I::Command) -> Result<(), Halted> {
        if self.halted {
            return Err(Halted);
        }
        self.latched = command;
        self.send_now = true;
        Ok(())
    }

    /// The latest state the robot sent: what the per-datagram rules look at.
    pub fn handle_state(&mut self, state: &I::State) {
        self.observed = Some(I::observe(state));
    }

    /// The watchdog expired: the latched motion becomes a stop (spec decision 6), the state is
    /// forgotten. The stop keeps streaming.
    pub fn handle_disconnect(&mut self) {
        self.observed = None;
        I::stop_motion(&mut self.latched);
    }

    /// The datagram due at `now`, if any: the latched command at once after a call, or the
    /// refresh. The per-datagram rules run on it first; the robot's "SDK mismatch" halts the
    /// stream (nothing more is ever sent).
    pub fn poll_transmit(&mut self, now: Time) -> Option<Transmit<I::Command>> {
        if self.halted {
            return None;
        }
        let cause = if self.send_now {
            self.send_now = false;
            self.counters.calls += 1;
            Cause::Call
        } else {
            let tick = self.refresh.poll(now)?;
            self.counters.refreshes += 1;
            self.counters.missed_ticks += tick.skipped;
            Cause::Refresh(tick)
        };
        if !I::before_send(&mut self.latched, &mut self.memory, self.observed.as_ref()) {
            self.halted = true;
            return None;
        }
        Some(Transmit { command: self.latched, cause })
    }

    /// When to call [`poll_transmit`](Self::poll_transmit) next: the refresh deadline, or the
    /// epoch if a call waits; `None` once halted.
    pub fn poll_timeout(&self) -> Option<Time> {
        if self.halted {
            None
        } else if self.send_now {
            Some(Time::ZERO)
        } else {
            Some(self.refresh.deadline())
        }
    }

    /// The command being streamed.
    pub fn latched(&self) -> &I::Command {
        &self.latched
    }

    /// Whether the robot's "SDK mismatch" stopped the stream for good.
    pub fn is_halted(&self) -> bool {
        self.halted
    }

    /// What the stream has sent.
    pub fn counters(&self) -> StreamCounters {
        self.counters
    }
}
