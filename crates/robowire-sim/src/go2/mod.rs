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

use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::Duration;

use lowcmd_proto::api::{motion_switcher, sport};
use lowcmd_proto::{LowCmd, LowState, Message, go2};
use robowire_core::cdr::CdrType;
use robowire_core::schedule::{Periodic, Time};
use robowire_core::timing::LatenessSummary;
use robowire_dds::qos::Qos;
use robowire_dds::{DdsError, Participant, ParticipantOptions, Reader, StatsHandle, TopicStats, Writer};
use robowire_rt::runner::{Job, Runner, RunnerOptions};
use robowire_rt::stats::{Counter, SharedLateness, micros};
use tokio::sync::watch;

pub use model::{COMMAND_HOLD_S, Go2Body, JOINTS, LYING_POSE_RAD, STAND_POSE_RAD};

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
}

impl Default for Go2SimConfig {
    fn default() -> Self {
        Self {
            participant: ParticipantOptions::default(),
            state_period: Duration::from_millis(2),
            cpu: None,
            answer_lowcmd: false,
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

/// What the state stream, the receive task and the services share (a simulator: one lock).
struct Shared {
    body: Go2Body,
    sport_mode: String,
    silent: bool,
    bit_flip_every: u32,
    log: Vec<String>,
    /// The sport mode was said to ignore LowCmds (once per ownership).
    ignore_logged: bool,
    last_command: Option<Time>,
}

#[derive(Default)]
struct Stats {
    accepted: Counter,
    ignored: Counter,
    bad_head: Counter,
    requests: Counter,
    corrupted: Counter,
    lateness: SharedLateness<4096>,
    jitter: SharedLateness<4096>,
}

fn lock(shared: &Mutex<Shared>) -> MutexGuard<'_, Shared> {
    shared.lock().unwrap_or_else(PoisonError::into_inner)
}

impl Shared {
    fn say(&mut self, line: impl Into<String>) {
        self.log.push(line.into());
    }
}

/// A running simulated Go2; stopped on drop.
pub struct Go2Sim {
    shared: Arc<Mutex<Shared>>,
    stats: Arc<Stats>,
    lowstate: StatsHandle,
    lowcmd: StatsHandle,
    stream: Option<Runner<StateStream>>,
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
        let shared = Arc::new(Mutex::new(Shared {
            body: Go2Body::new(),
            sport_mode: BOOT_SPORT_MODE.into(),
            silent: false,
            bit_flip_every: 0,
            log: vec![format!("booted lying down; sport mode \"{BOOT_SPORT_MODE}\" owns the motors")],
            ignore_logged: false,
            last_command: None,
        }));
        let stats = Arc::new(Stats::default());
        let writer = participant.writer::<LowState>(LowState::TOPIC, Qos::WRITER)?;
        let corrupt = participant.writer::<BitFlipped>(LowState::TOPIC, Qos::WRITER)?;
        let lowstate = writer.stats_handle();
        let reader = participant.reader::<LowCmd>(LowCmd::TOPIC, Qos::READER)?;
        let lowcmd = reader.stats_handle();
        let answers =
            config.answer_lowcmd.then(|| participant.writer::<LowState>(LowState::TOPIC, Qos::WRITER)).transpose()?;
        let switcher = services::service_server(&participant, motion_switcher::SERVICE)?;
        let sport = services::service_server(&participant, sport::SERVICE)?;
        let (stop, stop_rx) = watch::channel(false);
        let services = std::thread::Builder::new()
            .name("go2-sim-services".into())
            .spawn({
                let (shared, stats, period) = (shared.clone(), stats.clone(), config.state_period);
                let endpoints = services::Endpoints { lowcmd: reader, answers, switcher, sport };
                move || services::run(shared, stats, endpoints, period, stop_rx)
            })
            .map_err(Go2SimError::Services)?;
        let job = StateStream {
            shared: shared.clone(),
            stats: stats.clone(),
            writer,
            corrupt,
            grid: Periodic::new(robowire_rt::now(), config.state_period),
            period_ms: u32::try_from(config.state_period.as_millis()).unwrap_or(u32::MAX).max(1),
            last_step: None,
            sent: AtomicU32::new(0),
        };
        let stream = Runner::spawn(
            RunnerOptions::placed("go2-sim-state", robowire_rt::Placement { cpu: config.cpu, ..Default::default() }),
            job,
        )?;
        Ok(Self {
            shared,
            stats,
            lowstate,
            lowcmd,
            stream: Some(stream),
            stop,
            services: Some(services),
            _participant: participant,
        })
    }

    /// Injects a fault.
    pub fn inject(&self, fault: Go2Fault) {
        let mut s = lock(&self.shared);
        match fault {
            Go2Fault::Silence => s.silent = true,
            Go2Fault::MotorFault { motor } => s.body.set_motor_fault(motor, true),
            Go2Fault::BitFlips { every } => s.bit_flip_every = every.max(1),
        }
        s.say(format!("fault injected: {fault:?}"));
    }

    /// Clears every fault.
    pub fn clear_faults(&self) {
        let mut s = lock(&self.shared);
        s.silent = false;
        s.bit_flip_every = 0;
        for motor in 0..JOINTS {
            s.body.set_motor_fault(motor, false);
        }
        s.say("faults cleared");
    }

    /// The log lines since the last call (what the robot did that a user should know).
    pub fn take_log(&self) -> Vec<String> {
        std::mem::take(&mut lock(&self.shared).log)
    }

    /// The simulator now.
    pub fn snapshot(&self) -> Go2Snapshot {
        let reader = self.lowcmd.get();
        let s = lock(&self.shared);
        let st = &self.stats;
        Go2Snapshot {
            sport_mode: s.sport_mode.clone(),
            joints_rad: s.body.joint_positions(),
            lowcmd: LowCmdCounters {
                accepted: st.accepted.get(),
                ignored_sport_mode: st.ignored.get(),
                bad_head: st.bad_head.get(),
                bad_crc: reader.checksum_errors,
                malformed: reader.decode_errors,
            },
            lowstate: self.lowstate.get(),
            corrupted_states: st.corrupted.get(),
            requests: st.requests.get(),
            state_lateness: st.lateness.summary(),
            command_jitter: st.jitter.summary(),
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

/// The 500 Hz state stream.
struct StateStream {
    shared: Arc<Mutex<Shared>>,
    stats: Arc<Stats>,
    writer: Writer<LowState>,
    corrupt: Writer<BitFlipped>,
    grid: Periodic,
    /// The tick's step per slot, ms.
    period_ms: u32,
    last_step: Option<Time>,
    sent: AtomicU32,
}

/// Longest step of the model: after a stall the body does not jump.
const MAX_STEP_S: f32 = 0.05;

impl Job for StateStream {
    fn next_run(&mut self) -> Option<Time> {
        Some(self.grid.deadline())
    }

    fn run(&mut self, now: Time) {
        let Some(tick) = self.grid.poll(now) else { return };
        self.stats.lateness.record(micros(tick.lateness));
        let dt = self.last_step.replace(now).map_or(0.0, |last| now.saturating_duration_since(last).as_secs_f32());
        let (state, silent, flip_every) = {
            let mut s = lock(&self.shared);
            s.body.step(dt.min(MAX_STEP_S));
            let slots = u32::try_from(tick.skipped + 1).unwrap_or(u32::MAX);
            s.body.advance_tick(self.period_ms.saturating_mul(slots));
            (s.body.low_state(), s.silent, s.bit_flip_every)
        };
        if silent {
            return;
        }
        let n = self.sent.fetch_add(1, Ordering::Relaxed) + 1;
        // A failed write is counted by the writer; the next tick writes again.
        if flip_every > 0 && n.is_multiple_of(flip_every) {
            self.stats.corrupted.add(1);
            let _ = self.corrupt.write(BitFlipped { state, bit: n as usize * 7919 });
        } else {
            let _ = self.writer.write(state);
        }
    }
}

/// Whether a LowCmd has the header the Go2 expects.
fn head_ok(cmd: &LowCmd) -> bool {
    cmd.head == go2::HEAD && cmd.level_flag == go2::LEVEL_LOW
}

/// Applies one decoded LowCmd (arrived at `now`); the state right after it, if accepted.
fn on_lowcmd(shared: &Mutex<Shared>, stats: &Stats, period: Duration, cmd: &LowCmd, now: Time) -> Option<LowState> {
    let mut s = lock(shared);
    if !head_ok(cmd) {
        stats.bad_head.add(1);
        return None;
    }
    if !s.sport_mode.is_empty() {
        stats.ignored.add(1);
        if !s.ignore_logged {
            s.ignore_logged = true;
            let mode = s.sport_mode.clone();
            s.say(format!(
                "LowCmd ignored: sport mode \"{mode}\" owns the motors (release it with motion_switcher ReleaseMode); \
                 further ones are counted"
            ));
        }
        return None;
    }
    stats.accepted.add(1);
    if let Some(last) = s.last_command.replace(now) {
        stats.jitter.record(micros(now.saturating_duration_since(last).abs_diff(period)));
    }
    s.body.command(cmd);
    Some(s.body.low_state())
}

/// `Reader<LowCmd>` for the services module.
type LowCmdReader = Reader<LowCmd>;
