//! The low-level command stream of a Unitree robot, sans-IO: the latched `LowCmd`, sent every
//! 2 ms on absolute deadlines once the first command is set; replaced by damping when it is
//! older than the command timeout ([`robot`](crate::robot)); damping at once on
//! [`damp`](CommandStream::damp). Missed ticks follow `robowire-core`'s policy: skipped and
//! counted, never caught up. The state side's watchdog is `robowire_core::schedule::Watchdog`.
//!
//! A [`Motion`] is stepped on the stream's own grid ([`follow`](CommandStream::follow)): each
//! tick sends the motion's command at that tick's slot, counted from the motion's first tick,
//! and from its end on its final command, held; it never goes stale (it is the stream's own
//! command). A newer command or motion replaces it, [`damp`](CommandStream::damp) ends it.
//!
//! ```
//! use core::time::Duration;
//! use unitree_proto::robot::Go2;
//! use unitree_proto::stream::{CommandStream, MotionState, StreamConfig, Transmit, from_fn};
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
//!
//! // A motion instead: a hip's target moves 0.1 rad per tick, on the stream's grid.
//! let mut stream = CommandStream::<Go2, _>::new(t0, StreamConfig::default());
//! let step = |elapsed: Duration| {
//!     let mut cmd = LowCmd::default();
//!     cmd.motor_cmd[0] = unitree_proto::MotorCmd::servo(elapsed.as_millis() as f32 / 20.0, 0.0, 10.0, 1.0, 0.0);
//!     cmd
//! };
//! stream.follow(t0, from_fn(Duration::from_millis(4), step));
//! let q = |t: Transmit<LowCmd>| t.command.motor_cmd[0].q.get();
//! assert_eq!(stream.poll_transmit(t0).map(q), Some(0.0));
//! assert_eq!(stream.poll_transmit(t0 + Duration::from_millis(2)).map(q), Some(0.1));
//! assert_eq!(stream.poll_transmit(t0 + Duration::from_millis(4)).map(q), Some(0.2));
//! assert_eq!(stream.motion().map(|(_, state)| state), Some(MotionState::Reached));
//! // Its final command, held: never stale.
//! assert_eq!(stream.poll_transmit(t0 + Duration::from_secs(1)).map(q), Some(0.2));
//! ```

use core::fmt;
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
    /// The latched command or a motion's step (`true`), or damping (`false`).
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
    /// Commands (and motions' steps) refused by the robot's rules.
    pub refused: u64,
    /// Slots skipped because a tick was served more than a period late.
    pub missed_ticks: u64,
}

/// A motion the stream steps on its own grid ([`CommandStream::follow`]): the command at
/// `elapsed`, the time from the motion's first tick to the slot being sent. The stream asks at
/// its slots only (0, one period, two, …) while they are before [`duration`](Self::duration),
/// then at `duration` for good: the final command is held. Meant as a pure function of
/// `elapsed`, so that a caller can check steps before handing the motion over.
pub trait Motion<C> {
    /// The command at `elapsed`, or why there is none (the stream then damps).
    fn command_at(&self, elapsed: Duration) -> Result<C, CommandError>;

    /// How long the motion lasts.
    fn duration(&self) -> Duration;
}

/// A [`Motion`] made of a function of the elapsed time: [`from_fn`].
#[derive(Clone, Copy)]
pub struct FromFn<F> {
    duration: Duration,
    f: F,
}

impl<F> fmt::Debug for FromFn<F> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("FromFn").field("duration", &self.duration).finish_non_exhaustive()
    }
}

impl<C, F: Fn(Duration) -> C> Motion<C> for FromFn<F> {
    fn command_at(&self, elapsed: Duration) -> Result<C, CommandError> {
        Ok((self.f)(elapsed))
    }

    fn duration(&self) -> Duration {
        self.duration
    }
}

/// A motion of `duration` whose command at `elapsed` is `f(elapsed)`.
pub fn from_fn<C, F: Fn(Duration) -> C>(duration: Duration, f: F) -> FromFn<F> {
    FromFn { duration, f }
}

/// No motion: the motion type of a stream that never follows one (the default).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoMotion {}

impl<C> Motion<C> for NoMotion {
    fn command_at(&self, _: Duration) -> Result<C, CommandError> {
        match *self {}
    }

    fn duration(&self) -> Duration {
        match *self {}
    }
}

/// Where a followed motion is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MotionState {
    /// Handed over; its first step goes out at the next tick.
    Pending,
    /// Its step at `elapsed` went out last.
    Moving {
        /// From its first tick to the slot of that step.
        elapsed: Duration,
    },
    /// Its last step (at its duration) went out: the stream holds its final command until the
    /// next command, motion or damping.
    Reached,
    /// A newer command or motion took over.
    Replaced,
    /// Damping ended it ([`CommandStream::damp`]).
    Damped,
    /// The robot's rules refused a step: damping from that tick on, until the next command or
    /// motion.
    Refused(CommandError),
}

impl MotionState {
    /// Whether the stream still sends the motion's commands (pending, moving, reached).
    pub fn is_followed(self) -> bool {
        matches!(self, Self::Pending | Self::Moving { .. } | Self::Reached)
    }
}

impl fmt::Display for MotionState {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Pending => f.write_str("not started"),
            Self::Moving { elapsed } => write!(f, "moving, {:.3} s in", elapsed.as_secs_f64()),
            Self::Reached => f.write_str("at its end, holding its final command"),
            Self::Replaced => f.write_str("replaced by a newer command or motion"),
            Self::Damped => f.write_str("ended by damping"),
            Self::Refused(e) => write!(f, "a step refused ({e}); damping"),
        }
    }
}

/// A motion the stream follows (or followed), and where it is.
#[derive(Debug, Clone)]
struct Followed<M> {
    motion: M,
    /// The slot of its first step.
    began: Option<Time>,
    state: MotionState,
}

/// The stream; see the [module](self). `M`: the motions it can follow ([`NoMotion`]: none).
#[derive(Debug, Clone)]
pub struct CommandStream<R: Robot, M = NoMotion> {
    config: StreamConfig,
    /// Starts at the first command.
    grid: Option<Periodic>,
    /// The caller's command, or the motion's last step, and when it was set (for a step: its
    /// slot).
    latched: Option<(Time, R::Cmd)>,
    damping: Option<R::Cmd>,
    /// Damping until the next command, whatever its age ([`damp`](Self::damp)).
    damp_now: bool,
    was_fresh: bool,
    /// Kept until the next motion replaces it: the stream never drops a motion it was handed
    /// while it runs (a caller whose motions hold memory frees them on its own thread).
    motion: Option<Followed<M>>,
    counters: StreamCounters,
}

impl<R: Robot, M: Motion<R::Cmd>> CommandStream<R, M> {
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
            motion: None,
            counters: StreamCounters::default(),
        }
    }

    /// The configuration.
    pub fn config(&self) -> &StreamConfig {
        &self.config
    }

    /// Latches `command`, set at `set_at`, if the robot's rules allow it; otherwise nothing
    /// changes. The first command starts the grid at `set_at`. It replaces a motion being
    /// followed.
    pub fn handle_command(&mut self, set_at: Time, command: R::Cmd) -> Result<(), CommandError> {
        if let Err(e) = R::check(&command) {
            self.counters.refused += 1;
            return Err(e);
        }
        self.grid.get_or_insert_with(|| Periodic::new(set_at, self.config.period));
        self.latched = Some((set_at, command));
        self.damping = None;
        self.damp_now = false;
        self.end_motion(MotionState::Replaced);
        Ok(())
    }

    /// Follows `motion`, handed over at `at`, from the next tick on: each tick sends its command
    /// at the tick's slot (the latest grid slot at or before `now`) minus the slot of its first
    /// tick, up to its duration; from then on its command at its duration, fresh whatever its
    /// age, until the next command, motion or damping. Each step is checked by the robot's
    /// rules; a refused one ends the motion in damping ([`MotionState::Refused`]). The first
    /// motion or command starts the grid at `at`. Returns the motion this one replaces, with
    /// what became of it, for the caller to drop.
    pub fn follow(&mut self, at: Time, motion: M) -> Option<(M, MotionState)> {
        self.grid.get_or_insert_with(|| Periodic::new(at, self.config.period));
        self.damp_now = false;
        self.end_motion(MotionState::Replaced);
        let followed = Followed { motion, began: None, state: MotionState::Pending };
        self.motion.replace(followed).map(|f| (f.motion, f.state))
    }

    /// Damping from the next tick on, until the next command or motion; ends a motion.
    pub fn damp(&mut self, now: Time) {
        self.grid.get_or_insert_with(|| Periodic::new(now, self.config.period));
        self.damp_now = true;
        self.end_motion(MotionState::Damped);
    }

    fn end_motion(&mut self, how: MotionState) {
        if let Some(followed) = self.motion.as_mut().filter(|f| f.state.is_followed()) {
            followed.state = how;
        }
    }

    /// Whether the stream sends fresh commands at `now`: a motion is being followed, or the
    /// latched command was set within the command timeout (or after `now`: by another thread
    /// after the stream read its clock).
    pub fn is_fresh(&self, now: Time) -> bool {
        !self.damp_now && (self.is_following() || self.latched_is_fresh(now))
    }

    fn is_following(&self) -> bool {
        self.motion.as_ref().is_some_and(|f| f.state.is_followed())
    }

    fn latched_is_fresh(&self, now: Time) -> bool {
        self.latched.as_ref().is_some_and(|(at, _)| now.saturating_duration_since(*at) <= self.config.command_timeout)
    }

    /// When to call [`poll_transmit`](Self::poll_transmit) next; `None` before the first
    /// command (motion, or [`damp`](Self::damp)).
    pub fn poll_timeout(&self) -> Option<Time> {
        self.grid.as_ref().map(Periodic::deadline)
    }

    /// The command due at `now`, if a tick is due.
    pub fn poll_transmit(&mut self, now: Time) -> Option<Transmit<R::Cmd>> {
        let tick = self.grid.as_mut()?.poll(now)?;
        self.counters.missed_ticks += tick.skipped;
        let slot = tick.deadline + self.config.period.saturating_mul(u32::try_from(tick.skipped).unwrap_or(u32::MAX));
        if let Some(step) = self.step_motion(slot) {
            self.latched = Some((slot, step));
            self.damping = None;
        }
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

    /// The followed motion's command for `slot`, checked; `None` without one (or refused: the
    /// motion ends in damping).
    fn step_motion(&mut self, slot: Time) -> Option<R::Cmd> {
        let followed = self.motion.as_mut().filter(|f| f.state.is_followed())?;
        let began = *followed.began.get_or_insert(slot);
        let duration = followed.motion.duration();
        let elapsed = slot.saturating_duration_since(began).min(duration);
        match followed.motion.command_at(elapsed).and_then(|c| R::check(&c).map(|()| c)) {
            Ok(command) => {
                followed.state =
                    if elapsed >= duration { MotionState::Reached } else { MotionState::Moving { elapsed } };
                Some(command)
            }
            Err(e) => {
                followed.state = MotionState::Refused(e);
                self.counters.refused += 1;
                self.damp_now = true;
                None
            }
        }
    }

    /// The latched command (or the last step of a motion) and when it was set.
    pub fn latched(&self) -> Option<&(Time, R::Cmd)> {
        self.latched.as_ref()
    }

    /// The motion being (or last) followed, and where it is.
    pub fn motion(&self) -> Option<(&M, MotionState)> {
        self.motion.as_ref().map(|f| (&f.motion, f.state))
    }

    /// The slot of the followed motion's first step (`None` before it went out).
    pub fn motion_began(&self) -> Option<Time> {
        self.motion.as_ref().and_then(|f| f.began)
    }

    /// What the stream has done.
    pub fn counters(&self) -> StreamCounters {
        self.counters
    }
}
