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
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crossbeam_queue::ArrayQueue;
use kmc_proto::{
    AfFrame, AllState, BatteryVoltage, ChassisFrame, DecoderCounters, HostFrame, HostFrameDecoder, MAX_FRAME_LEN,
    ParamId, PcControl, Rw, VehicleSpeed,
};
use robowire_rt::lock;
use robowire_serial::{Pty, PtyDevice, SerialTaps};

use crate::handover::{Published, Requests};

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

/// Wheel geometry of the model: two drive motors, 0 = left, 1 = right.
const WHEEL_RADIUS_M: f32 = 0.08;
const TRACK_WIDTH_M: f32 = 0.5;
/// How long the simulator waits for bytes before it advances the model anyway.
const POLL_INTERVAL: Duration = Duration::from_millis(5);
/// Longest a response write may block on a client that does not read.
const WRITE_TIMEOUT: Duration = Duration::from_millis(500);

/// The physics and the protocol logic, with the state, counters and pending faults: owned by
/// the simulator's thread.
struct Model {
    config: ChassisSimConfig,
    state: ChassisState,
    stats: ChassisSimStats,
    garbage_pending: usize,
    drop_pending: u32,
    last_update: Instant,
    last_control: Option<Instant>,
    wheel_position_deg: [f32; 2],
    rng: u64,
    /// A round's frames, answers and bytes out (kept to reuse their memory).
    frames: Vec<HostFrame>,
    responses: Vec<ChassisFrame>,
    out: Vec<u8>,
    /// Where each response sits in `out`, for the taps.
    out_frames: Vec<std::ops::Range<usize>>,
}

impl Model {
    fn new(config: ChassisSimConfig, state: ChassisState) -> Self {
        let rng = config.seed | 1;
        Self {
            config,
            state,
            stats: ChassisSimStats::default(),
            garbage_pending: 0,
            drop_pending: 0,
            last_update: Instant::now(),
            last_control: None,
            wheel_position_deg: [0.0; 2],
            rng,
            frames: Vec::new(),
            responses: Vec::new(),
            out: Vec::new(),
            out_frames: Vec::new(),
        }
    }

    fn run(mut self, mut line: Line, handover: &Handover, stop: &AtomicBool) {
        line.set_taps(self.config.taps.clone());
        while !stop.load(Ordering::Relaxed) {
            self.frames.clear();
            // A read error other than "no client yet" leaves the line as it is; try again.
            let _ = line.receive(POLL_INTERVAL, |frame| self.frames.push(frame));
            // Faults asked for until now apply to this round's answers.
            let taken = handover.requests.take(|request| self.apply(request, &mut line));
            let now = Instant::now();
            self.advance(now);
            self.responses.clear();
            for i in 0..self.frames.len() {
                let frame = self.frames[i];
                // The oldest is replaced when the handle does not collect them.
                let _ = handover.received.force_push(Received { at: now, frame });
                if let Some(response) = self.handle(frame, now) {
                    self.responses.push(response);
                }
            }
            self.stats.decoder = line.counters().decoder;
            self.emit_responses();
            // Published before the answers go out: a client that got one sees its effect.
            handover.view.publish(&View { state: self.state, stats: self.stats });
            handover.requests.confirm(taken);
            if !self.out.is_empty() {
                // A client that does not read: the answer is lost, as on a real line.
                if line.send(&self.out, WRITE_TIMEOUT).is_ok() {
                    for frame in &self.out_frames {
                        self.config.taps.sent(&self.out[frame.clone()]);
                    }
                }
            }
        }
    }

    fn apply(&mut self, request: Request, line: &mut Line) {
        match request {
            Request::Fault(Fault::Garbage { bytes }) => {
                self.garbage_pending = self.garbage_pending.saturating_add(bytes)
            }
            Request::Fault(Fault::DropResponses { count }) => {
                self.drop_pending = self.drop_pending.saturating_add(count)
            }
            Request::Fault(Fault::HangUp) => {
                self.stats.hang_ups += 1;
                line.hang_up();
            }
            Request::Plug(pty) => {
                if line.plug_in(pty).is_err() {
                    // The symlink could not be pointed at the new line: stay unplugged.
                    line.hang_up();
                }
            }
        }
    }

    /// This round's answers as bytes in `out`, after the garbage and without the dropped ones.
    fn emit_responses(&mut self) {
        self.out.clear();
        self.out_frames.clear();
        if !self.responses.is_empty() && self.garbage_pending > 0 {
            let count = std::mem::take(&mut self.garbage_pending);
            for _ in 0..count {
                let byte = self.garbage_byte();
                self.out.push(byte);
            }
            self.stats.garbage_bytes_sent += count as u64;
        }
        for response in &self.responses {
            if self.drop_pending > 0 {
                self.drop_pending -= 1;
                self.stats.responses_dropped += 1;
                continue;
            }
            let mut frame = [0u8; MAX_FRAME_LEN];
            if let Ok(len) = response.emit(&mut frame) {
                self.out_frames.push(self.out.len()..self.out.len() + len);
                self.out.extend_from_slice(&frame[..len]);
                self.stats.responses_sent += 1;
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
    fn advance(&mut self, now: Instant) {
        let dt = now.saturating_duration_since(self.last_update).as_secs_f32();
        self.last_update = now;
        if let (Some(limit), Some(last)) = (self.config.command_watchdog, self.last_control)
            && now.saturating_duration_since(last) > limit
            && self.state.commanded_velocity_mps != 0.0
        {
            self.state.commanded_velocity_mps = 0.0;
            self.state.commanded_curvature_per_m = 0.0;
            self.stats.watchdog_stops += 1;
        }
        let st = &mut self.state;
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

    fn handle(&mut self, frame: HostFrame, now: Instant) -> Option<ChassisFrame> {
        match frame {
            HostFrame::PcControl(PcControl { velocity_mps, curvature_per_m }) => {
                self.stats.control_frames += 1;
                self.state.commanded_velocity_mps = velocity_mps;
                self.state.commanded_curvature_per_m = curvature_per_m;
                self.last_control = Some(now);
                None
            }
            HostFrame::VehicleSpeedRequest => {
                self.stats.speed_requests += 1;
                Some(ChassisFrame::VehicleSpeed(VehicleSpeed { speed_mps: self.state.speed_mps }))
            }
            HostFrame::Af(request) => self.handle_af(&request),
        }
    }

    fn handle_af(&mut self, request: &AfFrame) -> Option<ChassisFrame> {
        let motor = request.motor_id();
        match request.rw() {
            Rw::Read => {
                self.stats.af_reads += 1;
                match request.ids() {
                    [ParamId::BatteryVoltage] => Some(ChassisFrame::BatteryVoltage(BatteryVoltage {
                        motor_id: motor,
                        volts: self.state.battery_volts,
                    })),
                    [ParamId::AllState] => Some(ChassisFrame::AllState(self.all_state(motor))),
                    _ => {
                        self.stats.unanswered_reads += 1;
                        None
                    }
                }
            }
            Rw::Write => {
                self.stats.af_writes += 1;
                for (i, id) in request.ids().iter().enumerate() {
                    let value = request.slot_f32(i).unwrap_or(0.0);
                    let m = usize::from(motor.min(1));
                    match id {
                        ParamId::SpeedErpm => self.state.speed_erpm[m] = value,
                        ParamId::ServoPulseUs => self.state.servo_pulse_us[m] = value,
                        ParamId::SystemReset => {
                            self.stats.resets += 1;
                            self.state.commanded_velocity_mps = 0.0;
                            self.state.commanded_curvature_per_m = 0.0;
                            self.state.speed_mps = 0.0;
                        }
                        ParamId::AllState | ParamId::BatteryVoltage => {}
                    }
                }
                None
            }
        }
    }

    fn all_state(&self, motor: u8) -> AllState {
        let m = usize::from(motor.min(1));
        let wheel = wheel_speed_mps(&self.state, m);
        let speed_rpm = wheel / (2.0 * PI * WHEEL_RADIUS_M) * 60.0;
        let accel = (self.state.commanded_velocity_mps - self.state.speed_mps).abs()
            / self.config.speed_time_constant.as_secs_f32().max(1e-3);
        AllState {
            motor_id: motor,
            ids: AllState::IDS,
            id: u32::from(motor) + 1,
            position_deg: self.wheel_position_deg[m],
            speed_rpm,
            current_a: 0.4 + 0.8 * wheel.abs() + 1.5 * accel,
            temperature_c: 30.0 + 2.0 * self.state.speed_mps.abs(),
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
