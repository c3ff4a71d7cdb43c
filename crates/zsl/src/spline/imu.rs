//! [`ImuReader`]: `/imu_shm`, read with the timestamp as the record's version.

use std::time::Duration;

use robowire_shm::{MappedRegion, RegionError, SharedRegion, ShmError, VersionedReadError};
use robowire_tap::{Direction, SampleOrigin, Tap};
use zsl_proto::shm::{IMU_RECORD, NAV_IMU_LEN, NavImuSample};
use zsl_proto::zerocopy::{FromZeros, IntoBytes};

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
    /// The object could not be opened (permissions, size).
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

impl From<VersionedReadError> for ImuError {
    fn from(e: VersionedReadError) -> Self {
        match e {
            VersionedReadError::Empty => Self::NoSample,
            VersionedReadError::Torn { attempts } => Self::Torn { attempts },
            VersionedReadError::Region(e) => Self::Region(e),
        }
    }
}

/// One IMU sample.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ImuSample {
    /// Sample time, ns (robowire's producer: the monotonic clock, `robowire_rt::monotonic_ns`).
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
/// retry if it changed (or is 0, which robowire's producer writes while it updates).
///
/// Against robowire's producer this never yields a torn sample. Against a producer that writes
/// the timestamp and the data in another order, a tear that leaves the timestamp unchanged stays
/// undetectable: the vendor layout has no in-progress marker (spec decision 5).
#[derive(Debug)]
pub struct ImuReader<R: SharedRegion = MappedRegion> {
    region: R,
    max_attempts: u32,
    counters: ImuReaderCounters,
    tap: Option<Tap>,
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
        region.check_fits(NAV_IMU_LEN)?;
        Ok(Self { region, max_attempts: 16, counters: ImuReaderCounters::default(), tap: None })
    }

    /// Hands each sample read (received) to `tap`, a link described by
    /// `zsl_proto::description::IMU`: the 48-byte `nav_imu` record as accepted, its timestamp
    /// (little-endian) then the sample. A copy into the tap's ring: no allocation, no lock.
    #[must_use]
    pub fn with_tap(mut self, tap: Tap) -> Self {
        self.tap = Some(tap);
        self
    }

    /// Attempts per read (at least 1).
    #[must_use]
    pub fn with_max_attempts(mut self, attempts: u32) -> Self {
        self.max_attempts = attempts.max(1);
        self
    }

    /// The latest consistent sample.
    pub fn read(&mut self) -> Result<ImuSample, ImuError> {
        let mut sample = NavImuSample::new_zeroed();
        match self.region.read_versioned(&IMU_RECORD, sample.as_mut_bytes(), self.max_attempts) {
            Ok(read) => {
                self.counters.reads += 1;
                self.counters.retries += u64::from(read.attempts - 1);
                if let Some(tap) = &self.tap {
                    let parts: [&[u8]; 2] = [&read.version.to_le_bytes(), sample.as_bytes()];
                    tap.record_parts(Direction::Received, &parts, SampleOrigin::NONE);
                }
                Ok(ImuSample {
                    timestamp_ns: read.version,
                    acc_mps2: sample.acc.map(|v| v.get()),
                    gyro_radps: sample.gyro.map(|v| v.get()),
                    quaternion_wxyz: sample.q.map(|v| v.get()),
                })
            }
            Err(e) => {
                self.counters.retries += u64::from(self.max_attempts);
                Err(e.into())
            }
        }
    }

    /// Age of the latest sample on the monotonic clock.
    pub fn latest_age(&mut self) -> Result<Duration, ImuError> {
        Ok(self.read()?.age_at(robowire_rt::monotonic_ns()))
    }

    /// Counters.
    pub fn counters(&self) -> ImuReaderCounters {
        self.counters
    }
}
