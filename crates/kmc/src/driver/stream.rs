//! The stream thread's job: `kmc-proto`'s sans-IO [`CommandStream`] on the runner, writing
//! frames through the serial link's synchronous writer. It never takes a lock a normal thread
//! holds: commands come through a seqlock ([`Latest`]), requests through a channel it only
//! `try_recv`s, the writer through a slot it only `try_lock`s, and statistics go out as atomics.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use kmc_proto::stream::{CommandStream, Due, StreamConfig, Transmit};
use kmc_proto::{AfFrame, HostFrame, MAX_FRAME_LEN, ParamId, PcControl};
use robowire_rt::runner::Job;
use robowire_rt::stats::{Counter, SharedLateness, micros};
use robowire_rt::{Latest, Time};
use robowire_serial::{SerialError, SyncWriter};
use zerocopy::little_endian::F32;
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout};

/// The latched command as the seqlock carries it.
#[derive(Debug, Clone, Copy, FromBytes, IntoBytes, KnownLayout, Immutable)]
#[repr(C)]
pub(super) struct CommandSlot {
    pub(super) velocity_mps: F32,
    pub(super) curvature_per_m: F32,
}

impl From<PcControl> for CommandSlot {
    fn from(c: PcControl) -> Self {
        Self { velocity_mps: c.velocity_mps.into(), curvature_per_m: c.curvature_per_m.into() }
    }
}

/// A request from the [`Driver`](super::Driver).
#[derive(Debug)]
pub(super) enum Request {
    Af(AfFrame),
    Stop,
}

/// What the stream thread shares with everyone else; all lock-free for the stream thread.
#[derive(Debug, Default)]
pub(super) struct StreamShared {
    /// The latched command and when it was set.
    pub(super) command: Latest<CommandSlot>,
    /// The command timeout, ns, as last set by the caller (0: the options' one).
    pub(super) command_timeout_ns: AtomicU64,
    /// The writer of the port as it is now; the receive thread swaps it on (re)connect.
    pub(super) writer: Mutex<Option<SyncWriter>>,
    pub(super) lateness: SharedLateness<4096>,
    pub(super) control_frames: Counter,
    pub(super) timeout_frames: Counter,
    pub(super) command_timeouts: Counter,
    pub(super) stop_frames: Counter,
    pub(super) speed_requests: Counter,
    pub(super) battery_requests: Counter,
    pub(super) all_state_requests: Counter,
    pub(super) missed_ticks: Counter,
    pub(super) write_errors: Counter,
    pub(super) bytes_written: Counter,
    pub(super) frames_written: Counter,
}

/// The job.
pub(super) struct StreamJob {
    stream: CommandStream,
    shared: Arc<StreamShared>,
    requests: mpsc::Receiver<Request>,
    writer: Option<SyncWriter>,
    /// When the command this job last took was set (a new one has another time).
    command_set_at: Option<Time>,
    /// The command timeout in force, ns.
    command_timeout_ns: u64,
    /// The stop burst's outcome: the first write error, if any.
    pub(super) stop_result: Result<(), SerialError>,
}

impl StreamJob {
    pub(super) fn new(
        now: Time,
        config: StreamConfig,
        shared: Arc<StreamShared>,
        requests: mpsc::Receiver<Request>,
    ) -> Self {
        Self {
            stream: CommandStream::new(now, config),
            shared,
            requests,
            writer: None,
            command_set_at: None,
            command_timeout_ns: 0,
            stop_result: Ok(()),
        }
    }

    /// Takes what the other threads handed over: requests, the command timeout, the command, a
    /// new writer.
    fn take_inputs(&mut self, now: Time) {
        let timeout_ns = self.shared.command_timeout_ns.load(Ordering::Acquire);
        if timeout_ns != 0 && timeout_ns != self.command_timeout_ns {
            self.command_timeout_ns = timeout_ns;
            self.stream.set_command_timeout(Duration::from_nanos(timeout_ns));
        }
        while let Ok(request) = self.requests.try_recv() {
            match request {
                Request::Af(frame) => {
                    self.stream.request(frame);
                }
                Request::Stop => self.stream.stop(),
            }
        }
        if let Some((set_at, slot)) = self.shared.command.read_newer(self.command_set_at) {
            self.command_set_at = Some(set_at);
            let command =
                PcControl { velocity_mps: slot.velocity_mps.get(), curvature_per_m: slot.curvature_per_m.get() };
            self.stream.handle_command(set_at, command);
        }
        // A new writer after a (re)connect; never wait for the slot.
        if let Ok(mut slot) = self.shared.writer.try_lock()
            && let Some(writer) = slot.take()
        {
            self.writer = Some(writer);
            self.stream.restart(now);
        }
    }

    fn send(&mut self, frame: &HostFrame) -> Result<(), SerialError> {
        let mut buf = [0u8; MAX_FRAME_LEN];
        let Ok(len) = frame.emit(&mut buf) else { return Ok(()) };
        let Some(writer) = self.writer.as_mut() else {
            return Err(SerialError::Disconnected { path: Default::default(), source: None });
        };
        let result = writer.send(&buf[..len]);
        if result.is_err() {
            // The port is gone; the receive thread reopens it and hands a new writer over.
            self.writer = None;
        }
        result
    }

    fn count(&self, transmit: &Transmit) {
        let s = &self.shared;
        s.frames_written.add(1);
        s.bytes_written.add(transmit.frame.buffer_len() as u64);
        match transmit.due {
            Due::Control { fresh, lateness, .. } => {
                s.control_frames.add(1);
                s.lateness.record(micros(lateness));
                if !fresh {
                    s.timeout_frames.add(1);
                }
            }
            Due::SpeedPoll => s.speed_requests.add(1),
            Due::BatteryPoll => s.battery_requests.add(1),
            Due::AllStatePoll { .. } => s.all_state_requests.add(1),
            Due::Request => match transmit.frame {
                HostFrame::Af(af) if af.ids() == [ParamId::BatteryVoltage] => s.battery_requests.add(1),
                HostFrame::Af(af) if af.ids() == [ParamId::AllState] => s.all_state_requests.add(1),
                _ => {}
            },
            Due::Stop => s.stop_frames.add(1),
        }
    }
}

impl Job for StreamJob {
    fn next_run(&mut self) -> Option<Time> {
        self.stream.poll_timeout()
    }

    fn run(&mut self, now: Time) {
        self.take_inputs(now);
        let connected = self.writer.is_some();
        while let Some(transmit) = self.stream.poll_transmit(now) {
            if !connected && transmit.due != Due::Stop {
                // Disconnected: the schedule goes on, nothing goes out until a new writer.
                continue;
            }
            match self.send(&transmit.frame) {
                Ok(()) => self.count(&transmit),
                Err(e) => {
                    self.shared.write_errors.add(1);
                    if transmit.due == Due::Stop && self.stop_result.is_ok() {
                        self.stop_result = Err(e);
                    }
                }
            }
        }
        let c = self.stream.counters();
        self.shared.command_timeouts.set(c.command_timeouts);
        self.shared.missed_ticks.set(c.missed_ticks);
    }
}
