//! The spline shared-memory interface (spec `spline-shm.md`): a controller's client, a daemon's
//! side, and the IMU record.

use std::sync::atomic::{Ordering, fence};
use std::time::{Duration, Instant};

use robowire_shm::{CreateOptions, MappedRegion, RegionError, SharedRegion, ShmError};
use zsl_proto::shm::{
    CMD_FLAG_CONTROL_OFFSET, CMD_LEGS_LEN, ConsumerIndex, IMU_SHM_SIZE, JointIndex, Leg, LegControl, NavImu,
    SPLINE_SHM_SIZE, STATE_FLAG_CONTROL_OFFSET, STATE_FLAG_OTHER_OFFSET, STATE_LEGS_LEN, STATE_OFFSET,
    SplineCommandBlock, SplineStateBlock,
};
use zsl_proto::zerocopy::{FromZeros, IntoBytes};

/// Bytes of `spline_data` a region must hold.
pub const SPLINE_DATA_LEN: usize = 608;
/// Bytes of `nav_imu` a region must hold.
pub const NAV_IMU_LEN: usize = 48;
/// Default: no fresh state for this long means the daemon is stalled.
pub const DEFAULT_STALL_AFTER: Duration = Duration::from_millis(10);
/// Default: the daemon clears the command after this many cycles without a fresh one.
pub const DEFAULT_CLEAR_AFTER_CYCLES: u32 = 10;

/// Errors of the spline client and daemon.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SplineError {
    /// The spline object does not exist: no daemon has created it.
    #[error("spline daemon not running (no {name})")]
    DaemonNotRunning {
        /// The object's name.
        name: String,
    },
    /// The object could not be opened or created.
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
}

/// Errors of the IMU reader.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ImuError {
    /// The IMU object does not exist: no producer has created it.
    #[error("IMU producer not running (no {name})")]
    ProducerNotRunning {
        /// The object's name.
        name: String,
    },
    /// The object could not be opened or created.
    #[error(transparent)]
    Shm(#[from] ShmError),
    /// An access was refused.
    #[error(transparent)]
    Region(#[from] RegionError),
    /// No sample published yet (timestamp 0).
    #[error("no IMU sample yet")]
    NoSample,
    /// The record changed during every read attempt.
    #[error("IMU record changed during each of {attempts} read attempts")]
    Torn {
        /// Attempts made.
        attempts: u32,
    },
}

const FIELD_NAMES: [&str; 5] = ["p_des", "v_des", "kp", "kd", "t_ff"];
/// Offset of `flags` in a `leg_control`.
const LEG_FLAGS_OFFSET: usize = std::mem::offset_of!(LegControl, flags);

fn check_len(region: &impl SharedRegion, needed: usize) -> Result<(), RegionError> {
    if region.len() < needed {
        Err(RegionError::OutOfBounds { offset: 0, len: needed, region_len: region.len() })
    } else {
        Ok(())
    }
}

/// Time on the monotonic clock, ns: the clock of robowire's IMU timestamps.
pub fn monotonic_ns() -> u64 {
    let t = rustix::time::clock_gettime(rustix::time::ClockId::Monotonic);
    (t.tv_sec as u64).saturating_mul(1_000_000_000).saturating_add(t.tv_nsec as u64)
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
    waiting_since: Option<Instant>,
    stalled: bool,
    counters: SplineClientCounters,
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
        check_len(&region, SPLINE_DATA_LEN)?;
        Ok(Self {
            region,
            consumer: ConsumerIndex::Control,
            stall_after: DEFAULT_STALL_AFTER,
            waiting_since: None,
            stalled: false,
            counters: SplineClientCounters::default(),
        })
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

    /// The region.
    pub fn region(&self) -> &R {
        &self.region
    }

    /// Writes all four legs and raises the control flag. NaN and infinities are refused and
    /// nothing is written.
    pub fn write_command(&mut self, command: &SplineCommandBlock) -> Result<(), SplineError> {
        if let Some((leg, joint, field)) = command.first_non_finite() {
            return Err(SplineError::NonFinite { leg, joint, field: FIELD_NAMES[field] });
        }
        // The legs as given, then each leg's `flags` word set to 1 (spec decision 7); nothing
        // is visible to the daemon before the control flag below.
        self.region.write(0, command.legs.as_bytes())?;
        for leg in 0..4 {
            self.region.store_u32(leg * size_of::<LegControl>() + LEG_FLAGS_OFFSET, 1, Ordering::Relaxed)?;
        }
        self.region.store_u32(CMD_FLAG_CONTROL_OFFSET, 1, Ordering::Release)?;
        self.counters.commands_written += 1;
        Ok(())
    }

    fn state_flag(&self) -> usize {
        match self.consumer {
            ConsumerIndex::Control => STATE_FLAG_CONTROL_OFFSET,
            ConsumerIndex::Other => STATE_FLAG_OTHER_OFFSET,
        }
    }

    /// The state, if the daemon published one since the last read.
    pub fn try_read_state(&mut self) -> Result<Option<SplineStateBlock>, SplineError> {
        if self.region.load_u32(self.state_flag(), Ordering::Acquire)? == 0 {
            if self.waiting_since.is_none() {
                self.waiting_since = Some(Instant::now());
            }
            return Ok(None);
        }
        let mut state = SplineStateBlock::new_zeroed();
        self.region.read(STATE_OFFSET, &mut state.as_mut_bytes()[..STATE_LEGS_LEN])?;
        self.region.store_u32(self.state_flag(), 0, Ordering::Release)?;
        self.counters.states_read += 1;
        self.waiting_since = None;
        self.stalled = false;
        Ok(Some(state))
    }

    /// Waits for fresh state: spins briefly, then sleeps in short steps.
    ///
    /// Crossing the stall bound (no fresh state for `stall_after` of polling, counted from the
    /// first poll that found none) returns
    /// [`SplineError::DaemonStalled`] at once, the first time. While stalled, a call waits up to
    /// `timeout` for the daemon to come back and returns `DaemonStalled` again if it does not.
    /// A healthy daemon that is merely slower than `timeout` gives [`SplineError::Timeout`].
    pub fn wait_state(&mut self, timeout: Duration) -> Result<SplineStateBlock, SplineError> {
        let start = Instant::now();
        loop {
            if let Some(state) = self.try_read_state()? {
                return Ok(state);
            }
            let now = Instant::now();
            let since_fresh = self.waiting_since.map_or(Duration::ZERO, |t| now.saturating_duration_since(t));
            if since_fresh >= self.stall_after && !self.stalled {
                self.stalled = true;
                self.counters.stalls += 1;
                return Err(SplineError::DaemonStalled { stalled_for: since_fresh });
            }
            let waited = now.saturating_duration_since(start);
            if waited >= timeout {
                return Err(if self.stalled {
                    SplineError::DaemonStalled { stalled_for: since_fresh }
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

    /// Polled for longer than the stall bound without fresh state?
    pub fn is_stalled(&self) -> bool {
        self.waiting_since.is_some_and(|t| t.elapsed() >= self.stall_after)
    }

    /// Counters.
    pub fn counters(&self) -> SplineClientCounters {
        self.counters
    }
}

/// What the daemon does with the command in a cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CommandUpdate {
    /// A fresh command arrived (flag was set; now cleared).
    Fresh,
    /// No fresh command: the previous one is applied again.
    Repeated,
    /// No fresh command for the clear bound: the command was cleared (all zero, motors limp).
    Cleared,
    /// The fresh command held NaN or infinity: ignored, counted as missed.
    Rejected,
}

/// What a [`SplineDaemon`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SplineDaemonCounters {
    /// Cycles with a fresh command.
    pub fresh: u64,
    /// Cycles that repeated the previous command.
    pub repeated: u64,
    /// Cycles with the command cleared.
    pub cleared: u64,
    /// Times the command was cleared after missed cycles.
    pub clears: u64,
    /// Fresh commands rejected for non-finite values.
    pub rejected: u64,
    /// States published.
    pub states_published: u64,
}

/// The daemon's side of `/spline_shm` (used by robowire's simulator, usable by any daemon).
#[derive(Debug)]
pub struct SplineDaemon<R: SharedRegion = MappedRegion> {
    region: R,
    /// Double buffer: `buffers[active]` is the command in force; a fresh command lands in the
    /// other one and becomes active once checked, without a copy.
    buffers: [SplineCommandBlock; 2],
    active: usize,
    /// The command was cleared and no fresh one came since.
    cleared: bool,
    missed: u32,
    clear_after: u32,
    counters: SplineDaemonCounters,
}

impl SplineDaemon<MappedRegion> {
    /// Creates the object (10240 bytes, permissions from `options`, applied after creation).
    pub fn create(name: &str, options: &CreateOptions) -> Result<Self, SplineError> {
        Self::new(MappedRegion::create(name, SPLINE_SHM_SIZE, options)?)
    }
}

impl<R: SharedRegion> SplineDaemon<R> {
    /// A daemon on `region` (at least 608 bytes). The command starts cleared.
    pub fn new(region: R) -> Result<Self, SplineError> {
        check_len(&region, SPLINE_DATA_LEN)?;
        Ok(Self {
            region,
            buffers: [SplineCommandBlock::default(); 2],
            active: 0,
            cleared: true,
            missed: 0,
            clear_after: DEFAULT_CLEAR_AFTER_CYCLES,
            counters: SplineDaemonCounters::default(),
        })
    }

    /// Clears the command after this many cycles without a fresh one (default 10).
    #[must_use]
    pub fn with_clear_after(mut self, cycles: u32) -> Self {
        self.clear_after = cycles.max(1);
        self
    }

    /// The region.
    pub fn region(&self) -> &R {
        &self.region
    }

    /// Takes this cycle's command: the fresh one if the control flag is set (then clears it),
    /// else the previous one, or nothing after the clear bound.
    pub fn take_command(&mut self) -> Result<CommandUpdate, SplineError> {
        if self.region.load_u32(CMD_FLAG_CONTROL_OFFSET, Ordering::Acquire)? != 0 {
            let spare = 1 - self.active;
            self.region.read(0, &mut self.buffers[spare].as_mut_bytes()[..CMD_LEGS_LEN])?;
            self.region.store_u32(CMD_FLAG_CONTROL_OFFSET, 0, Ordering::Release)?;
            if self.buffers[spare].first_non_finite().is_none() {
                self.active = spare;
                self.cleared = false;
                self.missed = 0;
                self.counters.fresh += 1;
                return Ok(CommandUpdate::Fresh);
            }
            self.counters.rejected += 1;
            if self.missed < self.clear_after {
                self.missed += 1;
            }
            return Ok(self.after_miss(CommandUpdate::Rejected));
        }
        if self.missed < self.clear_after {
            self.missed += 1;
        }
        Ok(self.after_miss(CommandUpdate::Repeated))
    }

    fn after_miss(&mut self, update: CommandUpdate) -> CommandUpdate {
        if self.missed >= self.clear_after {
            if !self.cleared {
                self.buffers[self.active] = SplineCommandBlock::default();
                self.cleared = true;
                self.counters.clears += 1;
            }
            self.counters.cleared += 1;
            CommandUpdate::Cleared
        } else {
            self.counters.repeated += 1;
            update
        }
    }

    /// The command in force.
    pub fn command(&self) -> &SplineCommandBlock {
        &self.buffers[self.active]
    }

    /// Publishes `state` and raises both readers' flags.
    pub fn publish_state(&mut self, state: &SplineStateBlock) -> Result<(), SplineError> {
        self.region.write(STATE_OFFSET, &state.as_bytes()[..STATE_LEGS_LEN])?;
        self.region.store_u32(STATE_FLAG_CONTROL_OFFSET, 1, Ordering::Release)?;
        self.region.store_u32(STATE_FLAG_OTHER_OFFSET, 1, Ordering::Release)?;
        self.counters.states_published += 1;
        Ok(())
    }

    /// Counters.
    pub fn counters(&self) -> SplineDaemonCounters {
        self.counters
    }
}

/// One IMU sample.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ImuSample {
    /// Sample time, ns (robowire's producer: the monotonic clock, [`monotonic_ns`]).
    pub timestamp_ns: u64,
    /// Acceleration x, y, z, m/s².
    pub acc_mps2: [f32; 3],
    /// Angular rate x, y, z, rad/s.
    pub gyro_radps: [f32; 3],
    /// Orientation quaternion w, x, y, z.
    pub quaternion_wxyz: [f32; 4],
}

impl ImuSample {
    /// Age at `now_ns` on the sample's clock.
    pub fn age_at(&self, now_ns: u64) -> Duration {
        Duration::from_nanos(now_ns.saturating_sub(self.timestamp_ns))
    }

    fn from_record(record: &NavImu) -> Self {
        Self {
            timestamp_ns: record.timestamp_ns.get(),
            acc_mps2: record.acc.map(|v| v.get()),
            gyro_radps: record.gyro.map(|v| v.get()),
            quaternion_wxyz: record.q.map(|v| v.get()),
        }
    }
}

/// What an [`ImuReader`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ImuReaderCounters {
    /// Samples read.
    pub reads: u64,
    /// Attempts repeated because the record changed underneath.
    pub retries: u64,
}

/// Reads `/imu_shm` using the timestamp as a version: read it, copy the record, read it again;
/// retry if it changed (or is 0, which robowire's writer uses while it updates).
///
/// Against robowire's [`ImuWriter`] this never yields a torn sample. Against a producer that
/// writes the timestamp and the data in another order, a tear that leaves the timestamp
/// unchanged stays undetectable: the vendor layout has no in-progress marker (spec decision 5).
#[derive(Debug)]
pub struct ImuReader<R: SharedRegion = MappedRegion> {
    region: R,
    max_attempts: u32,
    counters: ImuReaderCounters,
}

impl ImuReader<MappedRegion> {
    /// Opens the producer's object (never creates it): "IMU producer not running" if absent.
    pub fn open(name: &str) -> Result<Self, ImuError> {
        match MappedRegion::open(name, NAV_IMU_LEN) {
            Ok(region) => Self::new(region),
            Err(ShmError::NotFound { name }) => Err(ImuError::ProducerNotRunning { name }),
            Err(e) => Err(e.into()),
        }
    }
}

impl<R: SharedRegion> ImuReader<R> {
    /// A reader on `region` (at least 48 bytes), 16 attempts per read.
    pub fn new(region: R) -> Result<Self, ImuError> {
        check_len(&region, NAV_IMU_LEN)?;
        Ok(Self { region, max_attempts: 16, counters: ImuReaderCounters::default() })
    }

    /// Attempts per read (at least 1).
    #[must_use]
    pub fn with_max_attempts(mut self, attempts: u32) -> Self {
        self.max_attempts = attempts.max(1);
        self
    }

    /// The latest consistent sample.
    pub fn read(&mut self) -> Result<ImuSample, ImuError> {
        let mut saw_sample = false;
        for _ in 0..self.max_attempts {
            let before = self.region.load_u64(0, Ordering::Acquire)?;
            if before != 0 {
                saw_sample = true;
                let mut record = NavImu::new_zeroed();
                self.region.read(8, &mut record.as_mut_bytes()[8..])?;
                fence(Ordering::Acquire);
                let after = self.region.load_u64(0, Ordering::Relaxed)?;
                if before == after {
                    record.timestamp_ns = before.into();
                    self.counters.reads += 1;
                    return Ok(ImuSample::from_record(&record));
                }
            }
            self.counters.retries += 1;
            std::hint::spin_loop();
        }
        if saw_sample { Err(ImuError::Torn { attempts: self.max_attempts }) } else { Err(ImuError::NoSample) }
    }

    /// Age of the latest sample on the monotonic clock.
    pub fn latest_age(&mut self) -> Result<Duration, ImuError> {
        Ok(self.read()?.age_at(monotonic_ns()))
    }

    /// Counters.
    pub fn counters(&self) -> ImuReaderCounters {
        self.counters
    }
}

/// Publishes IMU samples: timestamp 0 while the record is updated, then the real timestamp with
/// release, so that an [`ImuReader`] never accepts a half-written record.
#[derive(Debug)]
pub struct ImuWriter<R: SharedRegion = MappedRegion> {
    region: R,
}

impl ImuWriter<MappedRegion> {
    /// Creates the object (1024 bytes, permissions from `options`).
    pub fn create(name: &str, options: &CreateOptions) -> Result<Self, ImuError> {
        Self::new(MappedRegion::create(name, IMU_SHM_SIZE, options)?)
    }
}

impl<R: SharedRegion> ImuWriter<R> {
    /// A writer on `region` (at least 48 bytes).
    pub fn new(region: R) -> Result<Self, ImuError> {
        check_len(&region, NAV_IMU_LEN)?;
        Ok(Self { region })
    }

    /// Publishes `sample` (its timestamp must be non-zero).
    pub fn publish(&mut self, sample: &ImuSample) -> Result<(), ImuError> {
        let mut record = NavImu::new_zeroed();
        record.acc = sample.acc_mps2.map(Into::into);
        record.gyro = sample.gyro_radps.map(Into::into);
        record.q = sample.quaternion_wxyz.map(Into::into);
        self.region.store_u64(0, 0, Ordering::Relaxed)?;
        fence(Ordering::Release);
        self.region.write(8, &record.as_bytes()[8..])?;
        self.region.store_u64(0, sample.timestamp_ns.max(1), Ordering::Release)?;
        Ok(())
    }
}
