//! The ZSL-1 spline daemon on POSIX shared memory (spec `spline-shm.md`): a 1 kHz loop on
//! absolute deadlines that consumes commands like the vendor daemon, drives a PD joint model,
//! publishes motor state and an IMU sample every cycle, and measures its own lateness.
//!
//! Waiting: sleep until shortly before each deadline (`spin_margin`), then spin; on this class of
//! machine a plain sleep overshoots by 50–100 µs, the spin removes that.
//!
//! [`SplineDaemon`] and [`ImuWriter`] ([`daemon`]) are the device side of the shared memory,
//! usable by any daemon.

pub mod daemon;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use robowire_core::timing::{LatenessRing, LatenessSummary};
use robowire_shm::CreateOptions;
use zsl_proto::shm::{
    IMU_SHM_NAME, JointFlags, JointIndex, Leg, NavImu, NavImuSample, SPLINE_SHM_NAME, SplineCommandBlock,
    SplineStateBlock,
};

pub use daemon::{CommandUpdate, DaemonError, ImuWriter, SplineDaemon, SplineDaemonCounters};

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
    /// Sleep until this long before a deadline, then spin (default 200 µs).
    pub spin_margin: Duration,
}

impl Default for SplineSimConfig {
    fn default() -> Self {
        Self {
            spline_name: SPLINE_SHM_NAME.into(),
            imu_name: IMU_SHM_NAME.into(),
            create: CreateOptions::default(),
            period: Duration::from_millis(1),
            spin_margin: Duration::from_micros(200),
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
    /// The thread.
    #[error("cannot start the simulator thread")]
    Thread(#[from] std::io::Error),
}

#[derive(Debug, Default)]
struct Shared {
    stats: SplineSimStats,
    lateness: LatenessRing<16384>,
    state: SplineStateBlock,
    fault_bits: [[u32; 4]; 4],
}

/// A running spline daemon simulator; dropping it stops the loop and removes its objects.
#[derive(Debug)]
pub struct SplineSim {
    config: SplineSimConfig,
    shared: Arc<Mutex<Shared>>,
    stop: Arc<AtomicBool>,
    paused: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

fn lock(shared: &Mutex<Shared>) -> MutexGuard<'_, Shared> {
    shared.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

impl SplineSim {
    /// Creates both objects and starts the 1 kHz loop.
    pub fn spawn(config: SplineSimConfig) -> Result<Self, SplineSimError> {
        let daemon = SplineDaemon::create(&config.spline_name, &config.create)?;
        let imu = ImuWriter::create(&config.imu_name, &config.create)?;
        let shared = Arc::new(Mutex::new(Shared::default()));
        let stop = Arc::new(AtomicBool::new(false));
        let paused = Arc::new(AtomicBool::new(false));
        let thread = std::thread::Builder::new().name("spline-sim".into()).spawn({
            let (shared, stop, paused, config) = (shared.clone(), stop.clone(), paused.clone(), config.clone());
            move || run(daemon, imu, &config, &shared, &stop, &paused)
        })?;
        Ok(Self { config, shared, stop, paused, thread: Some(thread) })
    }

    /// The configuration (object names).
    pub fn config(&self) -> &SplineSimConfig {
        &self.config
    }

    /// Counters and lateness.
    pub fn stats(&self) -> SplineSimStats {
        let shared = lock(&self.shared);
        SplineSimStats { lateness: shared.lateness.summary(), ..shared.stats }
    }

    /// The state published last.
    pub fn state(&self) -> SplineStateBlock {
        lock(&self.shared).state
    }

    /// Fault: a hung daemon (no commands consumed, no state or IMU published) while `paused`.
    pub fn pause(&self, paused: bool) {
        self.paused.store(paused, Ordering::Relaxed);
    }

    /// Fault: sets fault bits (1..5 of [`JointFlags`]) on a joint's state.
    pub fn inject_fault(&self, leg: Leg, joint: JointIndex, bits: u32) {
        lock(&self.shared).fault_bits[leg.index()][joint as usize] = bits & 0x3E;
    }
}

impl Drop for SplineSim {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
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

fn run(
    mut daemon: SplineDaemon,
    mut imu: ImuWriter,
    config: &SplineSimConfig,
    shared: &Mutex<Shared>,
    stop: &AtomicBool,
    paused: &AtomicBool,
) {
    let period = config.period;
    let dt = period.as_secs_f32();
    let mut model = JointModel::at(LYING_POSE_RAD);
    let mut next = Instant::now() + period;
    while !stop.load(Ordering::Relaxed) {
        let now = Instant::now();
        if next > now + config.spin_margin {
            std::thread::sleep(next - config.spin_margin - now);
        }
        while Instant::now() < next {
            std::hint::spin_loop();
        }
        let started = Instant::now();
        let lateness_us = u32::try_from(started.duration_since(next).as_micros()).unwrap_or(u32::MAX);
        if !paused.load(Ordering::Relaxed) {
            // Fresh, repeated or cleared: the daemon's command is what the motors get. (Region
            // errors cannot happen: the object is ours and large enough.)
            let _update: Result<CommandUpdate, _> = daemon.take_command();
            model.step_command(daemon.command(), dt);
            let fault_bits = lock(shared).fault_bits;
            let state = model.state(daemon.command(), &fault_bits);
            let _ = daemon.publish_state(&state);
            let record = NavImu {
                timestamp_ns: robowire_rt::monotonic_ns().into(),
                sample: NavImuSample {
                    acc: [0.0, 0.0, 9.81].map(Into::into),
                    gyro: [0.0; 3].map(Into::into),
                    q: [1.0, 0.0, 0.0, 0.0].map(Into::into),
                },
            };
            let imu_ok = imu.publish(&record).is_ok();
            let mut s = lock(shared);
            s.state = state;
            s.stats.cycles += 1;
            s.stats.daemon = daemon.counters();
            s.stats.imu_samples += u64::from(imu_ok);
            s.lateness.record(lateness_us);
        }
        next += period;
        let after = Instant::now();
        if after > next {
            let behind = (after - next).as_nanos() / period.as_nanos().max(1) + 1;
            next += period * behind as u32;
            lock(shared).stats.missed_cycles += behind as u64;
        }
    }
}
