//! The stream thread's job: `unitree-proto`'s sans-IO [`CommandStream`] on robowire's runner,
//! writing through `robowire-dds`. Commands arrive through a seqlock, damping requests through
//! an atomic; statistics leave as atomics. The stream thread never waits on the caller.

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

use robowire_dds::Writer;
use robowire_rt::runner::Job;
use robowire_rt::stats::{Counter, SharedLateness, micros};
use robowire_rt::{Latest, Time};
use unitree_proto::robot::Robot;
use unitree_proto::stream::CommandStream;

/// Damping frames written when the client closes.
pub(crate) const CLOSING_DAMPING_FRAMES: usize = 3;

/// What the stream thread shares with the client.
pub(crate) struct StreamShared<R: Robot> {
    /// The latest command and when it was set (validated by the client).
    pub(crate) commands: Latest<R::Cmd>,
    /// When damping was last requested, ns on the monotonic clock (0: never).
    pub(crate) damp_at: AtomicU64,
    pub(crate) lateness: SharedLateness<4096>,
    pub(crate) sent: Counter,
    pub(crate) damping: Counter,
    pub(crate) command_timeouts: Counter,
    pub(crate) missed_ticks: Counter,
    pub(crate) write_errors: Counter,
}

impl<R: Robot> Default for StreamShared<R> {
    fn default() -> Self {
        Self {
            commands: Latest::new(),
            damp_at: AtomicU64::new(0),
            lateness: SharedLateness::new(),
            sent: Counter::default(),
            damping: Counter::default(),
            command_timeouts: Counter::default(),
            missed_ticks: Counter::default(),
            write_errors: Counter::default(),
        }
    }
}

pub(crate) struct StreamJob<R: Robot> {
    stream: CommandStream<R>,
    writer: Writer<R::Cmd>,
    shared: Arc<StreamShared<R>>,
    seen_command: Option<Time>,
    seen_damp: u64,
    /// When idle (no command yet), wake this often to look for one (a wake makes it sooner).
    idle: Duration,
}

impl<R: Robot> StreamJob<R> {
    pub(crate) fn new(stream: CommandStream<R>, writer: Writer<R::Cmd>, shared: Arc<StreamShared<R>>) -> Self {
        Self { stream, writer, shared, seen_command: None, seen_damp: 0, idle: Duration::from_millis(50) }
    }

    fn take_inputs(&mut self, now: Time) {
        if let Some((at, command)) = self.shared.commands.read_newer(self.seen_command) {
            self.seen_command = Some(at);
            // Checked by the client already; a refusal here changes nothing.
            let _ = self.stream.handle_command(at, command);
        }
        let damp = self.shared.damp_at.load(Ordering::Acquire);
        if damp != self.seen_damp {
            self.seen_damp = damp;
            // A damping request older than the latest command is overridden by it.
            if self.seen_command.is_none_or(|at| at.as_nanos() < damp) {
                self.stream.damp(now);
            }
        }
    }

    fn write(&self, command: R::Cmd) {
        // The encoder zeroes padding and writes the CRC. Never waits: a full send window (a
        // reader that does not acknowledge) drops this one, counted; the next tick writes again.
        if self.writer.try_write(command).is_err() {
            self.shared.write_errors.add(1);
        }
    }

    /// The closing burst: damping, from the last command.
    pub(crate) fn write_closing_damping(&self, kd: f32) {
        let last = self.stream.latched().map(|(_, c)| *c).unwrap_or_default();
        let damping = R::damping(&last, kd);
        for _ in 0..CLOSING_DAMPING_FRAMES {
            self.write(damping);
        }
    }

    pub(crate) fn damping_kd(&self) -> f32 {
        self.stream.config().damping_kd
    }
}

impl<R: Robot> Job for StreamJob<R> {
    fn next_run(&mut self) -> Option<Time> {
        Some(self.stream.poll_timeout().unwrap_or_else(|| robowire_rt::now() + self.idle))
    }

    fn run(&mut self, now: Time) {
        self.take_inputs(now);
        while let Some(transmit) = self.stream.poll_transmit(now) {
            self.write(transmit.command);
            self.shared.lateness.record(micros(transmit.tick.lateness));
        }
        let c = self.stream.counters();
        let s = &self.shared;
        s.sent.set(c.sent);
        s.damping.set(c.damping);
        s.command_timeouts.set(c.command_timeouts);
        s.missed_ticks.set(c.missed_ticks);
    }
}
