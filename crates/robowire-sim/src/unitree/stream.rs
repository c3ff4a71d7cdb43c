//! The state stream every simulated Unitree robot runs on robowire's runner: it owns the body
//! and the wire faults, takes the handle's requests and what the services thread handed over,
//! steps the body and writes `rt/lowstate` without ever waiting.

use std::sync::Arc;

use lowcmd_proto::Message;
use robowire_core::cdr::{CdrEncoding, CdrType};
use robowire_core::schedule::{Periodic, Tick, Time};
use robowire_dds::Writer;
use robowire_rt::runner::Job;
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout};

use super::{Fault, Handover, Request};

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

/// Applies a request of the handle to the body and the wire.
fn apply<B: StreamBody>(body: &mut B, wire: &mut WireFaults, request: Request) {
    match request {
        Request::Inject(Fault::Silence) => wire.silent = true,
        Request::Inject(Fault::MotorFault { motor }) => body.set_motor_fault(motor, true),
        Request::Inject(Fault::BitFlips { every }) => wire.bit_flip_every = every.max(1),
        Request::ClearFaults => {
            *wire = WireFaults::default();
            body.clear_motor_faults();
        }
    }
}

/// The periodic state stream of one robot.
pub(super) struct StateStream<B: StreamBody> {
    body: B,
    wire: WireFaults,
    handover: Arc<Handover<B>>,
    writer: Writer<B::State>,
    corrupt: Writer<BitFlipped<B>>,
    grid: Periodic,
    /// The tick's step per slot, ms.
    period_ms: u32,
    last_step: Option<Time>,
    sent: u32,
}

impl<B: StreamBody> StateStream<B> {
    pub(super) fn new(
        body: B,
        handover: Arc<Handover<B>>,
        writer: Writer<B::State>,
        corrupt: Writer<BitFlipped<B>>,
        grid: Periodic,
    ) -> Self {
        let period_ms = u32::try_from(grid.period().as_millis()).unwrap_or(u32::MAX).max(1);
        Self { body, wire: WireFaults::default(), handover, writer, corrupt, grid, period_ms, last_step: None, sent: 0 }
    }

    /// One tick: step, publish, send.
    fn tick(&mut self, now: Time, tick: &Tick) {
        let h = &*self.handover;
        h.stream.record(tick, true);
        let dt = self.last_step.replace(now).map_or(0.0, |last| now.saturating_duration_since(last).as_secs_f32());
        self.body.step(dt.min(MAX_STEP_S));
        let slots = u32::try_from(tick.skipped + 1).unwrap_or(u32::MAX);
        self.body.advance_tick(self.period_ms.saturating_mul(slots));
        let state = self.body.low_state();
        h.state.write(now, &state);
        h.published.write(now, &self.body.published());
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
    }
}

impl<B: StreamBody> Job for StateStream<B> {
    fn next_run(&mut self) -> Option<Time> {
        Some(self.grid.deadline())
    }

    fn run(&mut self, now: Time) {
        let taken = self.handover.requests.take(|request| apply(&mut self.body, &mut self.wire, request));
        self.body.take(&self.handover.inbox);
        if let Some(tick) = self.grid.poll(now) {
            self.tick(now, &tick);
        }
        self.handover.requests.confirm(taken);
    }
}
