//! The low-level command stream of a Unitree robot, sans-IO: the latched `LowCmd`, sent every
//! 2 ms on absolute deadlines once the first command is set; replaced by damping when it is
//! older than the command timeout ([`robot`](crate::robot)); damping at once on
//! [`damp`](CommandStream::damp). Missed ticks follow `robowire-core`'s policy: skipped and
//! counted, never caught up. The state side's watchdog is `robowire_core::schedule::Watchdog`.
//!
//! ```
//! use core::time::Duration;
//! use unitree_proto::robot::Go2;
//! use unitree_proto::stream::{CommandStream, StreamConfig};
//! use unitree_proto::LowCmd;
//! use robowire_core::schedule::Time;
//!
//! let t0 = Time::from_nanos(1_000_000_000);
//! let mut stream = CommandStream::<Go2>::new(t0, StreamConfig::default());
//! assert_eq!(stream.poll_timeout(), None, "nothing is sent before the first command");
//! stream.handle_command(t0, LowCmd::default()).unwrap();
//! let first = stream.poll_transmit(t0).unwrap();
//! assert!(first.fresh);
//! // 100 ms without a new command: damping.
//! let stale = stream.poll_transmit(t0 + Duration::from_millis(102)).unwrap();
//! assert!(!stale.fresh);
//! assert_eq!(stale.command.motor_cmd[0].kp.get(), 0.0);
//! ```

use core::time::Duration;

use robowire_core::schedule::{Periodic, Tick, Time};

use crate::robot::{CommandError, DAMPING_KD, Robot};

/// The stream's timing and damping.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StreamConfig {
    /// Command period. Unitree's examples: 2 ms (500 Hz).
    pub period: Duration,
    /// A command older than this is replaced by damping. Default 100 ms (50 periods).
    pub command_timeout: Duration,
    /// kd of the damping command. Default [`DAMPING_KD`].
    pub damping_kd: f32,
}

/// The default command timeout.
pub const COMMAND_TIMEOUT: Duration = Duration::from_millis(100);
/// The default command period.
pub const COMMAND_PERIOD: Duration = Duration::from_millis(2);

impl Default for StreamConfig {
    fn default() -> Self {
        Self { period: COMMAND_PERIOD, command_timeout: COMMAND_TIMEOUT, damping_kd: DAMPING_KD }
    }
}

/// A command to send now.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transmit<C> {
    /// The command (sealed by the encoder when it is written).
    pub command: C,
    /// The latched command (`true`) or damping (`false`).
    pub fresh: bool,
    /// The tick it is sent for.
    pub tick: Tick,
}

/// What the stream has sent and refused.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StreamCounters {
    /// Commands sent (fresh and damping).
    pub sent: u64,
    /// Of those, damping.
    pub damping: u64,
    /// Times a fresh command went stale.
    pub command_timeouts: u64,
    /// Commands refused by the robot's rules.
    pub refused: u64,
    /// Slots skipped because a tick was served more than a period late.
    pub missed_ticks: u64,
}

/// The stream; see the [module](self).
#[derive(Debug, Clone)]
pub struct CommandStream<R: Robot> {
    config: StreamConfig,
    /// Starts at the first command.
    grid: Option<Periodic>,
    latched: Option<(Time, R::Cmd)>,
    damping: Option<R::Cmd>,
    /// Damping until the next command, whatever its age ([`damp`](Self::damp)).
    damp_now: bool,
    was_fresh: bool,
    counters: StreamCounters,
}

impl<R: Robot> CommandStream<R> {
    /// A stream that sends nothing until its first command. `now` is unused beyond the type
    /// (the grid starts at the first command).
    pub fn new(now: Time, config: StreamConfig) -> Self {
        let _ = now;
        Self {
            config,
            grid: None,
            latched: None,
            damping: None,
            damp_now: false,
            was_fresh: false,
            counters: StreamCounters::default(),
        }
    }

    /// The configuration.
    pub fn config(&self) -> &StreamConfig {
        &self.config
    }

    /// Latches `command`, set at `set_at`, if the robot's rules allow it; otherwise nothing
    /// changes. The first command starts the grid at `set_at`.
    pub fn handle_command(&mut self, set_at: Time, command: R::Cmd) -> Result<(), CommandError> {
        if let Err(e) = R::check(&command) {
            self.counters.refused += 1;
            return Err(e);
        }
        self.grid.get_or_insert_with(|| Periodic::new(set_at, self.config.period));
        self.latched = Some((set_at, command));
        self.damping = None;
        self.damp_now = false;
        Ok(())
    }

    /// Damping from the next tick on, until the next command.
    pub fn damp(&mut self, now: Time) {
        self.grid.get_or_insert_with(|| Periodic::new(now, self.config.period));
        self.damp_now = true;
    }

    /// Whether the latched command is fresh at `now` (set within the command timeout, or after
    /// `now`: by another thread after the stream read its clock).
    pub fn is_fresh(&self, now: Time) -> bool {
        !self.damp_now
            && self
                .latched
                .as_ref()
                .is_some_and(|(at, _)| now.saturating_duration_since(*at) <= self.config.command_timeout)
    }

    /// When to call [`poll_transmit`](Self::poll_transmit) next; `None` before the first
    /// command (and [`damp`](Self::damp)).
    pub fn poll_timeout(&self) -> Option<Time> {
        self.grid.as_ref().map(Periodic::deadline)
    }

    /// The command due at `now`, if a tick is due.
    pub fn poll_transmit(&mut self, now: Time) -> Option<Transmit<R::Cmd>> {
        let tick = self.grid.as_mut()?.poll(now)?;
        self.counters.missed_ticks += tick.skipped;
        let fresh = self.is_fresh(now);
        let command = if fresh {
            self.latched.as_ref().map(|(_, c)| *c)?
        } else {
            if self.was_fresh {
                self.counters.command_timeouts += u64::from(!self.damp_now);
            }
            let last = self.latched.as_ref().map(|(_, c)| *c).unwrap_or_default();
            *self.damping.get_or_insert_with(|| R::damping(&last, self.config.damping_kd))
        };
        self.was_fresh = fresh;
        self.counters.sent += 1;
        self.counters.damping += u64::from(!fresh);
        Some(Transmit { command, fresh, tick })
    }

    /// The latched command and when it was set.
    pub fn latched(&self) -> Option<&(Time, R::Cmd)> {
        self.latched.as_ref()
    }

    /// What the stream has done.
    pub fn counters(&self) -> StreamCounters {
        self.counters
    }
}
