//! The state stream every simulated Unitree robot runs on robowire's runner: it owns the body
//! and the wire faults, takes the handle's requests and what the services thread handed over,
//! steps the body and writes `rt/lowstate` without ever waiting.

use std::sync::Arc;

use robowire_core::cdr::{CdrEncoding, CdrType};
use robowire_core::schedule::{Periodic, Tick, Time};
use robowire_dds::Writer;
use robowire_rt::runner::Job;
use unitree_proto::Message;
use unitree_proto::sport_state::SportModeState;
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout};

use super::{BasePose, Fault, Handover, Request, SimClock};

/// Where a bit flip of [`Fault::BitFlips`] lands in a LowState's XCDR1 body: one of the joints'
/// `q` (data, never alignment padding, which a decoder rightly ignores).
#[derive(Debug, Clone, Copy)]
pub(crate) struct FlipSite {
    /// Body offset of motor 0's `q`, bytes.
    pub(crate) first_q: usize,
    /// Bytes from one motor's state to the next.
    pub(crate) stride: usize,
    /// Motors whose `q` may be hit.
    pub(crate) motors: usize,
}

/// A robot's body as its state stream drives it.
pub(crate) trait StreamBody: Send + 'static {
    /// The `rt/lowstate` message.
    type State: Message + CdrType + Send;
    /// What the services thread hands the stream (seqlocks, atomics) and counts.
    type Inbox: Send + Sync + std::fmt::Debug + 'static;
    /// What the handle reads of the body (joint positions, …).
    type Published: FromBytes + IntoBytes + KnownLayout + Immutable + Copy + Send + 'static;
    /// Where a bit flip lands.
    const FLIP: FlipSite;

    /// Takes what the services thread handed over since the last call. Never waits.
    fn take(&mut self, inbox: &Self::Inbox);
    /// Advances the body by `dt_s` seconds.
    fn step(&mut self, dt_s: f32);
    /// Advances the state's `tick` by `ms`.
    fn advance_tick(&mut self, ms: u32);
    /// The state the robot reports now (the CRC is written by the encoder).
    fn low_state(&self) -> Self::State;
    /// What the handle reads.
    fn published(&self) -> Self::Published;
    /// Simulated time the body has stepped, s.
    fn time_s(&self) -> f64;
    /// Where the base is; `None`: the body has none (the kinematic joint model).
    fn base_pose(&self) -> Option<BasePose>;
    /// `rt/sportmodestate`; `None`: the body has no base.
    fn sport_state(&self) -> Option<SportModeState>;
    /// Motor `motor` fails (or recovers).
    fn set_motor_fault(&mut self, motor: usize, faulted: bool);
    /// Every motor recovers.
    fn clear_motor_faults(&mut self) {
        for motor in 0..Self::FLIP.motors {
            self.set_motor_fault(motor, false);
        }
    }
}

/// The [`StreamBody`] methods a robot's stream side forwards to the inherent methods of the
/// same names of its field `body`: `step`, `advance_tick`, `low_state`, `set_motor_fault`.
macro_rules! forward_to_body {
    () => {
        fn step(&mut self, dt_s: f32) {
            self.body.step(dt_s);
        }
        fn advance_tick(&mut self, ms: u32) {
            self.body.advance_tick(ms);
        }
        fn low_state(&self) -> Self::State {
            self.body.low_state()
        }
        fn time_s(&self) -> f64 {
            self.body.time_s()
        }
        fn sport_state(&self) -> Option<unitree_proto::sport_state::SportModeState> {
            self.body.sport_state()
        }
        fn base_pose(&self) -> Option<crate::unitree::BasePose> {
            self.body.base().map(|b| crate::unitree::BasePose {
                position_m: b.position_m,
                velocity_mps: b.velocity_mps,
                rpy_rad: b.rpy_rad,
            })
        }
        fn set_motor_fault(&mut self, motor: usize, faulted: bool) {
            self.body.set_motor_fault(motor, faulted);
        }
    };
}
pub(crate) use forward_to_body;

/// A LowState with one bit flipped after sealing: what a noisy wire delivers.
pub(super) struct BitFlipped<B: StreamBody> {
    state: B::State,
    bit: usize,
}

impl<B: StreamBody> CdrType for BitFlipped<B> {
    const TYPE_NAME: &'static str = <B::State as CdrType>::TYPE_NAME;
    type Error = <B::State as CdrType>::Error;
    fn body_len(&self) -> usize {
        self.state.body_len()
    }
    fn encode_body(&self, out: &mut [u8]) -> Result<usize, robowire_core::BufferTooSmall> {
        let n = self.state.encode_body(out)?;
        let site = B::FLIP;
        let motor = self.bit % site.motors;
        let bit = (site.first_q + site.stride * motor) * 8 + (self.bit / site.motors) % 32;
        out[bit / 8] ^= 1 << (bit % 8);
        Ok(n)
    }
    fn decode_body(encoding: CdrEncoding, body: &[u8]) -> Result<Self, Self::Error> {
        <B::State as CdrType>::decode_body(encoding, body).map(|state| Self { state, bit: 0 })
    }
}

/// Longest step of the model: after a stall the body does not jump.
const MAX_STEP_S: f32 = 0.05;

/// The faults of `rt/lowstate` itself.
#[derive(Debug, Clone, Copy, Default)]
struct WireFaults {
    silent: bool,
    /// Every n-th state with a bit flipped; 0: none.
    bit_flip_every: u32,
}

/// Applies a request of the handle to the body and the wire (not [`Request::Advance`], which
/// the stream runs).
fn apply<B: StreamBody>(body: &mut B, wire: &mut WireFaults, request: Request) {
    match request {
        Request::Advance { .. } => {}
        Request::Inject(Fault::Silence) => wire.silent = true,
        Request::Inject(Fault::MotorFault { motor }) => body.set_motor_fault(motor, true),
        Request::Inject(Fault::BitFlips { every }) => wire.bit_flip_every = every.max(1),
        // The services' fault: never sent to the stream (`Sim::inject` sets it).
        Request::Inject(Fault::ModeHeld { .. }) => {}
        Request::ClearFaults => {
            *wire = WireFaults::default();
            body.clear_motor_faults();
        }
    }
}

/// What a state stream writes: `rt/lowstate`, the same with a flipped bit, and
/// `rt/sportmodestate` for a body with a base.
pub(super) struct Writers<B: StreamBody> {
    pub(super) state: Writer<B::State>,
    pub(super) corrupt: Writer<BitFlipped<B>>,
    pub(super) sport: Option<Writer<SportModeState>>,
}

/// The periodic state stream of one robot.
pub(super) struct StateStream<B: StreamBody> {
    body: B,
    wire: WireFaults,
    handover: Arc<Handover<B>>,
    writer: Writer<B::State>,
    corrupt: Writer<BitFlipped<B>>,
    /// `rt/sportmodestate`, for a body with a base.
    sport: Option<Writer<SportModeState>>,
    /// The grid in wall time (the period divided by the speed).
    grid: Periodic,
    clock: SimClock,
    /// The state period, s of simulated time.
    period_s: f32,
    /// The tick's step per slot, ms.
    period_ms: u32,
    last_step: Option<Time>,
    sent: u32,
}

impl<B: StreamBody> StateStream<B> {
    /// `period` is the state's period in simulated time; `grid` runs it in wall time.
    pub(super) fn new(
        body: B,
        handover: Arc<Handover<B>>,
        Writers { state: writer, corrupt, sport }: Writers<B>,
        (period, grid): (std::time::Duration, Periodic),
        clock: SimClock,
    ) -> Self {
        let period_ms = u32::try_from(period.as_millis()).unwrap_or(u32::MAX).max(1);
        Self {
            body,
            wire: WireFaults::default(),
            handover,
            writer,
            corrupt,
            sport,
            grid,
            clock,
            period_s: period.as_secs_f32(),
            period_ms,
            last_step: None,
            sent: 0,
        }
    }

    /// A real-time tick: step by the wall time since the last one times the speed.
    fn tick(&mut self, now: Time, tick: &Tick) {
        self.handover.stream.record(tick, true);
        let speed = match self.clock {
            SimClock::RealTime { speed } => speed,
            SimClock::LockStep => 1.0,
        };
        let dt = self.last_step.replace(now).map_or(0.0, |last| now.saturating_duration_since(last).as_secs_f32());
        let slots = u32::try_from(tick.skipped + 1).unwrap_or(u32::MAX);
        self.step_and_send(now, (dt * speed).min(MAX_STEP_S), slots);
    }

    /// Steps the body by `dt_s`, advances the tick by `slots` periods, publishes the state and
    /// sends it (unless silenced).
    fn step_and_send(&mut self, now: Time, dt_s: f32, slots: u32) {
        let h = &*self.handover;
        self.body.step(dt_s);
        h.sim_time_us.set((self.body.time_s() * 1e6) as u64);
        self.body.advance_tick(self.period_ms.saturating_mul(slots));
        let state = self.body.low_state();
        h.state.write(now, &state);
        h.published.write(now, &self.body.published());
        if let Some(pose) = self.body.base_pose() {
            h.base.write(now, &pose);
        }
        if self.wire.silent {
            return;
        }
        self.sent = self.sent.wrapping_add(1);
        // A refused write is counted by the writer; the next tick writes again.
        if self.wire.bit_flip_every > 0 && self.sent.is_multiple_of(self.wire.bit_flip_every) {
            h.corrupted.add(1);
            let _ = self.corrupt.try_write(BitFlipped { state, bit: self.sent as usize * 7919 });
        } else {
            let _ = self.writer.try_write(state);
        }
        if let (Some(writer), Some(sport)) = (&mut self.sport, self.body.sport_state()) {
            let _ = writer.try_write(sport);
        }
    }

    /// Lock-step: `periods` state periods of simulated time, each stepped, published and sent.
    fn advance(&mut self, now: Time, periods: u32) {
        for _ in 0..periods {
            self.body.take(&self.handover.inbox);
            self.step_and_send(now, self.period_s, 1);
        }
    }
}

/// How long a lock-step stream sleeps between looks at its requests (it is woken by each).
const LOCK_STEP_IDLE: std::time::Duration = std::time::Duration::from_millis(100);

impl<B: StreamBody> Job for StateStream<B> {
    fn next_run(&mut self) -> Option<Time> {
        match self.clock {
            SimClock::RealTime { .. } => Some(self.grid.deadline()),
            SimClock::LockStep => Some(robowire_rt::now() + LOCK_STEP_IDLE),
        }
    }

    fn run(&mut self, now: Time) {
        let handover = self.handover.clone();
        let taken = handover.requests.take(|request| match request {
            Request::Advance { periods } => self.advance(now, periods),
            other => apply(&mut self.body, &mut self.wire, other),
        });
        self.body.take(&handover.inbox);
        if matches!(self.clock, SimClock::RealTime { .. })
            && let Some(tick) = self.grid.poll(now)
        {
            self.tick(now, &tick);
        }
        handover.requests.confirm(taken);
    }
}
