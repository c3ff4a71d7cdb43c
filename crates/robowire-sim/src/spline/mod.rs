//! The ZSL-1 spline daemon on POSIX shared memory (spec `spline-shm.md`): a 1 kHz loop on
//! robowire's runner (absolute deadlines, coarse sleep then a short spin, a late cycle run once
//! and the missed ones counted) that consumes commands like the vendor daemon, drives a PD joint
//! model, publishes motor state and an IMU sample every cycle, and measures its own lateness.
//! The loop takes no lock: it owns the model and its faults, takes the handle's requests through
//! the crate's `handover` module, and publishes through seqlocks and atomics.
//!
//! [`SplineDaemon`] and [`ImuWriter`] ([`daemon`]) are the device side of the shared memory,
//! usable by any daemon.

pub mod daemon;

use std::sync::Arc;
use std::time::Duration;

use robowire_core::schedule::{Periodic, Time};
use robowire_core::timing::LatenessSummary;
use robowire_rt::Latest;
use robowire_rt::runner::{DEFAULT_SPIN, Job, Runner, RunnerOptions, Waker};
use robowire_rt::stats::Counter;
use robowire_shm::CreateOptions;
use robowire_tap::Tap;
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout};
use zsl_proto::shm::{
    IMU_SHM_NAME, JointFlags, JointIndex, Leg, NavImu, NavImuSample, SPLINE_SHM_NAME, SplineCommandBlock,
    SplineStateBlock,
};

pub use daemon::{CommandUpdate, DaemonError, ImuWriter, SplineDaemon, SplineDaemonCounters};

use crate::handover::{Requests, StreamStats};
use crate::joints::{JointModel, PdTarget};

/// Joint angles of the lying pose: abad, hip, knee (rad); the foot joint stays at 0.
pub const LYING_POSE_RAD: [f32; 3] = [0.0, 1.22, -2.7];
/// Joint angles of a standing pose: abad, hip, knee (rad).
pub const STANDING_POSE_RAD: [f32; 3] = [0.0, 0.72, -1.45];

/// Simulator settings.
#[derive(Debug, Clone)]
pub struct SplineSimConfig {
    /// Name of the spline object (default `/spline_shm`; tests use private names).
    pub spline_name: String,
    /// Name of the IMU object (default `/imu_shm`).
    pub imu_name: String,
    /// Permissions and cleanup of the objects.
    pub create: CreateOptions,
    /// Cycle period (default 1 ms).
    pub period: Duration,
    /// The last part of each wait, spent spinning (default the runner's [`DEFAULT_SPIN`]).
    pub spin: Duration,
    /// Where `/spline_shm`'s traffic goes for a recorder, as the daemon sees it: each command
    /// taken (received) and each state published (sent), a link described by
    /// `zsl_proto::description::SPLINE_DAEMON` ([`SplineDaemon::with_tap`]). Default: nowhere.
    pub tap: Option<Tap>,
    /// Where each IMU record published goes (sent; `zsl_proto::description::IMU`). Default:
    /// nowhere.
    pub imu_tap: Option<Tap>,
}

impl Default for SplineSimConfig {
    fn default() -> Self {
        Self {
            spline_name: SPLINE_SHM_NAME.into(),
            imu_name: IMU_SHM_NAME.into(),
            create: CreateOptions::default(),
            period: Duration::from_millis(1),
            spin: DEFAULT_SPIN,
            tap: None,
            imu_tap: None,
        }
    }
}

impl SplineSimConfig {
    /// Private object names (`/robowire-<tag>-<pid>-spline`, `…-imu`) so that runs never touch
    /// a robot's objects or each other's.
    pub fn private(tag: &str) -> Self {
        let pid = std::process::id();
        Self {
            spline_name: format!("/robowire-{tag}-{pid}-spline"),
            imu_name: format!("/robowire-{tag}-{pid}-imu"),
            ..Self::default()
        }
    }
}

/// What the simulator did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SplineSimStats {
    /// Cycles run.
    pub cycles: u64,
    /// Deadlines skipped because a cycle ran later than a whole period.
    pub missed_cycles: u64,
    /// Lateness of cycle starts against their absolute deadlines.
    pub lateness: LatenessSummary,
    /// The daemon's command bookkeeping.
    pub daemon: SplineDaemonCounters,
    /// IMU samples published.
    pub imu_samples: u64,
}

/// Why the simulator could not start.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SplineSimError {
    /// An object could not be created.
    #[error(transparent)]
    Daemon(#[from] DaemonError),
    /// The loop's thread.
    #[error("cannot start the simulator thread")]
    Thread(#[from] robowire_rt::RtError),
}

/// What the loop shares with the handle, none of it a lock the loop takes.
#[derive(Debug)]
struct Handover {
    requests: Requests<Request>,
    stream: StreamStats<16384>,
    imu_samples: Counter,
    daemon: Latest<DaemonCounterWords>,
    state: Latest<SplineStateBlock>,
}

/// What the handle asks of the loop.
#[derive(Debug, Clone, Copy)]
enum Request {
    Pause(bool),
    Fault { leg: Leg, joint: JointIndex, bits: u32 },
}

/// Requests the loop has not taken yet (the handle waits for each).
const REQUESTS: usize = 16;

/// [`SplineDaemonCounters`] as the seqlock carries them.
#[derive(Debug, Clone, Copy, FromBytes, IntoBytes, KnownLayout, Immutable)]
#[repr(C)]
struct DaemonCounterWords([u64; 6]);

impl From<SplineDaemonCounters> for DaemonCounterWords {
    fn from(c: SplineDaemonCounters) -> Self {
        Self([c.fresh, c.repeated, c.cleared, c.clears, c.rejected, c.states_published])
    }
}

impl From<DaemonCounterWords> for SplineDaemonCounters {
    fn from(
        DaemonCounterWords([fresh, repeated, cleared, clears, rejected, states_published]): DaemonCounterWords,
    ) -> Self {
        Self { fresh, repeated, cleared, clears, rejected, states_published }
    }
}

/// A running spline daemon simulator; dropping it stops the loop and removes its objects.
#[derive(Debug)]
pub struct SplineSim {
    config: SplineSimConfig,
    handover: Arc<Handover>,
    runner: Option<Runner<DaemonLoop>>,
    waker: Waker,
}

impl SplineSim {
    /// Creates both objects and starts the 1 kHz loop.
    pub fn spawn(config: SplineSimConfig) -> Result<Self, SplineSimError> {
        let mut daemon = SplineDaemon::create(&config.spline_name, &config.create)?;
        if let Some(tap) = &config.tap {
            daemon = daemon.with_tap(tap.clone());
        }
        let mut imu = ImuWriter::create(&config.imu_name, &config.create)?;
        if let Some(tap) = &config.imu_tap {
            imu = imu.with_tap(tap.clone());
        }
        let handover = Arc::new(Handover {
            requests: Requests::new(REQUESTS),
            stream: StreamStats::default(),
            imu_samples: Counter::default(),
            daemon: Latest::new(),
            state: Latest::new(),
        });
        let now = robowire_rt::now();
        let job = DaemonLoop {
            daemon,
            imu,
            model: JointModel::at(LYING_POSE_RAD),
            grid: Periodic::new(now + config.period, config.period),
            dt_s: config.period.as_secs_f32(),
            paused: false,
            fault_bits: [[0; 4]; 4],
            handover: handover.clone(),
        };
        let options = RunnerOptions { spin: config.spin, ..RunnerOptions::named("spline-sim") };
        let runner = Runner::spawn(options, job)?;
        let waker = runner.waker();
        Ok(Self { config, handover, runner: Some(runner), waker })
    }

    /// The configuration (object names).
    pub fn config(&self) -> &SplineSimConfig {
        &self.config
    }

    /// Counters and lateness.
    pub fn stats(&self) -> SplineSimStats {
        let h = &self.handover;
        let stream = h.stream.summary();
        SplineSimStats {
            cycles: stream.cycles,
            missed_cycles: stream.missed,
            lateness: stream.lateness,
            daemon: h.daemon.read().map(|(_, c)| c.into()).unwrap_or_default(),
            imu_samples: h.imu_samples.get(),
        }
    }

    /// The state published last.
    pub fn state(&self) -> SplineStateBlock {
        self.handover.state.read().map(|(_, state)| state).unwrap_or_default()
    }

    /// Fault: a hung daemon (no commands consumed, no state or IMU published) while `paused`.
    /// In force when this returns.
    pub fn pause(&self, paused: bool) {
        self.call(Request::Pause(paused));
    }

    /// Fault: sets fault bits (1..5 of [`JointFlags`]) on a joint's state, from the next state
    /// published on.
    pub fn inject_fault(&self, leg: Leg, joint: JointIndex, bits: u32) {
        self.call(Request::Fault { leg, joint, bits: bits & 0x3E });
    }

    fn call(&self, request: Request) {
        self.handover.requests.call(request, || self.waker.wake());
    }
}

impl Drop for SplineSim {
    fn drop(&mut self) {
        if let Some(runner) = self.runner.take() {
            runner.stop();
        }
    }
}

/// The spline daemon's view of the shared joint model.
trait SplineJoints {
    fn step_command(&mut self, command: &SplineCommandBlock, dt: f32);
    fn state(&self, command: &SplineCommandBlock, fault_bits: &[[u32; 4]; 4]) -> SplineStateBlock;
}

impl SplineJoints for JointModel {
    /// One step of `dt` seconds under `command`.
    fn step_command(&mut self, command: &SplineCommandBlock, dt: f32) {
        self.step(dt, |leg, joint| {
            let c = command.joint(Leg::ALL[leg], JointIndex::ALL[joint]);
            PdTarget {
                q_rad: c.p_des.get(),
                qd_radps: c.v_des.get(),
                kp: c.kp.get(),
                kd: c.kd.get(),
                tau_ff_nm: c.t_ff.get(),
            }
        });
    }

    fn state(&self, command: &SplineCommandBlock, fault_bits: &[[u32; 4]; 4]) -> SplineStateBlock {
        let mut state = SplineStateBlock::default();
        for leg in Leg::ALL {
            for joint in JointIndex::ALL {
                let (l, j) = (leg.index(), joint as usize);
                let c = command.joint(leg, joint);
                let enabled = c.kp.get() != 0.0 || c.kd.get() != 0.0;
                let temperature = 30 + (self.tau_nm[l][j].abs() / 3.0) as i16;
                let bits = if enabled { JointFlags::ENABLED } else { 0 } | fault_bits[l][j];
                let s = state.joint_mut(leg, joint);
                s.flags = JointFlags::new(48, temperature, bits).0.into();
                s.p = self.q_rad[l][j].into();
                s.v = self.qd_radps[l][j].into();
                s.t = self.tau_nm[l][j].into();
            }
        }
        state
    }
}

/// The daemon's cycle on the runner.
struct DaemonLoop {
    daemon: SplineDaemon,
    imu: ImuWriter,
    model: JointModel,
    grid: Periodic,
    dt_s: f32,
    /// A hung daemon: nothing consumed or published.
    paused: bool,
    /// Fault bits per joint, `[leg][joint]`.
    fault_bits: [[u32; 4]; 4],
    handover: Arc<Handover>,
}

impl Job for DaemonLoop {
    fn next_run(&mut self) -> Option<Time> {
        Some(self.grid.deadline())
    }

    fn run(&mut self, now: Time) {
        let h = &self.handover;
        let taken = h.requests.take(|request| match request {
            Request::Pause(paused) => self.paused = paused,
            Request::Fault { leg, joint, bits } => self.fault_bits[leg.index()][joint as usize] = bits,
        });
        // Requests take effect from the next cycle's state on (pausing: nothing more published).
        h.requests.confirm(taken);
        let Some(tick) = self.grid.poll(now) else { return };
        h.stream.record(&tick, !self.paused);
        if self.paused {
            return;
        }
        // Fresh, repeated or cleared: the daemon's command is what the motors get. (Region
        // errors cannot happen: the object is ours and large enough.)
        let _update: Result<CommandUpdate, _> = self.daemon.take_command();
        // Counted before the state it produces can be read: a client that sees the state sees
        // the command counted.
        h.daemon.write(now, &self.daemon.counters().into());
        self.model.step_command(self.daemon.command(), self.dt_s);
        let state = self.model.state(self.daemon.command(), &self.fault_bits);
        let _ = self.daemon.publish_state(&state);
        let record = NavImu {
            timestamp_ns: now.as_nanos().into(),
            sample: NavImuSample {
                acc: [0.0, 0.0, 9.81].map(Into::into),
                gyro: [0.0; 3].map(Into::into),
                q: [1.0, 0.0, 0.0, 0.0].map(Into::into),
            },
        };
        h.imu_samples.add(u64::from(self.imu.publish(&record).is_ok()));
        h.state.write(now, &state);
        h.daemon.write(now, &self.daemon.counters().into());
    }
}
