//! The `rt/arm_sdk` stream thread's job: the sans-IO [`ArmSdkStream`] on robowire's runner,
//! writing through `robowire-dds`. Commands arrive through a seqlock ([`Latest`]), closing
//! through an atomic; statistics leave as atomics. The thread never waits on the caller.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::time::Duration;

use robowire_dds::Writer;
use robowire_rt::runner::Job;
use robowire_rt::stats::{Counter, SharedLateness, micros};
use robowire_rt::{Latest, Time};
use unitree_proto::HgLowCmd;

use unitree_proto::g1::arm_stream::ArmSdkStream;

/// What the arm stream thread shares with the client.
pub(crate) struct ArmShared {
    /// The latest arm command (slot 29's `q`: the target weight) and when it was set.
    pub(crate) commands: Latest<HgLowCmd>,
    /// Set by the client when it closes.
    pub(crate) closing: AtomicBool,
    /// The weight of the last frame, as `f32` bits.
    pub(crate) weight: AtomicU32,
    pub(crate) lateness: SharedLateness<1024>,
    pub(crate) sent: Counter,
    pub(crate) command_timeouts: Counter,
    pub(crate) missed_ticks: Counter,
    pub(crate) write_drops: Counter,
}

impl Default for ArmShared {
    fn default() -> Self {
        Self {
            commands: Latest::new(),
            closing: AtomicBool::new(false),
            weight: AtomicU32::new(0),
            lateness: SharedLateness::new(),
            sent: Counter::default(),
            command_timeouts: Counter::default(),
            missed_ticks: Counter::default(),
            write_drops: Counter::default(),
        }
    }
}

pub(crate) struct ArmSdkJob {
    stream: ArmSdkStream,
    writer: Writer<HgLowCmd>,
    shared: Arc<ArmShared>,
    seen_command: Option<Time>,
    /// When idle, wake this often to look for a command (a wake makes it sooner).
    idle: Duration,
}

impl ArmSdkJob {
    pub(crate) fn new(stream: ArmSdkStream, writer: Writer<HgLowCmd>, shared: Arc<ArmShared>) -> Self {
        Self { stream, writer, shared, seen_command: None, idle: Duration::from_millis(50) }
    }
}

impl Job for ArmSdkJob {
    fn next_run(&mut self) -> Option<Time> {
        if self.stream.is_done() {
            return None;
        }
        Some(self.stream.poll_timeout().unwrap_or_else(|| robowire_rt::now() + self.idle))
    }

    fn run(&mut self, now: Time) {
        if let Some((at, command)) = self.shared.commands.read_newer(self.seen_command) {
            self.seen_command = Some(at);
            self.stream.handle_command(at, command);
        }
        if self.shared.closing.load(Ordering::Acquire) {
            self.stream.close();
        }
        while let Some(frame) = self.stream.poll_transmit(now) {
            // The encoder zeroes padding and writes the CRC. Never waits: a full send window
            // drops this frame, counted; the next one follows a period later.
            if self.writer.try_write(frame.command).is_err() {
                self.shared.write_drops.add(1);
            }
            self.shared.lateness.record(micros(frame.tick.lateness));
        }
        let c = self.stream.counters();
        let s = &self.shared;
        s.weight.store(self.stream.weight().to_bits(), Ordering::Relaxed);
        s.sent.set(c.sent);
        s.command_timeouts.set(c.command_timeouts);
        s.missed_ticks.set(c.missed_ticks);
    }
}
