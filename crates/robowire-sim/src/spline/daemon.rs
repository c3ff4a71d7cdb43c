//! The daemon's side of `/spline_shm` and the producer of `/imu_shm`: what the vendor's motor
//! daemon does with the shared memory, on `robowire-shm`'s handshake and versioned record and
//! `zsl-proto`'s layouts. Usable by any daemon; the simulator's loop is built on it.

use robowire_shm::{CreateOptions, MappedRegion, RegionError, SharedRegion, ShmError};
use robowire_tap::{Direction, SampleOrigin, Tap};
use zsl_proto::shm::{
    IMU_RECORD, IMU_SHM_SIZE, LegControl, NAV_IMU_LEN, NavImu, SPLINE_COMMAND, SPLINE_DATA_LEN, SPLINE_SHM_SIZE,
    SPLINE_STATE, SplineCommandBlock, SplineStateBlock,
};
use zsl_proto::zerocopy::IntoBytes;

/// Default: the daemon clears the command after this many cycles without a fresh one.
pub const DEFAULT_CLEAR_AFTER_CYCLES: u32 = 10;

/// Why the daemon side failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DaemonError {
    /// An object could not be created.
    #[error(transparent)]
    Shm(#[from] ShmError),
    /// An access was refused (a region too small for the layout).
    #[error(transparent)]
    Region(#[from] RegionError),
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

/// The daemon's side of `/spline_shm`.
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
    tap: Option<Tap>,
}

impl SplineDaemon<MappedRegion> {
    /// Creates the object (10240 bytes, permissions from `options`, applied after creation).
    pub fn create(name: &str, options: &CreateOptions) -> Result<Self, DaemonError> {
        Self::new(MappedRegion::create(name, SPLINE_SHM_SIZE, options)?)
    }
}

impl<R: SharedRegion> SplineDaemon<R> {
    /// A daemon on `region` (at least 608 bytes). The command starts cleared.
    pub fn new(region: R) -> Result<Self, DaemonError> {
        region.check_fits(SPLINE_DATA_LEN)?;
        Ok(Self {
            region,
            buffers: [SplineCommandBlock::default(); 2],
            active: 0,
            cleared: true,
            missed: 0,
            clear_after: DEFAULT_CLEAR_AFTER_CYCLES,
            counters: SplineDaemonCounters::default(),
            tap: None,
        })
    }

    /// Hands each command taken (received: its 336 bytes of legs as copied out, rejected ones
    /// too) and each state published (sent: its 256 bytes of legs) to `tap`, a link described by
    /// `zsl_proto::description::SPLINE_DAEMON`. A copy into the tap's ring: no allocation, no lock.
    #[must_use]
    pub fn with_tap(mut self, tap: Tap) -> Self {
        self.tap = Some(tap);
        self
    }

    /// Clears the command after this many cycles without a fresh one (default 10).
    #[must_use]
    pub fn with_clear_after(mut self, cycles: u32) -> Self {
        self.clear_after = cycles.max(1);
        self
    }

    /// Takes this cycle's command: the fresh one if the control flag is set (then lowers it),
    /// else the previous one, or nothing after the clear bound.
    pub fn take_command(&mut self) -> Result<CommandUpdate, DaemonError> {
        let spare = 1 - self.active;
        let legs: &mut [LegControl; 4] = &mut self.buffers[spare].legs;
        if self.region.take(&SPLINE_COMMAND, legs.as_mut_bytes())? {
            if let Some(tap) = &self.tap {
                tap.record(Direction::Received, legs.as_bytes());
            }
            if self.buffers[spare].first_non_finite().is_none() {
                self.active = spare;
                self.cleared = false;
                self.missed = 0;
                self.counters.fresh += 1;
                return Ok(CommandUpdate::Fresh);
            }
            self.counters.rejected += 1;
            self.missed = (self.missed + 1).min(self.clear_after);
            return Ok(self.after_miss(CommandUpdate::Rejected));
        }
        self.missed = (self.missed + 1).min(self.clear_after);
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

    /// Publishes `state` and raises both consumers' flags.
    pub fn publish_state(&mut self, state: &SplineStateBlock) -> Result<(), DaemonError> {
        self.region.publish(&SPLINE_STATE, state.legs.as_bytes())?;
        self.counters.states_published += 1;
        if let Some(tap) = &self.tap {
            tap.record(Direction::Sent, state.legs.as_bytes());
        }
        Ok(())
    }

    /// Counters.
    pub fn counters(&self) -> SplineDaemonCounters {
        self.counters
    }
}

/// Publishes IMU records on `/imu_shm`: the timestamp is the record's version, 0 while the
/// record is updated, so that a reader never accepts a half-written record.
#[derive(Debug)]
pub struct ImuWriter<R: SharedRegion = MappedRegion> {
    region: R,
    tap: Option<Tap>,
}

impl ImuWriter<MappedRegion> {
    /// Creates the object (1024 bytes, permissions from `options`).
    pub fn create(name: &str, options: &CreateOptions) -> Result<Self, DaemonError> {
        Self::new(MappedRegion::create(name, IMU_SHM_SIZE, options)?)
    }
}

impl<R: SharedRegion> ImuWriter<R> {
    /// A writer on `region` (at least 48 bytes).
    pub fn new(region: R) -> Result<Self, DaemonError> {
        region.check_fits(NAV_IMU_LEN)?;
        Ok(Self { region, tap: None })
    }

    /// Hands each record published (sent: the 48-byte `nav_imu`, its timestamp as published,
    /// then the sample) to `tap`, a link described by `zsl_proto::description::IMU`.
    #[must_use]
    pub fn with_tap(mut self, tap: Tap) -> Self {
        self.tap = Some(tap);
        self
    }

    /// Publishes `record` (a timestamp of 0 is published as 1: 0 means "no record").
    pub fn publish(&mut self, record: &NavImu) -> Result<(), DaemonError> {
        let version = record.timestamp_ns.get().max(1);
        self.region.write_versioned(&IMU_RECORD, version, record.sample.as_bytes())?;
        if let Some(tap) = &self.tap {
            let parts: [&[u8]; 2] = [&version.to_le_bytes(), record.sample.as_bytes()];
            tap.record_parts(Direction::Sent, &parts, SampleOrigin::NONE);
        }
        Ok(())
    }
}
