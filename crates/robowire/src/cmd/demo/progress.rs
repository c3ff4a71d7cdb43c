//! The live progress line of a running scenario: mode, motion, loop rate, lateness.
//!
//! On a terminal the line is redrawn in place four times a second; in a log (a pipe, a file,
//! CI) a plain line is printed every second instead. It goes to the report's stream (stdout,
//! or stderr under `--json`), and every report line clears it first.

use std::time::{Duration, Instant};

use crate::output::Output;

const LIVE_EVERY: Duration = Duration::from_millis(250);
const LOG_EVERY: Duration = Duration::from_secs(1);

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
pub(crate) struct Progress<'a> {
    out: &'a Output,
    device: &'static str,
    started: Instant,
    last: (Instant, u64),
    next_at: Instant,
    live: bool,
}

impl<'a> Progress<'a> {
    pub(crate) fn new(device: &'static str, out: &'a Output) -> Self {
        let now = Instant::now();
        let live = out.is_terminal();
        Self { out, device, started: now, last: (now, 0), next_at: now + Self::every(live), live }
    }

    fn every(live: bool) -> Duration {
        if live { LIVE_EVERY } else { LOG_EVERY }
    }

    /// The loop starts now, its counter at `loop_count`: the next line's rate is taken from here,
    /// not from the scenario's start (a G1's LowCmd stream starts seconds in).
    pub(crate) fn loop_started(&mut self, loop_count: u64) {
        self.last = (Instant::now(), loop_count);
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
            self.out.live(&text);
        } else {
            self.out.write(&format!("{text}\n"));
        }
    }
}
