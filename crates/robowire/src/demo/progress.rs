//! The live progress line of a running scenario: mode, motion, loop rate, lateness.
//!
//! On a terminal the line is redrawn in place four times a second; in a log (a pipe, a file,
//! CI) a plain line is printed every second instead. It goes to the report's stream (stdout,
//! or stderr under `--json`), and every `say!` clears it first.

use std::io::{IsTerminal, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Whether a live line is on screen (and must be cleared before the next report line).
static SHOWN: AtomicBool = AtomicBool::new(false);

const LIVE_EVERY: Duration = Duration::from_millis(250);
const LOG_EVERY: Duration = Duration::from_secs(1);

fn report_is_terminal() -> bool {
    if super::json() { std::io::stderr().is_terminal() } else { std::io::stdout().is_terminal() }
}

fn write_report(text: &str) {
    // Progress is best effort: a closed stream must not stop the robot's loop.
    if super::json() {
        let _ = std::io::stderr().write_all(text.as_bytes());
        let _ = std::io::stderr().flush();
    } else {
        let _ = std::io::stdout().write_all(text.as_bytes());
        let _ = std::io::stdout().flush();
    }
}

/// Clears the live line if one is shown (called by `say!`).
pub(crate) fn clear() {
    if SHOWN.swap(false, Ordering::Relaxed) {
        write_report("\r\x1b[2K");
    }
}

/// What the line shows at one moment.
pub(crate) struct Status<'a> {
    /// The device's mode or phase, in its own terms.
    pub(crate) mode: &'a str,
    /// The main motion figure, with its unit (`+0.49 m/s`, `calf -1.21 rad`).
    pub(crate) motion: String,
    /// A counter of the device's main loop (frames sent, cycles); its rate is shown.
    pub(crate) loop_count: u64,
    /// Lateness or jitter of that loop, µs, and what it is (`p99`, `max`).
    pub(crate) lateness_us: (u32, &'static str),
}

/// The progress line of one scenario.
pub(crate) struct Progress {
    device: &'static str,
    started: Instant,
    last: (Instant, u64),
    next_at: Instant,
    live: bool,
}

impl Progress {
    pub(crate) fn new(device: &'static str) -> Self {
        let now = Instant::now();
        let live = report_is_terminal();
        Self { device, started: now, last: (now, 0), next_at: now + Self::every(live), live }
    }

    fn every(live: bool) -> Duration {
        if live { LIVE_EVERY } else { LOG_EVERY }
    }

    /// Whether it is time to show a new line (one clock read; cheap enough for a 1 kHz loop).
    pub(crate) fn due(&self) -> bool {
        Instant::now() >= self.next_at
    }

    /// Shows `status` (call when [`due`](Self::due)).
    pub(crate) fn show(&mut self, status: &Status<'_>) {
        let now = Instant::now();
        let (then, count) = self.last;
        let seconds = (now - then).as_secs_f64();
        let rate_hz = if seconds > 0.0 { status.loop_count.saturating_sub(count) as f64 / seconds } else { 0.0 };
        self.last = (now, status.loop_count);
        self.next_at = now + Self::every(self.live);
        let (lateness_us, which) = status.lateness_us;
        let text = format!(
            "  > {:<6} {:>5.1} s  {:<14} {:<18} loop {:>6.1} Hz  lateness {which} {lateness_us} µs",
            self.device,
            (now - self.started).as_secs_f64(),
            status.mode,
            status.motion,
            rate_hz,
        );
        if self.live {
            write_report(&format!("\r\x1b[2K{text}"));
            SHOWN.store(true, Ordering::Relaxed);
        } else {
            write_report(&format!("{text}\n"));
        }
    }
}
