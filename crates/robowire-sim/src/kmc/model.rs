//! The chassis model, owned by the simulator's thread: the vehicle's speed as a first-order
//! response to the command, the answers to requests, the faults, the command watchdog.

use kmc_proto::{
    AfFrame, AllState, BatteryVoltage, ChassisFrame, HostFrame, MAX_FRAME_LEN, ParamId, PcControl, Rw, VehicleSpeed,
};
use std::f32::consts::PI;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use super::{ChassisSimConfig, ChassisSimStats, ChassisState, Fault, Handover, Line, Received, Request, View};

/// Wheel geometry of the model: two drive motors, 0 = left, 1 = right.
const WHEEL_RADIUS_M: f32 = 0.08;
const TRACK_WIDTH_M: f32 = 0.5;
/// How long the simulator waits for bytes before it advances the model anyway.
const POLL_INTERVAL: Duration = Duration::from_millis(5);
/// Longest a response write may block on a client that does not read.
const WRITE_TIMEOUT: Duration = Duration::from_millis(500);

/// The physics and the protocol logic, with the state, counters and pending faults: owned by
/// the simulator's thread.
pub(super) struct Model {
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
    pub(super) fn new(config: ChassisSimConfig, state: ChassisState) -> Self {
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

    pub(super) fn run(mut self, mut line: Line, handover: &Handover, stop: &AtomicBool) {
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
