//! [`SerialReplay`]: recorded frames played back to a live host on a pseudo-terminal. The device
//! end of `robowire-serial` ([`Pty`]): the host opens [`SerialReplay::path`] like a serial port;
//! the player waits for its first frame, then the runner writes each recorded frame on time while
//! this thread reads (and counts) what the host sends, so that its writes never stall.

use std::io;
use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use robowire_core::{FrameBuffer, StreamDecoder};
use robowire_serial::{Pty, RX_BUFFER_LEN};

use super::{Pace, ReplayError, ReplaySummary};

/// How long one frame may wait for room on the line (a host that does not read) before it is
/// given up (not counted as sent).
const WRITE_TIMEOUT: Duration = Duration::from_secs(1);
/// The longest wait for the host's bytes while playing.
const READ_EVERY: Duration = Duration::from_millis(10);
/// How long the line must hold nothing unread before the host counts as having read every
/// frame: the kernel hands written bytes to the line's reader side asynchronously, so one empty
/// look can come before the last bytes arrive there.
const QUIET: Duration = Duration::from_millis(100);

/// Recorded frames played back to a live host as the device, on a pseudo-terminal, with the
/// device side's stream decoder (which cuts what the host sends into frames, to count them).
///
/// ```
/// use std::io::{Read, Write};
/// use std::time::Duration;
/// use robowire_sim::replay::{Pace, SerialReplay};
///
/// let speeds = [(Duration::ZERO, vec![0xb3, 0, 0, 0, 0]), (Duration::from_millis(20), vec![0xb3, 0, 0, 0, 0x3f])];
/// let mut chassis = SerialReplay::open(kmc_proto::HostFrameDecoder::new(), speeds)?;
/// let mut host = std::fs::OpenOptions::new().read(true).write(true).open(chassis.path())?;
/// host.write_all(&[0xb3])?; // a vehicle speed request
/// assert!(chassis.first_command(Duration::from_secs(5))?);
/// // The host reads while the frames are played (the line hangs up once they are read).
/// let reading = std::thread::spawn(move || {
///     let mut read = [0u8; 10];
///     host.read_exact(&mut read).map(|()| read)
/// });
/// let summary = chassis.play(Pace::Recorded { speed: 1.0 }, Duration::from_secs(5))?;
/// assert_eq!((summary.frames, summary.sent, summary.commands), (2, 2, 1));
/// assert_eq!(reading.join().unwrap()?, [0xb3, 0, 0, 0, 0, 0xb3, 0, 0, 0, 0x3f]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct SerialReplay<D: StreamDecoder> {
    /// Shared with the runner, which writes while this side reads.
    pty: Arc<Pty>,
    rx: FrameBuffer<D, RX_BUFFER_LEN>,
    /// Offset from the first frame, bytes.
    frames: Vec<(Duration, Vec<u8>)>,
    commands: u64,
}

impl<D: StreamDecoder> SerialReplay<D> {
    /// Opens a pseudo-terminal whose host bytes `decoder` cuts into frames, to play `frames`
    /// (each: its offset from the first frame, its bytes, in the order to write them).
    pub fn open(decoder: D, frames: impl IntoIterator<Item = (Duration, Vec<u8>)>) -> io::Result<Self> {
        Ok(Self {
            pty: Arc::new(Pty::open()?),
            rx: FrameBuffer::new(decoder),
            frames: frames.into_iter().collect(),
            commands: 0,
        })
    }

    /// The path the host opens, e.g. `/dev/pts/3`.
    pub fn path(&self) -> &Path {
        self.pty.slave_path()
    }

    /// Frames to play.
    pub fn frames(&self) -> usize {
        self.frames.len()
    }

    /// Waits up to `timeout` for the host's first frame: `true` once one came (the host has the
    /// line open and speaks), `false` on timeout (call again to go on waiting).
    pub fn first_command(&mut self, timeout: Duration) -> io::Result<bool> {
        let deadline = Instant::now() + timeout;
        while self.commands == 0 {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Ok(false);
            }
            self.read_host(left.min(READ_EVERY))?;
        }
        Ok(true)
    }

    /// Reads what the host wrote, waiting up to `timeout` for it, and counts its frames.
    fn read_host(&mut self, timeout: Duration) -> io::Result<()> {
        let mut buf = [0u8; 512];
        // The player keeps the line's slave end open: no host is silence, not an error.
        let n = self.pty.read_timeout(&mut buf, timeout)?;
        let mut frames = 0;
        self.rx.push_all(&buf[..n], |_| frames += 1);
        self.commands += frames;
        Ok(())
    }

    /// Plays every frame to the host on robowire's runner at `pace`, reading and counting its
    /// frames meanwhile; returns once the last frame is written and the host has read them all
    /// (nothing unread on the line for 100 ms), or `drain` after the last one. The line hangs
    /// up when the player is dropped, with this call: what the host left unread is lost.
    pub fn play(mut self, pace: Pace, drain: Duration) -> Result<ReplaySummary, ReplayError> {
        let count = self.frames.len();
        let line = self.pty.clone();
        let frames = std::mem::take(&mut self.frames);
        let runner = super::spawn_playback(frames, pace, move |bytes| line.write_all(bytes, WRITE_TIMEOUT).is_ok())?;
        let mut listening = true;
        while listening && !runner.is_finished() {
            // A line that fails to read: the frames still go out; nothing more is counted.
            listening = self.read_host(READ_EVERY).is_ok();
        }
        let played = runner.join().ok_or(ReplayError::Lost)?;
        listening = listening && self.read_host(Duration::ZERO).is_ok();
        let deadline = Instant::now() + drain;
        let mut quiet_since = Instant::now();
        while listening && Instant::now() < deadline && quiet_since.elapsed() < QUIET {
            if self.pty.unread()? > 0 {
                quiet_since = Instant::now();
            }
            listening = self.read_host(READ_EVERY).is_ok();
        }
        let invalid = self.rx.counters().rejected_candidates;
        Ok(ReplaySummary { frames: count, sent: played.sent, commands: self.commands, invalid, client: None })
    }
}
