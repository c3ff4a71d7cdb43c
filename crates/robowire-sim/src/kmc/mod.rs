//! A KMC wheeled chassis on a pseudo-terminal (spec `kmc-uart.md`).
//!
//! The simulator is the device end of `robowire-serial` (a pseudo-terminal) with the device-side
//! decoder of `kmc-proto`; it models the
//! vehicle speed as a first-order response to the commanded velocity, answers `0xB3` speed
//! requests, battery reads (ID 0x07) and all-state reads (ID 0x06, nine slots), applies
//! writes (speed, servo, reset), and injects faults on request: garbage bytes, dropped
//! responses, a hang-up (and a re-plug at the same stable path).
//!
//! Not in the vendor protocol but in this model, as on any sane chassis: a command watchdog
//! (default 1 s) stops the wheels when `0xA5` frames stop arriving.

mod model;

use std::collections::VecDeque;
use std::io;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crossbeam_queue::ArrayQueue;
use kmc_proto::{DecoderCounters, HostFrame, HostFrameDecoder};
use robowire_rt::lock;
use robowire_serial::{Pty, PtyDevice, SerialTaps};

use crate::handover::{Published, Requests};
use model::Model;

/// Simulator settings.
#[derive(Debug, Clone)]
pub struct ChassisSimConfig {
    /// Time constant of the speed response to a velocity step.
    pub speed_time_constant: Duration,
    /// Battery voltage at start, V.
    pub battery_initial_volts: f32,
    /// Battery drain, V/s, at standstill (doubles at 1 m/s).
    pub battery_drain_volts_per_s: f32,
    /// Stop the wheels when no `0xA5` arrived for this long; `None` disables it.
    pub command_watchdog: Option<Duration>,
    /// Make a symlink here pointing at the pty, and keep it pointing at the current pty across
    /// [`ChassisSim::replug`]. Clients that open this path can reopen after a hang-up.
    pub link: Option<PathBuf>,
    /// Seed of the garbage generator, so runs are repeatable.
    pub seed: u64,
    /// Where the line's traffic goes for a recorder, as the chassis sees it (a link described by
    /// `kmc_proto::description::CHASSIS`): each host frame decoded (received), each response
    /// written (sent), and the bytes the chassis's decoder skipped (`skipped`, described by
    /// `robowire_core::json::SKIPPED_BYTES`). Injected garbage is noise, not a frame: it is not
    /// recorded here (the host's decoder records it as skipped). Default: nowhere.
    pub taps: SerialTaps,
}

impl Default for ChassisSimConfig {
    fn default() -> Self {
        Self {
            speed_time_constant: Duration::from_millis(200),
            battery_initial_volts: 25.2,
            battery_drain_volts_per_s: 0.0005,
            command_watchdog: Some(Duration::from_secs(1)),
            link: None,
            seed: 0x5eed_cafe,
            taps: SerialTaps::default(),
        }
    }
}

/// Faults to inject.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fault {
    /// Send this many random bytes before the next response. They are never `0xB3` or `0xAF`,
    /// so they are noise for the host decoder to skip, not false frame starts.
    Garbage {
        /// Bytes to send.
        bytes: usize,
    },
    /// Swallow the next `count` responses.
    DropResponses {
        /// Responses to drop.
        count: u32,
    },
    /// Hang the line up, like an unplugged adapter: the client's reads fail.
    HangUp,
}

/// What the simulated chassis is doing.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ChassisState {
    /// Last commanded velocity, m/s (0 after the watchdog stopped the wheels).
    pub commanded_velocity_mps: f32,
    /// Last commanded curvature, 1/m.
    pub commanded_curvature_per_m: f32,
    /// Modelled vehicle speed, m/s.
    pub speed_mps: f32,
    /// Distance travelled (signed), m.
    pub odometer_m: f32,
    /// Heading, rad (integrated yaw rate).
    pub heading_rad: f32,
    /// Battery voltage, V.
    pub battery_volts: f32,
    /// Last speed command written over 0xAF (ID 0x03) per motor, ERPM.
    pub speed_erpm: [f32; 2],
    /// Last servo pulse written over 0xAF (ID 0x05) per motor, µs.
    pub servo_pulse_us: [f32; 2],
}

/// What the simulator saw and did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ChassisSimStats {
    /// `0xA5` control frames received.
    pub control_frames: u64,
    /// `0xB3` speed requests received.
    pub speed_requests: u64,
    /// `0xAF` read requests received.
    pub af_reads: u64,
    /// `0xAF` writes received.
    pub af_writes: u64,
    /// System resets received.
    pub resets: u64,
    /// Responses sent.
    pub responses_sent: u64,
    /// Responses swallowed by [`Fault::DropResponses`].
    pub responses_dropped: u64,
    /// Reads the simulator has no answer for (IDs other than 0x06 / 0x07, or several IDs).
    pub unanswered_reads: u64,
    /// Garbage bytes sent by [`Fault::Garbage`].
    pub garbage_bytes_sent: u64,
    /// Times the command watchdog stopped the wheels.
    pub watchdog_stops: u64,
    /// Hang-ups performed.
    pub hang_ups: u64,
    /// The device-side decoder's counters (of the current line).
    pub decoder: DecoderCounters,
}

/// A received host frame and when it arrived.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Received {
    /// Arrival time (when the simulator read the bytes that completed it).
    pub at: Instant,
    /// The frame.
    pub frame: HostFrame,
}

/// How many received frames [`ChassisSim::received`] keeps.
pub const RECEIVED_LOG_LEN: usize = 16_384;

/// What the API asks of the simulator's thread.
#[derive(Debug)]
enum Request {
    Fault(Fault),
    /// A new line to plug in (after a hang-up).
    Plug(Pty),
}

/// What the simulator's thread publishes after each round.
#[derive(Debug, Clone, Copy, Default)]
struct View {
    state: ChassisState,
    stats: ChassisSimStats,
}

/// What the simulator's thread shares with the handle, none of it a lock the thread takes.
#[derive(Debug)]
struct Handover {
    requests: Requests<Request>,
    view: Published<View>,
    /// Frames as they arrive; the handle moves them into its log (the oldest replaced when the
    /// handle does not read).
    received: ArrayQueue<Received>,
}

/// A running simulated chassis. Dropping it stops the simulator and removes its symlink.
#[derive(Debug)]
pub struct ChassisSim {
    handover: Arc<Handover>,
    /// The current pty's path: the handle replaces the line, so it knows it.
    pty_path: Mutex<PathBuf>,
    /// The last [`RECEIVED_LOG_LEN`] frames, oldest first, as the handle collected them.
    received: Mutex<VecDeque<Received>>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
    link: Option<PathBuf>,
}

/// The device end of the line, with the chassis's decoder.
type Line = PtyDevice<HostFrameDecoder>;

/// Requests the thread has not taken yet (a fault a round; the API waits for each).
const REQUESTS: usize = 16;

impl ChassisSim {
    /// Opens a pty and starts the simulator on its own thread.
    pub fn spawn(config: ChassisSimConfig) -> io::Result<Self> {
        let line = Line::open(HostFrameDecoder::new, config.link.clone())?;
        let state = ChassisState { battery_volts: config.battery_initial_volts, ..ChassisState::default() };
        let handover = Arc::new(Handover {
            requests: Requests::new(REQUESTS),
            view: Published::new(&View { state, ..View::default() }),
            received: ArrayQueue::new(RECEIVED_LOG_LEN),
        });
        let pty_path = Mutex::new(line.pty_path().to_path_buf());
        let stop = Arc::new(AtomicBool::new(false));
        let link = config.link.clone();
        let thread = std::thread::Builder::new().name("kmc-chassis-sim".into()).spawn({
            let handover = handover.clone();
            let stop = stop.clone();
            move || Model::new(config, state).run(line, &handover, &stop)
        })?;
        Ok(Self { handover, pty_path, received: Mutex::new(VecDeque::new()), stop, thread: Some(thread), link })
    }

    /// The path a client opens: the symlink if configured, else the pty (`/dev/pts/N`).
    pub fn path(&self) -> PathBuf {
        self.link.clone().unwrap_or_else(|| self.pty_path())
    }

    /// The current pty's device path.
    pub fn pty_path(&self) -> PathBuf {
        lock(&self.pty_path).clone()
    }

    /// Injects a fault; in force when this returns.
    pub fn inject(&self, fault: Fault) {
        self.handover.requests.call(Request::Fault(fault), || {});
    }

    /// After a [`Fault::HangUp`]: plugs a new pty in and points the symlink at it.
    pub fn replug(&self) -> io::Result<PathBuf> {
        let pty = Pty::open()?;
        let path = pty.slave_path().to_path_buf();
        *lock(&self.pty_path) = path.clone();
        self.handover.requests.call(Request::Plug(pty), || {});
        Ok(path)
    }

    /// The modelled state.
    pub fn state(&self) -> ChassisState {
        self.handover.view.read().state
    }

    /// Counters.
    pub fn stats(&self) -> ChassisSimStats {
        self.handover.view.read().stats
    }

    /// The last [`RECEIVED_LOG_LEN`] frames received, oldest first.
    pub fn received(&self) -> Vec<Received> {
        let mut log = lock(&self.received);
        while let Some(frame) = self.handover.received.pop() {
            if log.len() == RECEIVED_LOG_LEN {
                log.pop_front();
            }
            log.push_back(frame);
        }
        log.iter().copied().collect()
    }
}

impl Drop for ChassisSim {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            // The line (and its symlink) goes with the thread.
            let _ = thread.join();
        }
    }
}
