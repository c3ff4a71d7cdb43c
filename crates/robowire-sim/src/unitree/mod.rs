//! What the simulated Unitree robots (the Go2, the G1) share: the handle's skeleton (a state
//! stream on robowire's runner, a services thread with its own tokio runtime, the handle's
//! requests to the stream, the log), the state stream itself with its wire faults, and the
//! services' server with `motion_switcher`. Each robot brings its body ([`StreamBody`]), its
//! inbox (what its services thread hands its stream) and its services' answers.

mod gait;
mod services;
mod stream;

use std::future::Future;
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use robowire_core::schedule::Periodic;
use robowire_core::timing::LatenessSummary;
use robowire_dds::qos::Qos;
use robowire_dds::{DdsError, Participant, ParticipantOptions, Reader, StatsHandle, TopicStats};
use robowire_rt::runner::{Runner, RunnerOptions, Waker};
use robowire_rt::stats::Counter;
use robowire_rt::{Latest, lock};
use robowire_tap::Tap;
use tokio::sync::watch;
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout};

pub(crate) use gait::{GaitAsk, Port};
pub use gait::{GaitRequest, Onboard};
pub(crate) use services::{CommandInbox, Owner, ServiceServer, answer_at_once, serve, service_server};
pub(crate) use stream::{FlipSite, StreamBody, forward_to_body};

use crate::handover::{Requests, StreamStats};
use stream::{BitFlipped, StateStream, Writers};

/// Without a command for this long the motors go passive (kp = kd = 0), s.
pub const COMMAND_HOLD_S: f32 = 0.1;

/// Faults to inject.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fault {
    /// `rt/lowstate` stops.
    Silence,
    /// Motor `motor` fails: it reports mode 0, exerts no torque (and on the Go2 counts lost
    /// frames).
    MotorFault {
        /// Motor slot (0..12 on the Go2, 0..29 on the G1).
        motor: usize,
    },
    /// Every `every`-th LowState goes out with one bit flipped after its CRC was computed.
    BitFlips {
        /// Period in samples (at least 1).
        every: u32,
    },
    /// The mode owning the motors withstands the next `releases` `motion_switcher` ReleaseModes:
    /// each is answered OK and lets nothing go, so CheckMode still names the mode (a client's
    /// release loop calls again); `u32::MAX`: it never lets go. A SelectMode does not reset it.
    ModeHeld {
        /// ReleaseModes answered without effect (`u32::MAX`: all of them).
        releases: u32,
    },
}

/// How a simulator's time runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SimClock {
    /// With the wall clock, `speed` times as fast (1.0: real time; 0 < speed ≤ [`MAX_SPEED`]).
    /// When the body cannot keep up, simulated time falls behind (the real-time factor says
    /// by how much) and each step is at most 50 ms.
    RealTime {
        /// Simulated seconds per wall second.
        speed: f32,
    },
    /// Time stands still until the handle advances it (`advance`): a test's sequence of
    /// commands and states is the same on a loaded machine.
    LockStep,
}

impl Default for SimClock {
    fn default() -> Self {
        Self::RealTime { speed: 1.0 }
    }
}

/// Where the robot's base is, when its body is simulated physics.
#[derive(Debug, Clone, Copy, PartialEq, FromBytes, IntoBytes, KnownLayout, Immutable)]
#[repr(C)]
pub struct BasePose {
    /// Position in the world, z up from the floor, m.
    pub position_m: [f32; 3],
    /// Velocity in the world, m/s.
    pub velocity_mps: [f32; 3],
    /// Roll, pitch, yaw (ZYX), rad.
    pub rpy_rad: [f32; 3],
}

/// The fastest a real-time simulator runs, × real time.
pub const MAX_SPEED: f32 = 100.0;

/// Why a lock-step simulator did not advance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum AdvanceError {
    /// The simulator runs on the wall clock.
    #[error("the simulator runs in real time; only a lock-step one is advanced")]
    NotLockStep,
    /// The state stream did not take the request within its bound (a stalled thread).
    #[error("the simulator's state stream did not answer")]
    Stalled,
}

/// What a simulated Unitree robot counts of its state stream and its services.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(not(feature = "g1"), allow(unreachable_pub, reason = "public as robowire_sim::g1::StreamCounters"))]
pub struct StreamCounters {
    /// The `rt/lowstate` writer's counters.
    pub lowstate: TopicStats,
    /// LowStates sent with a flipped bit.
    pub corrupted_states: u64,
    /// Service requests answered (one written again, as it was under its id, counted once).
    pub requests: u64,
    /// Lateness of the state stream against its absolute deadlines, µs.
    pub state_lateness: LatenessSummary,
    /// Simulated time so far, s.
    pub sim_time_s: f64,
    /// Wall time since the simulator started, s (`sim_time_s / wall_time_s`: the real-time
    /// factor).
    pub wall_time_s: f64,
}

/// Why the simulator could not start.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SimError {
    /// DDS.
    #[error(transparent)]
    Dds(#[from] DdsError),
    /// The state stream's thread.
    #[error(transparent)]
    Thread(#[from] robowire_rt::RtError),
    /// The services' thread.
    #[error("cannot start the services' thread: {0}")]
    Services(#[source] std::io::Error),
    /// A speed outside 0 < speed ≤ [`MAX_SPEED`] (or not a number).
    #[error("speed {0} is outside 0 < speed <= {MAX_SPEED}")]
    Speed(f32),
    /// The physics model cannot drive the robot.
    #[cfg(feature = "mujoco")]
    #[error(transparent)]
    Physics(#[from] crate::physics::PhysicsError),
}

/// What the user is told: the mode owning the motors and the log. Written by the services
/// thread when a mode changes and by the handle; never by the state stream.
#[derive(Debug)]
pub(crate) struct Report {
    /// The `motion_switcher` mode owning the motors; empty once released.
    pub(crate) mode: String,
    /// ReleaseModes the mode still withstands ([`Fault::ModeHeld`]; `u32::MAX`: all).
    pub(crate) held_releases: u32,
    log: Vec<String>,
}

impl Report {
    /// Booted with `mode` owning the motors, the log's first line `booted`.
    pub(crate) fn booted(mode: &str, booted: String) -> Self {
        Self { mode: mode.into(), held_releases: 0, log: vec![booted] }
    }

    pub(crate) fn say(&mut self, line: impl Into<String>) {
        self.log.push(line.into());
    }
}

/// What the state stream shares with the services thread and the handle, none of it a lock the
/// stream takes.
#[derive(Debug)]
pub(crate) struct Handover<B: StreamBody> {
    requests: Requests<Request>,
    /// What the services thread hands the stream, and its counters.
    pub(crate) inbox: B::Inbox,
    /// The state the stream sent last.
    pub(crate) state: Latest<B::State>,
    /// What the handle reads of the body, as the stream last stepped it.
    pub(crate) published: Latest<B::Published>,
    pub(crate) stream: StreamStats<4096>,
    pub(crate) corrupted: Counter,
    /// Service requests answered (the services thread).
    pub(crate) requests_answered: Counter,
    /// The body's simulated time, µs.
    pub(crate) sim_time_us: Counter,
    /// Where the base is (physics only), as the stream last stepped it (as the body started,
    /// before its first step).
    pub(crate) base: Latest<BasePose>,
}

/// What the handle asks of the state stream.
#[derive(Debug, Clone, Copy)]
enum Request {
    Inject(Fault),
    ClearFaults,
    /// Lock-step: step this many state periods.
    Advance {
        periods: u32,
    },
}

/// State periods one lock-step request steps at most (well within the handle's wait bound).
const ADVANCE_CHUNK: u32 = 50;

/// Requests the stream has not taken yet (the handle waits for each).
const REQUESTS: usize = 16;

/// Samples a lock-step stream's writers keep until the transport has sent them: a lock-step
/// request writes [`ADVANCE_CHUNK`] states at once, faster than the transport sends them, and a
/// writer keeping only the newest (Unitree's keep-last 1, with the best-effort readers of
/// Unitree's clients) would send a few of them. Local to the writer: not matched on the wire.
const LOCK_STEP_KEPT: i32 = 4 * ADVANCE_CHUNK as i32;

/// The QoS of the stream's writers under `clock`.
fn stream_qos(clock: SimClock) -> Qos {
    match clock {
        SimClock::RealTime { .. } => Qos::STREAM_WRITER,
        SimClock::LockStep => Qos { depth: LOCK_STEP_KEPT, ..Qos::STREAM_WRITER },
    }
}

/// How a robot's stream runs.
#[derive(Debug)]
pub(crate) struct StreamOptions {
    /// `rt/lowstate` period.
    pub(crate) period: Duration,
    /// Pin the stream to this CPU.
    pub(crate) cpu: Option<usize>,
    /// Where each `rt/lowstate` written goes.
    pub(crate) tap: Option<Tap>,
    /// The threads' names start with this (`"go2-sim"`).
    pub(crate) name: &'static str,
    /// Real time (at a speed) or lock-step.
    pub(crate) clock: SimClock,
}

/// Joins the domain.
pub(crate) fn join(options: &ParticipantOptions) -> Result<Arc<Participant>, SimError> {
    Ok(Arc::new(Participant::new(options.clone())?))
}

/// A reader of the commands on `topic`, each taken recorded into `tap`, and its counters.
pub(crate) fn command_reader<T: robowire_core::cdr::CdrType + Send + 'static>(
    participant: &Participant,
    topic: &str,
    tap: &Option<Tap>,
) -> Result<(Reader<T>, StatsHandle), DdsError> {
    let mut reader = participant.reader::<T>(topic, Qos::READER)?;
    reader.set_tap(tap.clone());
    let stats = reader.stats_handle();
    Ok((reader, stats))
}

/// The handle's methods every simulated Unitree robot has (`inject`, `clear_faults`,
/// `take_log`), for a handle whose field `sim` is a [`Sim`].
macro_rules! handle_methods {
    ($fault:ty) => {
        /// Injects a fault; in force when this returns.
        pub fn inject(&self, fault: $fault) {
            self.sim.inject(fault);
        }

        /// Clears every fault.
        pub fn clear_faults(&self) {
            self.sim.clear_faults();
        }

        /// The log lines since the last call (what the robot did that a user should know).
        pub fn take_log(&self) -> Vec<String> {
            self.sim.take_log()
        }

        /// Lock-step (`SimClock::LockStep`): advances simulated
        /// time by `by` (rounded to state periods, at least one), taking the latest accepted
        /// command before each period and sending each period's state; returns when done.
        pub fn advance(&self, by: std::time::Duration) -> Result<(), crate::unitree::AdvanceError> {
            self.sim.advance(by)
        }
    };
}
pub(crate) use handle_methods;

/// A running simulated robot's threads and what they share; stopped on drop.
pub(crate) struct Sim<B: StreamBody> {
    pub(crate) handover: Arc<Handover<B>>,
    pub(crate) report: Arc<Mutex<Report>>,
    lowstate: StatsHandle,
    stream: Option<Runner<StateStream<B>>>,
    waker: Waker,
    stop: watch::Sender<bool>,
    services: Option<JoinHandle<()>>,
    clock: SimClock,
    period: Duration,
    started: std::time::Instant,
    _participant: Arc<Participant>,
}

impl<B: StreamBody> std::fmt::Debug for Sim<B> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Sim").field("mode", &lock(&self.report).mode).finish_non_exhaustive()
    }
}

impl<B: StreamBody> Sim<B> {
    /// Starts the state stream of `body` on `participant`, then the services thread, which
    /// runs the future `services` makes (given the handover and the report) until the handle
    /// is dropped.
    pub(crate) fn spawn<F, Fut>(
        participant: Arc<Participant>,
        options: StreamOptions,
        body: B,
        inbox: B::Inbox,
        report: Report,
        services: impl FnOnce(Arc<Handover<B>>, Arc<Mutex<Report>>) -> F,
    ) -> Result<Self, SimError>
    where
        F: FnOnce() -> Fut + Send + 'static,
        Fut: Future<Output = ()>,
    {
        if let SimClock::RealTime { speed } = options.clock
            && !(speed > 0.0 && speed <= MAX_SPEED)
        {
            return Err(SimError::Speed(speed));
        }
        let handover = Arc::new(Handover {
            requests: Requests::new(REQUESTS),
            inbox,
            state: Latest::new(),
            published: Latest::new(),
            stream: StreamStats::default(),
            corrupted: Counter::default(),
            requests_answered: Counter::default(),
            sim_time_us: Counter::default(),
            base: Latest::new(),
        });
        handover.published.write(robowire_rt::now(), &body.published());
        // The base as the body starts, so that a snapshot taken before the stream's first step
        // (a participant is ready at once) shows it.
        if let Some(pose) = body.base_pose() {
            handover.base.write(robowire_rt::now(), &pose);
        }
        let report = Arc::new(Mutex::new(report));
        // The stream's writers never wait: a full send window is a dropped sample, counted.
        let qos = stream_qos(options.clock);
        let mut writer = participant.writer::<B::State>(<B::State as unitree_proto::Message>::TOPIC, qos)?;
        let mut corrupt = participant.writer::<BitFlipped<B>>(<B::State as unitree_proto::Message>::TOPIC, qos)?;
        writer.set_tap(options.tap.clone());
        corrupt.set_tap(options.tap);
        let lowstate = writer.stats_handle();
        let wall_period = match options.clock {
            SimClock::RealTime { speed } => options.period.div_f32(speed),
            SimClock::LockStep => options.period,
        };
        let grid = Periodic::new(robowire_rt::now(), wall_period);
        let sport = match body.base_pose() {
            Some(_) => Some(participant.writer(unitree_proto::sport_state::SPORT_MODE_STATE_TOPIC, qos)?),
            None => None,
        };
        let writers = Writers { state: writer, corrupt, sport };
        let job = StateStream::new(body, handover.clone(), writers, (options.period, grid), options.clock);
        let placement = robowire_rt::Placement { cpu: options.cpu, ..Default::default() };
        let stream = Runner::spawn(RunnerOptions::placed(format!("{}-state", options.name), placement), job)?;
        let (stop, stop_rx) = watch::channel(false);
        let tasks = services(handover.clone(), report.clone());
        let services = services::spawn(format!("{}-services", options.name), report.clone(), stop_rx, tasks)
            .map_err(SimError::Services)?;
        Ok(Self {
            handover,
            report,
            lowstate,
            waker: stream.waker(),
            stream: Some(stream),
            stop,
            services: Some(services),
            clock: options.clock,
            period: options.period,
            started: std::time::Instant::now(),
            _participant: participant,
        })
    }

    /// Lock-step: advances simulated time by `by` (rounded to state periods, at least one),
    /// each period stepped, its state published and sent; returns when done.
    pub(crate) fn advance(&self, by: Duration) -> Result<(), AdvanceError> {
        if self.clock != SimClock::LockStep {
            return Err(AdvanceError::NotLockStep);
        }
        let mut periods = ((by.as_secs_f64() / self.period.as_secs_f64()).round() as u32).max(1);
        while periods > 0 {
            let chunk = periods.min(ADVANCE_CHUNK);
            if !self.handover.requests.call(Request::Advance { periods: chunk }, || self.waker.wake()) {
                return Err(AdvanceError::Stalled);
            }
            periods -= chunk;
        }
        Ok(())
    }

    /// Injects a fault; in force when this returns. A fault of the services
    /// ([`Fault::ModeHeld`]) is set where the services thread reads it; the others go to the
    /// state stream.
    pub(crate) fn inject(&self, fault: Fault) {
        match fault {
            Fault::ModeHeld { releases } => lock(&self.report).held_releases = releases,
            Fault::Silence | Fault::MotorFault { .. } | Fault::BitFlips { .. } => {
                self.handover.requests.call(Request::Inject(fault), || self.waker.wake());
            }
        }
        lock(&self.report).say(format!("fault injected: {fault:?}"));
    }

    /// Clears every fault.
    pub(crate) fn clear_faults(&self) {
        self.handover.requests.call(Request::ClearFaults, || self.waker.wake());
        let mut report = lock(&self.report);
        report.held_releases = 0;
        report.say("faults cleared");
    }

    /// The log lines since the last call.
    pub(crate) fn take_log(&self) -> Vec<String> {
        std::mem::take(&mut lock(&self.report).log)
    }

    /// The stream's and the services' counts now.
    pub(crate) fn counters(&self) -> StreamCounters {
        let h = &self.handover;
        StreamCounters {
            lowstate: self.lowstate.get(),
            corrupted_states: h.corrupted.get(),
            requests: h.requests_answered.get(),
            state_lateness: h.stream.summary().lateness,
            sim_time_s: h.sim_time_us.get() as f64 * 1e-6,
            wall_time_s: self.started.elapsed().as_secs_f64(),
        }
    }

    /// The mode owning the motors; empty once released.
    pub(crate) fn mode(&self) -> String {
        lock(&self.report).mode.clone()
    }

    /// Where the base is (physics only), as the stream last stepped it (as the body started,
    /// before its first step).
    pub(crate) fn base(&self) -> Option<BasePose> {
        self.handover.base.read().map(|(_, pose)| pose)
    }

    /// What the stream last published of the body (published once before the stream starts).
    pub(crate) fn published(&self) -> Option<B::Published> {
        self.handover.published.read().map(|(_, p)| p)
    }
}

impl<B: StreamBody> Drop for Sim<B> {
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
