//! [`SplineReplay`]: recorded spline states and IMU records published again, byte for byte, as the
//! ZSL-1's motor daemon on shared memory. The daemon's end of `/spline_shm` and `/imu_shm`
//! ([`SplineDaemon`], [`ImuWriter`]): the motion controller maps the objects like the robot's;
//! the player waits for its first command, then the runner publishes each recorded state and IMU
//! record on time and, as the daemon does each cycle, takes (and counts) the controller's command.

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use robowire_shm::CreateOptions;
use zsl_proto::shm::{LegState, NavImu, SplineStateBlock};
use zsl_proto::zerocopy::FromBytes;

use super::{Pace, ReplayError, ReplaySummary};
use crate::spline::{CommandUpdate, DaemonError, ImuWriter, SplineDaemon};

/// How often [`SplineReplay::first_command`] looks for the controller's command.
const COMMAND_POLL: Duration = Duration::from_millis(1);

/// A recorded frame of the daemon's side. Most are states: kept inline, not boxed.
#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)]
enum Published {
    /// The 256 bytes of leg states.
    State([LegState; 4]),
    /// A 48-byte `nav_imu` record (timestamp, sample).
    Imu(NavImu),
}

/// Recorded spline states (each the 256 bytes of leg states) and IMU records (each 48 bytes)
/// published as the daemon on shared memory, from the motion controller's first command on.
///
/// ```
/// use std::time::Duration;
/// use robowire_shm::{CreateOptions, MappedRegion, SharedRegion};
/// use robowire_sim::replay::{Pace, SplineReplay};
/// use zsl_proto::shm::{ConsumerIndex, SPLINE_COMMAND, SPLINE_DATA_LEN};
///
/// let pid = std::process::id();
/// let (spline, imu) = (format!("/robowire-doc-{pid}-spline"), format!("/robowire-doc-{pid}-imu"));
/// let states = (0..3u8).map(|n| (Duration::from_millis(u64::from(n)), vec![n; 256]));
/// let mut daemon = SplineReplay::create(&spline, &imu, &CreateOptions::default(), states, [])?;
/// // The motion controller's side: a command published, the last state taken.
/// let controller = MappedRegion::open(&spline, SPLINE_DATA_LEN)?;
/// controller.publish(&[SPLINE_COMMAND], &[0u8; 336])?;
/// assert!(daemon.first_command(Duration::from_secs(5))?);
/// let summary = daemon.play(Pace::Fast)?;
/// assert_eq!((summary.frames, summary.sent, summary.commands), (3, 3, 1));
/// let mut last = [0u8; 256];
/// assert!(controller.take(&ConsumerIndex::Control.state(), &mut last)?);
/// assert_eq!(last, [2u8; 256]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct SplineReplay {
    daemon: SplineDaemon,
    imu: ImuWriter,
    /// Offset from the first frame, what to publish, in order.
    frames: Vec<(Duration, Published)>,
    commands: u64,
}

impl SplineReplay {
    /// Creates the spline object `spline_name` and the IMU object `imu_name` (as a daemon does,
    /// with `options`) to publish `states` (each: its offset from the first frame, the 256 bytes
    /// of leg states) and `imu` (each: its offset, the 48-byte record), merged in time. A frame
    /// of another length is refused, with its index, before anything is created.
    pub fn create(
        spline_name: &str,
        imu_name: &str,
        options: &CreateOptions,
        states: impl IntoIterator<Item = (Duration, Vec<u8>)>,
        imu: impl IntoIterator<Item = (Duration, Vec<u8>)>,
    ) -> Result<Self, ReplayError> {
        let mut frames = Vec::new();
        for (index, (offset, bytes)) in states.into_iter().enumerate() {
            let legs = <[LegState; 4]>::read_from_bytes(&bytes).map_err(|_| ReplayError::Length {
                index,
                what: "spline state",
                expected: 256,
                found: bytes.len(),
            })?;
            frames.push((offset, Published::State(legs)));
        }
        for (index, (offset, bytes)) in imu.into_iter().enumerate() {
            let record = NavImu::read_from_bytes(&bytes).map_err(|_| ReplayError::Length {
                index,
                what: "IMU record",
                expected: 48,
                found: bytes.len(),
            })?;
            frames.push((offset, Published::Imu(record)));
        }
        // Stable: equal offsets keep their order.
        frames.sort_by_key(|(offset, _)| *offset);
        let shm = |e: DaemonError| ReplayError::Io(std::io::Error::other(e));
        Ok(Self {
            daemon: SplineDaemon::create(spline_name, options).map_err(shm)?,
            imu: ImuWriter::create(imu_name, options).map_err(shm)?,
            frames,
            commands: 0,
        })
    }

    /// Frames to publish (states and IMU records).
    pub fn frames(&self) -> usize {
        self.frames.len()
    }

    /// Waits up to `timeout` for the controller's first command: `true` once one came, `false`
    /// on timeout (call again to go on waiting).
    pub fn first_command(&mut self, timeout: Duration) -> Result<bool, ReplayError> {
        let deadline = Instant::now() + timeout;
        while self.commands == 0 {
            if self.take_command()? {
                return Ok(true);
            }
            if Instant::now() >= deadline {
                return Ok(false);
            }
            std::thread::sleep(COMMAND_POLL);
        }
        Ok(true)
    }

    fn take_command(&mut self) -> Result<bool, ReplayError> {
        let fresh = self.daemon.take_command().map_err(|e| ReplayError::Io(std::io::Error::other(e)))?;
        let fresh = fresh == CommandUpdate::Fresh || fresh == CommandUpdate::Rejected;
        self.commands += u64::from(fresh);
        Ok(fresh)
    }

    /// Publishes every frame on robowire's runner at `pace`, taking the controller's command
    /// after each state as the daemon does each cycle; returns once the last is published.
    pub fn play(self, pace: Pace) -> Result<ReplaySummary, ReplayError> {
        let Self { mut daemon, mut imu, frames, commands } = self;
        let count = frames.len();
        let taken = Arc::new(AtomicU64::new(commands));
        let (offsets, published): (Vec<_>, Vec<_>) =
            frames.into_iter().enumerate().map(|(i, (o, p))| ((o, vec![]), (i, p))).unzip();
        // The runner plays indices into `published` (its frames' bytes are unused).
        let mut published = published.into_iter().map(|(_, p)| p);
        let counted = taken.clone();
        let mut state = SplineStateBlock::default();
        let runner = super::spawn_playback(offsets, pace, move |_| {
            let Some(frame) = published.next() else { return false };
            match frame {
                Published::State(legs) => {
                    state.legs = legs;
                    let sent = daemon.publish_state(&state).is_ok();
                    if let Ok(CommandUpdate::Fresh | CommandUpdate::Rejected) = daemon.take_command() {
                        counted.fetch_add(1, Ordering::Relaxed);
                    }
                    sent
                }
                Published::Imu(record) => imu.publish(&record).is_ok(),
            }
        })?;
        let played = runner.join().ok_or(ReplayError::Lost)?;
        let commands = taken.load(Ordering::Relaxed);
        Ok(ReplaySummary { frames: count, sent: played.sent, commands, invalid: 0, client: None })
    }
}
