//! [`SplineClient`]: the motion controller's side of `/spline_shm`.

use std::time::Duration;

use robowire_rt::Time;

use robowire_shm::{MappedRegion, RegionError, SharedRegion, ShmError};
use robowire_tap::{Direction, Tap};
use zsl_proto::shm::{
    ConsumerIndex, JointIndex, Leg, SPLINE_COMMAND, SPLINE_DATA_LEN, SplineCommandBlock, SplineStateBlock,
};
use zsl_proto::zerocopy::{FromZeros, IntoBytes};

/// Default: no fresh state for this long means the daemon is stalled.
pub const DEFAULT_STALL_AFTER: Duration = Duration::from_millis(10);

/// Errors of the spline client.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SplineError {
    /// The spline object does not exist: no daemon has created it.
    #[error("spline daemon not running (no {name})")]
    DaemonNotRunning {
        /// The object's name.
        name: String,
    },
    /// The object could not be opened (permissions, size).
    #[error(transparent)]
    Shm(#[from] ShmError),
    /// An access was refused (a region too small for the layout).
    #[error(transparent)]
    Region(#[from] RegionError),
    /// A command value is NaN or infinite; nothing was written.
    #[error("command for {leg:?} {joint:?} has a non-finite {field}")]
    NonFinite {
        /// Leg.
        leg: Leg,
        /// Joint.
        joint: JointIndex,
        /// `p_des`, `v_des`, `kp`, `kd` or `t_ff`.
        field: &'static str,
    },
    /// No fresh state for longer than the stall bound.
    #[error("spline daemon stalled: no fresh state for {stalled_for:?}")]
    DaemonStalled {
        /// Time since the last fresh state.
        stalled_for: Duration,
    },
    /// No fresh state within the caller's timeout (shorter than the stall bound).
    #[error("no fresh state within {timeout:?}")]
    Timeout {
        /// The timeout.
        timeout: Duration,
    },
    /// A monitor's thread could not be started.
    #[error("the monitor's thread")]
    Thread(#[from] robowire_rt::RtError),
}

const FIELD_NAMES: [&str; 5] = ["p_des", "v_des", "kp", "kd", "t_ff"];

/// The four consumer flags, as a monitor sees them (1: raised).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SplineFlags {
    /// `cmd.consumer_flags[CONTROL]`: a command waits for the daemon.
    pub command_control: u32,
    /// `cmd.consumer_flags[OTHER]` (never written by robowire).
    pub command_other: u32,
    /// `state.consumer_flags[CONTROL]`: a fresh state waits for the controller.
    pub state_control: u32,
    /// `state.consumer_flags[OTHER]`: a fresh state waits for monitors.
    pub state_other: u32,
}

/// What a [`SplineClient`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SplineClientCounters {
    /// Commands written (flag raised).
    pub commands_written: u64,
    /// Fresh states read (flag cleared).
    pub states_read: u64,
    /// Times the daemon was found stalled.
    pub stalls: u64,
}

/// The motion controller's side of `/spline_shm`: write commands, read fresh state.
///
/// Commands are written as a whole (all 4 legs × 4 joints, `flags = 1`) and published with the
/// control flag (release). Fresh state is the state block after the reader's consumer flag was
/// found set (acquire); the flag is cleared after the copy. A copied state may still mix two
/// daemon cycles: the vendor layout has no sequence counter (spec §6.3).
#[derive(Debug)]
pub struct SplineClient<R: SharedRegion = MappedRegion> {
    region: R,
    consumer: ConsumerIndex,
    stall_after: Duration,
    /// The first poll that found no fresh state since the last fresh one: the stall clock runs
    /// from here. Stamped once per gap, so the fresh path never reads the clock.
    waiting_since: Option<Time>,
    stalled: bool,
    counters: SplineClientCounters,
    tap: Option<Tap>,
}

impl SplineClient<MappedRegion> {
    /// Opens the daemon's object (never creates it): "spline daemon not running" if absent.
    pub fn open(name: &str) -> Result<Self, SplineError> {
        match MappedRegion::open(name, SPLINE_DATA_LEN) {
            Ok(region) => Self::new(region),
            Err(ShmError::NotFound { name }) => Err(SplineError::DaemonNotRunning { name }),
            Err(e) => Err(e.into()),
        }
    }
}

impl<R: SharedRegion> SplineClient<R> {
    /// A client on `region` (at least 608 bytes), consuming as the motion controller.
    pub fn new(region: R) -> Result<Self, SplineError> {
        region.check_fits(SPLINE_DATA_LEN)?;
        Ok(Self {
            region,
            consumer: ConsumerIndex::Control,
            stall_after: DEFAULT_STALL_AFTER,
            waiting_since: None,
            stalled: false,
            counters: SplineClientCounters::default(),
            tap: None,
        })
    }

    /// Hands each command published (sent: its 336 bytes of legs, as written) and each fresh
    /// state taken (received: its 256 bytes of legs, as copied out) to `tap`, a link described by
    /// `zsl_proto::description::SPLINE_CLIENT`. A copy into the tap's ring: no allocation, no
    /// lock, no clock but the monotonic one.
    #[must_use]
    pub fn with_tap(mut self, tap: Tap) -> Self {
        self.tap = Some(tap);
        self
    }

    /// Reads state as another consumer (a monitor): uses `consumer_flags[OTHER]`, so the
    /// controller's fresh-state flag is left alone.
    #[must_use]
    pub fn with_consumer(mut self, consumer: ConsumerIndex) -> Self {
        self.consumer = consumer;
        self
    }

    /// Sets the stall bound (default 10 ms).
    #[must_use]
    pub fn with_stall_after(mut self, stall_after: Duration) -> Self {
        self.stall_after = stall_after;
        self
    }

    /// Bytes mapped (the whole object).
    pub fn mapped_len(&self) -> usize {
        self.region.len()
    }

    /// The four consumer flags, without touching them.
    pub fn flags(&self) -> Result<SplineFlags, SplineError> {
        let flag = |block| self.region.is_raised(block).map(u32::from);
        Ok(SplineFlags {
            command_control: flag(&ConsumerIndex::Control.command())?,
            command_other: flag(&ConsumerIndex::Other.command())?,
            state_control: flag(&ConsumerIndex::Control.state())?,
            state_other: flag(&ConsumerIndex::Other.state())?,
        })
    }

    /// Writes all four legs (each leg's `flags` word as 1, spec decision 7) and raises the
    /// control flag. NaN and infinities are refused and nothing is written.
    pub fn write_command(&mut self, command: &SplineCommandBlock) -> Result<(), SplineError> {
        if let Some((leg, joint, field)) = command.first_non_finite() {
            return Err(SplineError::NonFinite { leg, joint, field: FIELD_NAMES[field] });
        }
        let legs = command.normalized().legs;
        self.region.publish(&[SPLINE_COMMAND], legs.as_bytes())?;
        self.counters.commands_written += 1;
        if let Some(tap) = &self.tap {
            tap.record(Direction::Sent, legs.as_bytes());
        }
        Ok(())
    }

    /// The state, if the daemon published one since the last read.
    pub fn try_read_state(&mut self) -> Result<Option<SplineStateBlock>, SplineError> {
        self.take_state(robowire_rt::now)
    }

    /// The state if the daemon published one since the last read; else, at `now` on the
    /// monotonic clock, whether the daemon just crossed the stall bound (no fresh state for
    /// `stall_after`, counted from the first poll that found none): then
    /// [`SplineError::DaemonStalled`], once per stall. The sans-IO core of
    /// [`wait_state`](Self::wait_state), for a loop that keeps its own time.
    pub fn poll_state(&mut self, now: Time) -> Result<Option<SplineStateBlock>, SplineError> {
        if let Some(state) = self.take_state(|| now)? {
            return Ok(Some(state));
        }
        let since_fresh = self.stalled_for(now);
        if since_fresh >= self.stall_after && !self.stalled {
            self.stalled = true;
            self.counters.stalls += 1;
            return Err(SplineError::DaemonStalled { stalled_for: since_fresh });
        }
        Ok(None)
    }

    /// Takes fresh state; without any, starts the stall clock at `now()` (read only then, so the
    /// fresh path never reads the clock).
    fn take_state(&mut self, now: impl FnOnce() -> Time) -> Result<Option<SplineStateBlock>, SplineError> {
        let mut state = SplineStateBlock::new_zeroed();
        if !self.region.take(&self.consumer.state(), state.legs.as_mut_bytes())? {
            if self.waiting_since.is_none() {
                self.waiting_since = Some(now());
            }
            return Ok(None);
        }
        self.counters.states_read += 1;
        if let Some(tap) = &self.tap {
            tap.record(Direction::Received, state.legs.as_bytes());
        }
        self.waiting_since = None;
        self.stalled = false;
        Ok(Some(state))
    }

    fn stalled_for(&self, now: Time) -> Duration {
        self.waiting_since.map_or(Duration::ZERO, |t| now.saturating_duration_since(t))
    }

    /// Waits for fresh state: spins briefly, then sleeps in short steps.
    ///
    /// Crossing the stall bound returns [`SplineError::DaemonStalled`] at once, the first time
    /// ([`poll_state`](Self::poll_state)). While stalled, a call waits up to `timeout` for the
    /// daemon to come back and returns `DaemonStalled` again if it does not. A healthy daemon
    /// that is merely slower than `timeout` gives [`SplineError::Timeout`].
    pub fn wait_state(&mut self, timeout: Duration) -> Result<SplineStateBlock, SplineError> {
        let start = robowire_rt::now();
        loop {
            let now = robowire_rt::now();
            if let Some(state) = self.poll_state(now)? {
                return Ok(state);
            }
            let waited = now.saturating_duration_since(start);
            if waited >= timeout {
                return Err(if self.stalled {
                    SplineError::DaemonStalled { stalled_for: self.stalled_for(now) }
                } else {
                    SplineError::Timeout { timeout }
                });
            }
            if waited < Duration::from_micros(50) {
                std::hint::spin_loop();
            } else {
                std::thread::sleep(Duration::from_micros(20));
            }
        }
    }

    /// Polled for longer than the stall bound without fresh state, at `now`?
    pub fn is_stalled_at(&self, now: Time) -> bool {
        self.waiting_since.is_some() && self.stalled_for(now) >= self.stall_after
    }

    /// Polled for longer than the stall bound without fresh state?
    pub fn is_stalled(&self) -> bool {
        self.is_stalled_at(robowire_rt::now())
    }

    /// Counters.
    pub fn counters(&self) -> SplineClientCounters {
        self.counters
    }
}
