//! A Unitree Go2 on DDS that Unitree's own software can drive (spec `unitree-dds.md`).
//!
//! It boots like the robot: the sport mode `normal` owns the motors, and a `LowCmd` that arrives
//! before `motion_switcher` ReleaseMode is ignored and counted (and said once in the log). The
//! `motion_switcher` and `sport` services answer on `rt/api/*`; `rt/lowstate` goes out at
//! 500 Hz on robowire's runner with a correct CRC; LowCmds with a bad CRC or a wrong head are
//! dropped and counted; the 12 joints follow accepted LowCmds through the shared PD joint model
//! ([`Go2Body`]), starting lying down. Faults: silence, a motor fault, bit flips on the wire.
//! Unlike a real Go2, its LowState's `reserve` echoes the last accepted LowCmd's `reserve`, and
//! it can answer each LowCmd at once ([`Go2SimConfig::answer_lowcmd`]): for round trips.
//!
//! Everything runs on `robowire-dds` (the transport), never on a facade. Create it inside a
//! network namespace whose loopback has multicast when testing on one machine
//! (`robowire_dds::netns`).

mod model;
mod services;

use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use lowcmd_proto::api::{motion_switcher, sport};
use lowcmd_proto::{LowCmd, LowState, Message, go2};
use robowire_core::cdr::CdrType;
use robowire_core::schedule::{Periodic, Tick, Time};
use robowire_core::timing::LatenessSummary;
use robowire_dds::qos::Qos;
use robowire_dds::{DdsError, Participant, ParticipantOptions, Reader, StatsHandle, TopicStats, Writer};
use robowire_rt::runner::{Job, Runner, RunnerOptions, Waker};
use robowire_rt::stats::{Counter, SharedLateness};
use robowire_rt::{Latest, lock};
use robowire_tap::Tap;
use tokio::sync::watch;

pub use model::{COMMAND_HOLD_S, Go2Body, JOINTS, LYING_POSE_RAD, STAND_POSE_RAD};

use crate::handover::{Requests, StreamStats};

/// The sport mode that owns the motors at boot.
pub const BOOT_SPORT_MODE: &str = "normal";

/// Simulator settings.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Go2SimConfig {
    /// Domain and interface (default: domain 0, the library's choice of interface).
    pub participant: ParticipantOptions,
    /// `rt/lowstate` period. Default 2 ms (500 Hz).
    pub state_period: Duration,
    /// Pin the simulator's state stream to this CPU.
    pub cpu: Option<usize>,
    /// Answer every accepted LowCmd with a LowState at once, besides the 500 Hz stream (for
    /// round-trip measurements; a real Go2 only streams).
    pub answer_lowcmd: bool,
    /// Where each `rt/lowstate` written (the corrupted ones of a fault too) and `rt/lowcmd`
    /// taken goes, as its payload: a link described by `lowcmd_proto::description::GO2_LOW_LEVEL`.
    pub low_level_tap: Option<Tap>,
    /// Where each service request taken and answer written goes
    /// (`lowcmd_proto::description::API_SERVER`).
    pub services_tap: Option<Tap>,
}

impl Default for Go2SimConfig {
    fn default() -> Self {
        Self {
            participant: ParticipantOptions::default(),
            state_period: Duration::from_millis(2),
            cpu: None,
            answer_lowcmd: false,
            low_level_tap: None,
            services_tap: None,
        }
    }
}

/// Faults to inject.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Go2Fault {
    /// `rt/lowstate` stops.
    Silence,
    /// Motor `motor` fails: it reports mode 0, exerts no torque, counts lost frames.
    MotorFault {
        /// Motor slot 0..12.
        motor: usize,
    },
    /// Every `every`-th LowState goes out with one bit flipped after its CRC was computed.
    BitFlips {
        /// Period in samples (at least 1).
        every: u32,
    },
}

/// What happened to the LowCmds that arrived.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LowCmdCounters {
    /// Accepted: the motors follow them.
    pub accepted: u64,
    /// Ignored because a sport mode owned the motors.
    pub ignored_sport_mode: u64,
    /// Dropped for a wrong `head` or `level_flag`.
    pub bad_head: u64,
    /// Dropped for a CRC mismatch (the reader's count).
    pub bad_crc: u64,
    /// Dropped because the body did not decode.
    pub malformed: u64,
}

/// The simulator now.
#[derive(Debug, Clone, PartialEq)]
pub struct Go2Snapshot {
    /// The sport mode owning the motors; empty once released.
    pub sport_mode: String,
    /// Joint positions, rad, motor order.
    pub joints_rad: [f32; JOINTS],
    /// LowCmds in.
    pub lowcmd: LowCmdCounters,
    /// The `rt/lowstate` writer's counters.
    pub lowstate: TopicStats,
    /// LowStates sent with a flipped bit.
    pub corrupted_states: u64,
    /// Service requests answered.
    pub requests: u64,
    /// Lateness of the state stream against its absolute deadlines, µs.
    pub state_lateness: LatenessSummary,
    /// |interval − 2 ms| between accepted LowCmds as they arrive, µs.
    pub command_jitter: LatenessSummary,
}

/// What the state stream shares with the services thread and the handle, none of it a lock the
/// stream takes.
#[derive(Debug)]
struct Handover {
    requests: Requests<Request>,
    /// The last accepted LowCmd, written by the services thread.
    command: Latest<LowCmd>,
    /// The state the stream sent last (for an immediate answer to a LowCmd).
    state: Latest<LowState>,
    /// Joint positions, rad, motor order, as the stream last stepped them.
    joints: Latest<[f32; JOINTS]>,
    stream: StreamStats<4096>,
    corrupted: Counter,
    /// The services thread's counters.
    accepted: Counter,
    ignored: Counter,
    bad_head: Counter,
    requests_answered: Counter,
    jitter: SharedLateness<4096>,
}

/// What the handle asks of the state stream.
#[derive(Debug, Clone, Copy)]
enum Request {
    Inject(Go2Fault),
    ClearFaults,
}

/// Requests the stream has not taken yet (the handle waits for each).
const REQUESTS: usize = 16;

/// What the user is told: the sport mode owning the motors and the log. Written by the services
/// thread when a mode changes and by the handle; never by the state stream.
#[derive(Debug)]
struct Report {
    sport_mode: String,
    log: Vec<String>,
}

impl Report {
    fn say(&mut self, line: impl Into<String>) {
        self.log.push(line.into());
    }
}

/// A running simulated Go2; stopped on drop.
pub struct Go2Sim {
    handover: Arc<Handover>,
    report: Arc<Mutex<Report>>,
    lowstate: StatsHandle,
    lowcmd: StatsHandle,
    stream: Option<Runner<StateStream>>,
    waker: Waker,
    stop: watch::Sender<bool>,
    services: Option<JoinHandle<()>>,
    _participant: Arc<Participant>,
}

impl std::fmt::Debug for Go2Sim {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Go2Sim").finish_non_exhaustive()
    }
}

/// Why the simulator could not start.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Go2SimError {
    /// DDS.
    #[error(transparent)]
    Dds(#[from] DdsError),
    /// The state stream's thread.
    #[error(transparent)]
    Thread(#[from] robowire_rt::RtError),
    /// The services' thread.
    #[error("cannot start the services' thread: {0}")]
    Services(#[source] std::io::Error),
}

impl Go2Sim {
    /// Joins the domain, starts the services, the LowCmd reader and the 500 Hz state stream.
    pub fn spawn(config: Go2SimConfig) -> Result<Self, Go2SimError> {
        let participant = Arc::new(Participant::new(config.participant.clone())?);
        let body = Go2Body::new();
        let handover = Arc::new(Handover {
            requests: Requests::new(REQUESTS),
            command: Latest::new(),
            state: Latest::new(),
            joints: Latest::new(),
            stream: StreamStats::default(),
            corrupted: Counter::default(),
            accepted: Counter::default(),
            ignored: Counter::default(),
            bad_head: Counter::default(),
            requests_answered: Counter::default(),
            jitter: SharedLateness::new(),
        });
        handover.joints.write(robowire_rt::now(), &body.joint_positions());
        let report = Arc::new(Mutex::new(Report {
            sport_mode: BOOT_SPORT_MODE.into(),
            log: vec![format!("booted lying down; sport mode \"{BOOT_SPORT_MODE}\" owns the motors")],
        }));
        // The stream's writers never wait: a full send window is a dropped sample, counted.
        let tap = &config.low_level_tap;
        let mut writer = participant.writer::<LowState>(LowState::TOPIC, Qos::STREAM_WRITER)?;
        let mut corrupt = participant.writer::<BitFlipped>(LowState::TOPIC, Qos::STREAM_WRITER)?;
        let mut reader = participant.reader::<LowCmd>(LowCmd::TOPIC, Qos::READER)?;
        writer.set_tap(tap.clone());
        corrupt.set_tap(tap.clone());
        reader.set_tap(tap.clone());
        let lowstate = writer.stats_handle();
        let lowcmd = reader.stats_handle();
        let answers = config
            .answer_lowcmd
            .then(|| {
                let mut answers = participant.writer::<LowState>(LowState::TOPIC, Qos::WRITER)?;
                answers.set_tap(tap.clone());
                Ok::<_, DdsError>(answers)
            })
            .transpose()?;
        let services_tap = config.services_tap.clone();
        let switcher = services::service_server(&participant, motion_switcher::SERVICE, services_tap.clone())?;
        let sport = services::service_server(&participant, sport::SERVICE, services_tap)?;
        let job = StateStream {
            body,
            wire: WireFaults::default(),
            handover: handover.clone(),
            writer,
            corrupt,
            grid: Periodic::new(robowire_rt::now(), config.state_period),
            period_ms: u32::try_from(config.state_period.as_millis()).unwrap_or(u32::MAX).max(1),
            last_step: None,
            seen_command: None,
            sent: 0,
        };
        let placement = robowire_rt::Placement { cpu: config.cpu, ..Default::default() };
        let stream = Runner::spawn(RunnerOptions::placed("go2-sim-state", placement), job)?;
        let (stop, stop_rx) = watch::channel(false);
        let services = std::thread::Builder::new()
            .name("go2-sim-services".into())
            .spawn({
                let (handover, report, period) = (handover.clone(), report.clone(), config.state_period);
                let endpoints = services::Endpoints { lowcmd: reader, answers, switcher, sport };
                move || services::run(&handover, &report, endpoints, period, stop_rx)
            })
            .map_err(Go2SimError::Services)?;
        Ok(Self {
            handover,
            report,
            lowstate,
            lowcmd,
            waker: stream.waker(),
            stream: Some(stream),
            stop,
            services: Some(services),
            _participant: participant,
        })
    }

    /// Injects a fault; in force when this returns.
    pub fn inject(&self, fault: Go2Fault) {
        self.handover.requests.call(Request::Inject(fault), || self.waker.wake());
        lock(&self.report).say(format!("fault injected: {fault:?}"));
    }

    /// Clears every fault.
    pub fn clear_faults(&self) {
        self.handover.requests.call(Request::ClearFaults, || self.waker.wake());
        lock(&self.report).say("faults cleared");
    }

    /// The log lines since the last call (what the robot did that a user should know).
    pub fn take_log(&self) -> Vec<String> {
        std::mem::take(&mut lock(&self.report).log)
    }

    /// The simulator now.
    pub fn snapshot(&self) -> Go2Snapshot {
        let reader = self.lowcmd.get();
        let h = &self.handover;
        Go2Snapshot {
            sport_mode: lock(&self.report).sport_mode.clone(),
            joints_rad: h.joints.read().map_or(LYING_POSE_RAD, |(_, q)| q),
            lowcmd: LowCmdCounters {
                accepted: h.accepted.get(),
                ignored_sport_mode: h.ignored.get(),
                bad_head: h.bad_head.get(),
                bad_crc: reader.checksum_errors,
                malformed: reader.decode_errors,
            },
            lowstate: self.lowstate.get(),
            corrupted_states: h.corrupted.get(),
            requests: h.requests_answered.get(),
            state_lateness: h.stream.summary().lateness,
            command_jitter: h.jitter.summary(),
        }
    }
}

impl Drop for Go2Sim {
    fn drop(&mut self) {
        if let Some(stream) = self.stream.take() {
            stream.stop();
        }
        let _ = self.stop.send(true);
        if let Some(services) = self.services.take() {
            let _ = services.join();
        }
    }
}

/// A LowState with one bit flipped after sealing: what a noisy wire delivers.
#[derive(Debug, Clone, Copy)]
struct BitFlipped {
    state: LowState,
    bit: usize,
}

impl CdrType for BitFlipped {
    const TYPE_NAME: &'static str = LowState::DDS_TYPE_NAME;
    type Error = <LowState as CdrType>::Error;
    fn body_len(&self) -> usize {
        self.state.body_len()
    }
    fn encode_body(&self, out: &mut [u8]) -> Result<usize, robowire_core::BufferTooSmall> {
        let n = self.state.encode_body(out)?;
        // A bit of one of the 12 joints' `q` (XCDR1 body offset 80 + 48·i, spec §6.3): data,
        // never alignment padding (which a decoder rightly ignores).
        let motor = self.bit % 12;
        let bit = (80 + 48 * motor) * 8 + (self.bit / 12) % 32;
        out[bit / 8] ^= 1 << (bit % 8);
        Ok(n)
    }
    fn decode_body(encoding: robowire_core::cdr::CdrEncoding, body: &[u8]) -> Result<Self, Self::Error> {
        LowState::decode_body(encoding, body).map(|state| Self { state, bit: 0 })
    }
}

/// The 500 Hz state stream: owns the body and the faults, takes the handle's requests and the
/// latest accepted LowCmd, steps the body and writes `rt/lowstate` without ever waiting.
struct StateStream {
    body: Go2Body,
    wire: WireFaults,
    handover: Arc<Handover>,
    writer: Writer<LowState>,
    corrupt: Writer<BitFlipped>,
    grid: Periodic,
    /// The tick's step per slot, ms.
    period_ms: u32,
    last_step: Option<Time>,
    /// The stamp of the LowCmd the body follows.
    seen_command: Option<Time>,
    sent: u32,
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
fn apply(body: &mut Go2Body, wire: &mut WireFaults, request: Request) {
    match request {
        Request::Inject(Go2Fault::Silence) => wire.silent = true,
        Request::Inject(Go2Fault::MotorFault { motor }) => body.set_motor_fault(motor, true),
        Request::Inject(Go2Fault::BitFlips { every }) => wire.bit_flip_every = every.max(1),
        Request::ClearFaults => {
            *wire = WireFaults::default();
            for motor in 0..JOINTS {
                body.set_motor_fault(motor, false);
            }
        }
    }
}

impl StateStream {
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
        h.joints.write(now, &self.body.joint_positions());
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

impl Job for StateStream {
    fn next_run(&mut self) -> Option<Time> {
        Some(self.grid.deadline())
    }

    fn run(&mut self, now: Time) {
        let taken = self.handover.requests.take(|request| apply(&mut self.body, &mut self.wire, request));
        if let Some((at, command)) = self.handover.command.read_newer(self.seen_command) {
            self.seen_command = Some(at);
            self.body.command(&command);
        }
        if let Some(tick) = self.grid.poll(now) {
            self.tick(now, &tick);
        }
        self.handover.requests.confirm(taken);
    }
}

/// Whether a LowCmd has the header the Go2 expects.
fn head_ok(cmd: &LowCmd) -> bool {
    cmd.head == go2::HEAD && cmd.level_flag == go2::LEVEL_LOW
}

/// `Reader<LowCmd>` for the services module.
type LowCmdReader = Reader<LowCmd>;
