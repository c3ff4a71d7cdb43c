//! Recorded frames played back, byte for byte, to a live client as the device
//! (`robowire replay --as-device`), so that a session seen once on a robot can be replayed on a
//! desk. A player knows no recorder and no device: it takes the device's frames as offsets from
//! the first and bytes, and the transport's device end.
//!
//! - [`DatagramReplay`] (feature `replay`): over UDP, with the device side's datagram codec,
//!   from the client's first command on (the ZSL-1).
//! - [`SerialReplay`] (feature `replay-serial`): on a pseudo-terminal, with the device side's
//!   stream decoder, from the host's first frame on (the KMC chassis).
//! - [`DdsReplay`] (feature `replay-dds`): on a DDS topic, as raw payloads, from the first
//!   matched reader on (the Go2's `rt/lowstate`).
//! - [`SplineReplay`] (feature `zsl`): on shared memory as the ZSL-1's motor daemon (spline
//!   states and IMU records), from the motion controller's first command on.
//!
//! Each sends every frame on robowire's runner at its due time: the recorded offset divided by
//! a speed, or at once ([`Pace`]); what the client sends meanwhile is counted.
//!
//! Which recorded links can be played, as which device, and which of their frames the device
//! sent: [`PLAYABLE`], keyed by the links' protocol (features `kmc`, `zsl`, `go2`).

#[cfg(feature = "replay")]
mod datagram;
#[cfg(feature = "replay-dds")]
mod dds;
#[cfg(feature = "replay-serial")]
mod serial;
#[cfg(feature = "zsl")]
mod shm;
mod table;

use std::time::Duration;

use robowire_core::schedule::Time;
use robowire_rt::runner::{Job, Runner, RunnerOptions};

#[cfg(feature = "replay")]
pub use self::datagram::DatagramReplay;
#[cfg(feature = "replay-dds")]
pub use self::dds::{DdsReplay, DdsTopic};
#[cfg(feature = "replay-serial")]
pub use self::serial::SerialReplay;
#[cfg(feature = "zsl")]
pub use self::shm::SplineReplay;
pub use self::table::{PLAYABLE, Playable, Played, playable, playable_list};

/// How fast to play.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Pace {
    /// At the recorded offsets divided by `speed` (2: twice as fast as recorded).
    Recorded {
        /// Finite, above 0.
        speed: f64,
    },
    /// Every frame at once, one after the other.
    Fast,
}

/// What a playback did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReplaySummary {
    /// Frames to play.
    pub frames: usize,
    /// Frames sent (the others failed at the transport, or had no client to go to).
    pub sent: u64,
    /// The client's valid commands (datagrams, serial frames, DDS samples), the first one
    /// included.
    pub commands: u64,
    /// What the client sent that did not decode as commands: datagrams; on a serial line,
    /// rejected frame candidates.
    pub invalid: u64,
    /// Where the frames went when the playback began (UDP only).
    pub client: Option<std::net::SocketAddr>,
}

/// Why a playback could not run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReplayError {
    /// [`Pace::Recorded`] with a speed that is not finite and above 0.
    #[error("the speed must be finite and above 0, got {0}")]
    Speed(f64),
    /// The player's thread could not start.
    #[error("cannot start the player's thread")]
    Thread(#[from] robowire_rt::RtError),
    /// The player's thread ended without a result (it panicked).
    #[error("the player's thread ended without a result")]
    Lost,
    /// The transport's device end could not be opened or failed.
    #[error("the device end of the line")]
    Io(#[from] std::io::Error),
    /// DDS refused the participant, the writer or the reader.
    #[cfg(feature = "replay-dds")]
    #[error("DDS")]
    Dds(#[from] robowire_dds::DdsError),
    /// A recorded frame of the wrong length for what it is played as.
    #[error("frame {index}: a {what} is {expected} bytes, found {found}")]
    Length {
        /// The frame's index among those of its kind.
        index: usize,
        /// What it is played as (`spline state`).
        what: &'static str,
        /// Its length.
        expected: usize,
        /// The frame's.
        found: usize,
    },
    /// A recorded DDS payload that is not CDR: shorter than its encapsulation header, or a
    /// representation other than XCDR1 (`00 01`) and XCDR2 (`00 07`).
    #[error("frame {index}: encapsulation header {found:02x?} is neither XCDR1 (00 01) nor XCDR2 (00 07)")]
    Encapsulation {
        /// The frame's index among those given.
        index: usize,
        /// Its first bytes (up to 4).
        found: Vec<u8>,
    },
}

/// Each frame's due time on robowire's clock from now, at `pace`.
fn schedule(frames: Vec<(Duration, Vec<u8>)>, pace: Pace) -> Result<Vec<(Time, Vec<u8>)>, ReplayError> {
    let speed = match pace {
        Pace::Recorded { speed } if speed.is_finite() && speed > 0.0 => Some(speed),
        Pace::Recorded { speed } => return Err(ReplayError::Speed(speed)),
        Pace::Fast => None,
    };
    let start = robowire_rt::now();
    let due = |offset: Duration| match speed {
        Some(speed) => start + Duration::try_from_secs_f64(offset.as_secs_f64() / speed).unwrap_or(Duration::MAX),
        // In the past: at once.
        None => Time::ZERO,
    };
    Ok(frames.into_iter().map(|(offset, bytes)| (due(offset), bytes)).collect())
}

/// Starts the runner that plays `frames` at `pace` with `send` (`true`: the frame went out).
fn spawn_playback<S>(frames: Vec<(Duration, Vec<u8>)>, pace: Pace, send: S) -> Result<Runner<Playback<S>>, ReplayError>
where
    S: FnMut(&[u8]) -> bool + Send + 'static,
{
    let frames = schedule(frames, pace)?;
    Ok(Runner::spawn(RunnerOptions::named("replay"), Playback { send, frames, next: 0, sent: 0 })?)
}

/// The frames on the runner: each sent at its due time.
struct Playback<S> {
    send: S,
    /// When each is due, its bytes.
    frames: Vec<(Time, Vec<u8>)>,
    next: usize,
    sent: u64,
}

impl<S: FnMut(&[u8]) -> bool + Send + 'static> Job for Playback<S> {
    fn next_run(&mut self) -> Option<Time> {
        self.frames.get(self.next).map(|(due, _)| *due)
    }

    fn run(&mut self, now: Time) {
        while let Some((due, bytes)) = self.frames.get(self.next)
            && *due <= now
        {
            self.sent += u64::from((self.send)(bytes));
            self.next += 1;
        }
    }
}
