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

use std::collections::VecDeque;
use std::f32::consts::PI;
use std::io;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use kmc_proto::{
    AfFrame, AllState, BatteryVoltage, ChassisFrame, DecoderCounters, HostFrame, HostFrameDecoder, MAX_FRAME_LEN,
    ParamId, PcControl, Rw, VehicleSpeed,
};
use robowire_serial::{Pty, PtyDevice};

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

#[derive(Debug)]
struct Shared {
    state: ChassisState,
    stats: ChassisSimStats,
    received: VecDeque<Received>,
    garbage_pending: usize,
    drop_pending: u32,
    hang_up: bool,
    /// Replaced by the thread when a re-plug opens a new pty.
    slave_path: PathBuf,
    new_pty: Option<Pty>,
}

/// A running simulated chassis. Dropping it stops the simulator and removes its symlink.
#[derive(Debug)]
pub struct ChassisSim {
    shared: Arc<Mutex<Shared>>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
    link: Option<PathBuf>,
}

/// The device end of the line, with the chassis's decoder.
type Line = PtyDevice<HostFrameDecoder>;

fn lock(shared: &Mutex<Shared>) -> MutexGuard<'_, Shared> {
    shared.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

impl ChassisSim {
    /// Opens a pty and starts the simulator on its own thread.
    pub fn spawn(config: ChassisSimConfig) -> io::Result<Self> {
        let line = Line::open(HostFrameDecoder::new, config.link.clone())?;
        let shared = Arc::new(Mutex::new(Shared {
            state: ChassisState { battery_volts: config.battery_initial_volts, ..ChassisState::default() },
            stats: ChassisSimStats::default(),
            received: VecDeque::with_capacity(RECEIVED_LOG_LEN),
            garbage_pending: 0,
            drop_pending: 0,
            hang_up: false,
            slave_path: line.pty_path().to_path_buf(),
            new_pty: None,
        }));
        let stop = Arc::new(AtomicBool::new(false));
        let link = config.link.clone();
        let thread = std::thread::Builder::new().name("kmc-chassis-sim".into()).spawn({
            let shared = shared.clone();
            let stop = stop.clone();
            move || Model::new(config).run(line, &shared, &stop)
        })?;
        Ok(Self { shared, stop, thread: Some(thread), link })
    }

    /// The path a client opens: the symlink if configured, else the pty (`/dev/pts/N`).
    pub fn path(&self) -> PathBuf {
        self.link.clone().unwrap_or_else(|| self.pty_path())
    }

    /// The current pty's device path.
    pub fn pty_path(&self) -> PathBuf {
        lock(&self.shared).slave_path.clone()
    }

    /// Injects a fault.
    pub fn inject(&self, fault: Fault) {
        let mut s = lock(&self.shared);
        match fault {
            Fault::Garbage { bytes } => s.garbage_pending += bytes,
            Fault::DropResponses { count } => s.drop_pending += count,
            Fault::HangUp => s.hang_up = true,
        }
    }

    /// After a [`Fault::HangUp`]: plugs a new pty in and points the symlink at it.
    pub fn replug(&self) -> io::Result<PathBuf> {
        let pty = Pty::open()?;
        let path = pty.slave_path().to_path_buf();
        let mut s = lock(&self.shared);
        s.slave_path = path.clone();
        s.new_pty = Some(pty);
        Ok(path)
    }

    /// The modelled state.
    pub fn state(&self) -> ChassisState {
        lock(&self.shared).state
    }

    /// Counters.
    pub fn stats(&self) -> ChassisSimStats {
        lock(&self.shared).stats
    }

    /// The last [`RECEIVED_LOG_LEN`] frames received, oldest first.
    pub fn received(&self) -> Vec<Received> {
        lock(&self.shared).received.iter().copied().collect()
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

/// Wheel geometry of the model: two drive motors, 0 = left, 1 = right.
const WHEEL_RADIUS_M: f32 = 0.08;
const TRACK_WIDTH_M: f32 = 0.5;
/// How long the simulator waits for bytes before it advances the model anyway.
const POLL_INTERVAL: Duration = Duration::from_millis(5);
/// Longest a response write may block on a client that does not read.
const WRITE_TIMEOUT: Duration = Duration::from_millis(500);

/// The physics and the protocol logic; owned by the simulator thread.
struct Model {
    config: ChassisSimConfig,
    last_update: Instant,
    last_control: Option<Instant>,
    wheel_position_deg: [f32; 2],
    rng: u64,
}

impl Model {
    fn new(config: ChassisSimConfig) -> Self {
        let rng = config.seed | 1;
        Self { config, last_update: Instant::now(), last_control: None, wheel_position_deg: [0.0; 2], rng }
    }

    fn run(mut self, mut line: Line, shared: &Mutex<Shared>, stop: &AtomicBool) {
        while !stop.load(Ordering::Relaxed) {
            {
                let mut s = lock(shared);
                if std::mem::take(&mut s.hang_up) {
                    s.stats.hang_ups += 1;
                    line.hang_up();
                }
                if let Some(new) = s.new_pty.take()
                    && line.plug_in(new).is_err()
                {
                    // The symlink could not be pointed at the new line: stay unplugged.
                    line.hang_up();
                }
            }
            let mut frames = Vec::new();
            // A read error other than "no client yet" leaves the line as it is; try again.
            let _ = line.receive(POLL_INTERVAL, |frame| frames.push(frame));
            let now = Instant::now();
            let mut responses: Vec<ChassisFrame> = Vec::new();
            let mut s = lock(shared);
            self.advance(&mut s, now);
            for frame in frames {
                if s.received.len() == RECEIVED_LOG_LEN {
                    s.received.pop_front();
                }
                s.received.push_back(Received { at: now, frame });
                if let Some(response) = self.handle(&mut s, frame, now) {
                    responses.push(response);
                }
            }
            s.stats.decoder = line.counters().decoder;
            let mut out = Vec::new();
            if !responses.is_empty() && s.garbage_pending > 0 {
                let count = std::mem::take(&mut s.garbage_pending);
                out.extend((0..count).map(|_| self.garbage_byte()));
                s.stats.garbage_bytes_sent += count as u64;
            }
            for response in responses {
                if s.drop_pending > 0 {
                    s.drop_pending -= 1;
                    s.stats.responses_dropped += 1;
                    continue;
                }
                let mut frame = [0u8; MAX_FRAME_LEN];
                if let Ok(len) = response.emit(&mut frame) {
                    out.extend_from_slice(&frame[..len]);
                    s.stats.responses_sent += 1;
                }
            }
            drop(s);
            if !out.is_empty() {
                // A client that does not read: the answer is lost, as on a real line.
                let _ = line.send(&out, WRITE_TIMEOUT);
            }
        }
    }

    /// xorshift64: repeatable noise without a dependency.
    fn garbage_byte(&mut self) -> u8 {
        loop {
            self.rng ^= self.rng << 13;
            self.rng ^= self.rng >> 7;
            self.rng ^= self.rng << 17;
            let byte = (self.rng >> 24) as u8;
            if !ChassisFrame::is_frame_id(byte) {
                return byte;
            }
        }
    }

    /// Integrates the model up to `now`.
    fn advance(&mut self, s: &mut Shared, now: Instant) {
        let dt = now.saturating_duration_since(self.last_update).as_secs_f32();
        self.last_update = now;
        if let (Some(limit), Some(last)) = (self.config.command_watchdog, self.last_control)
            && now.saturating_duration_since(last) > limit
            && s.state.commanded_velocity_mps != 0.0
        {
            s.state.commanded_velocity_mps = 0.0;
            s.state.commanded_curvature_per_m = 0.0;
            s.stats.watchdog_stops += 1;
        }
        let st = &mut s.state;
        let tau = self.config.speed_time_constant.as_secs_f32().max(1e-3);
        let previous = st.speed_mps;
        st.speed_mps = st.commanded_velocity_mps + (previous - st.commanded_velocity_mps) * (-dt / tau).exp();
        let mean_speed = 0.5 * (previous + st.speed_mps);
        st.odometer_m += mean_speed * dt;
        st.heading_rad += mean_speed * st.commanded_curvature_per_m * dt;
        for (motor, position) in self.wheel_position_deg.iter_mut().enumerate() {
            *position = (*position + wheel_speed_mps(st, motor) * dt / WHEEL_RADIUS_M * 180.0 / PI).rem_euclid(360.0);
        }
        let load = 1.0 + st.speed_mps.abs();
        st.battery_volts = (st.battery_volts - self.config.battery_drain_volts_per_s * load * dt).max(0.0);
    }

    fn handle(&mut self, s: &mut Shared, frame: HostFrame, now: Instant) -> Option<ChassisFrame> {
        match frame {
            HostFrame::PcControl(PcControl { velocity_mps, curvature_per_m }) => {
                s.stats.control_frames += 1;
                s.state.commanded_velocity_mps = velocity_mps;
                s.state.commanded_curvature_per_m = curvature_per_m;
                self.last_control = Some(now);
                None
            }
            HostFrame::VehicleSpeedRequest => {
                s.stats.speed_requests += 1;
                Some(ChassisFrame::VehicleSpeed(VehicleSpeed { speed_mps: s.state.speed_mps }))
            }
            HostFrame::Af(request) => self.handle_af(s, &request),
        }
    }

    fn handle_af(&mut self, s: &mut Shared, request: &AfFrame) -> Option<ChassisFrame> {
        let motor = request.motor_id();
        match request.rw() {
            Rw::Read => {
                s.stats.af_reads += 1;
                match request.ids() {
                    [ParamId::BatteryVoltage] => Some(ChassisFrame::BatteryVoltage(BatteryVoltage {
                        motor_id: motor,
                        volts: s.state.battery_volts,
                    })),
                    [ParamId::AllState] => Some(ChassisFrame::AllState(self.all_state(s, motor))),
                    _ => {
                        s.stats.unanswered_reads += 1;
                        None
                    }
                }
            }
            Rw::Write => {
                s.stats.af_writes += 1;
                for (i, id) in request.ids().iter().enumerate() {
                    let value = request.slot_f32(i).unwrap_or(0.0);
                    let m = usize::from(motor.min(1));
                    match id {
                        ParamId::SpeedErpm => s.state.speed_erpm[m] = value,
                        ParamId::ServoPulseUs => s.state.servo_pulse_us[m] = value,
                        ParamId::SystemReset => {
                            s.stats.resets += 1;
                            s.state.commanded_velocity_mps = 0.0;
                            s.state.commanded_curvature_per_m = 0.0;
                            s.state.speed_mps = 0.0;
                        }
                        ParamId::AllState | ParamId::BatteryVoltage => {}
                    }
                }
                None
            }
        }
    }

    fn all_state(&self, s: &Shared, motor: u8) -> AllState {
        let m = usize::from(motor.min(1));
        let wheel = wheel_speed_mps(&s.state, m);
        let speed_rpm = wheel / (2.0 * PI * WHEEL_RADIUS_M) * 60.0;
        let accel = (s.state.commanded_velocity_mps - s.state.speed_mps).abs()
            / self.config.speed_time_constant.as_secs_f32().max(1e-3);
        AllState {
            motor_id: motor,
            ids: AllState::IDS,
            id: u32::from(motor) + 1,
            position_deg: self.wheel_position_deg[m],
            speed_rpm,
            current_a: 0.4 + 0.8 * wheel.abs() + 1.5 * accel,
            temperature_c: 30.0 + 2.0 * s.state.speed_mps.abs(),
            error_code: 0,
            reserved: [0.0; 3],
        }
    }
}

/// Ground speed of one wheel of a differential drive following the commanded curvature.
fn wheel_speed_mps(state: &ChassisState, motor: usize) -> f32 {
    let side = if motor == 0 { -1.0 } else { 1.0 };
    state.speed_mps * (1.0 + side * state.commanded_curvature_per_m * TRACK_WIDTH_M / 2.0)
}
