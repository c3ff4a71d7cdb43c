//! A policy run on a robot: wait for its state, release its controller, then the
//! [`Controller`]'s sequence every `control_dt` on robowire's runner (absolute deadlines), while
//! the facade's 500 Hz LowCmd stream holds each tick's targets. Any fault damps the robot at once
//! and ends the run with the reason; so do [`Running::stop`] and the end of the duration.

use std::sync::atomic::{AtomicBool, AtomicU8, AtomicU32, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use robowire_core::schedule::Time;
use robowire_core::timing::LatenessSummary;
use robowire_rt::runner::{Job, Runner, RunnerOptions, Waker};
use robowire_rt::stats::{SharedLateness, micros};
use tokio::sync::watch;

use crate::body::{BaseVelocity, Body, Reading};
use crate::config::PolicyConfig;
use crate::control::{Controller, Fault, Phase, STALE_STATE, StepReport, Tick};
use crate::model::OnnxPolicy;
use crate::observation::{Sensed, Term};

/// How long to wait for the robot's first LowState.
pub const FIRST_STATE: Duration = Duration::from_secs(3);

/// The velocity asked of the policy (vx m/s, vy m/s, wz rad/s), changed while it runs (a
/// joystick, `cmd_vel`, a `Move` call); lock-free.
#[derive(Debug, Default)]
pub struct CommandSlot([AtomicU32; 3]);

impl CommandSlot {
    /// A slot holding `command`.
    pub fn new(command: [f32; 3]) -> Arc<Self> {
        let slot = Arc::new(Self::default());
        slot.set(command);
        slot
    }

    /// Asks `command` from the next tick on (clamped to `max_cmd` there).
    pub fn set(&self, command: [f32; 3]) {
        for (slot, v) in self.0.iter().zip(command) {
            slot.store(v.to_bits(), Ordering::Relaxed);
        }
    }

    /// The command asked.
    pub fn get(&self) -> [f32; 3] {
        self.0.each_ref().map(|v| f32::from_bits(v.load(Ordering::Relaxed)))
    }
}

/// How to run.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// The velocity asked.
    pub command: Arc<CommandSlot>,
    /// How long the policy runs once it took over; `None`: until stopped.
    pub duration: Option<Duration>,
    /// Move to the default pose and hold it first (`deploy_real.py`'s sequence); `false`: the
    /// policy from the first tick.
    pub stand: bool,
    /// Release the robot's controller first (motion_switcher). `false` for a robot already
    /// released.
    pub release: bool,
    /// Where each policy step goes, as a frame of [`crate::record::POLICY`] (sent): a link of a
    /// capture. A copy into the tap's ring: no allocation, no lock.
    pub tap: Option<robowire_tap::Tap>,
}

impl Default for RunOptions {
    fn default() -> Self {
        Self { command: CommandSlot::new([0.0; 3]), duration: None, stand: true, release: true, tap: None }
    }
}

/// How a run ended. The robot was damped in every case.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Ended {
    /// The duration ran out.
    #[error("the duration ran out")]
    Duration,
    /// [`Running::stop`].
    #[error("stopped")]
    Stopped,
    /// The controller found a fault.
    #[error("{0}")]
    Fault(Fault),
    /// The robot's rules refused the targets.
    #[error("refused: {0}")]
    Refused(String),
}

impl Ended {
    /// `duration`, `stopped`, `fault` or `refused`.
    pub fn name(&self) -> &'static str {
        match self {
            Ended::Duration => "duration",
            Ended::Stopped => "stopped",
            Ended::Fault(_) => "fault",
            Ended::Refused(_) => "refused",
        }
    }
}

/// Why a run could not start. Nothing was sent.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum StartError {
    /// The config is for the other message family.
    #[error("msg_type: the config is for {config} robots, the device speaks {device}")]
    MsgType {
        /// The config's.
        config: crate::config::MsgType,
        /// The device's.
        device: crate::config::MsgType,
    },
    /// No LowState within [`FIRST_STATE`].
    #[error("no LowState from the robot within {} s", FIRST_STATE.as_secs())]
    NoState,
    /// The holder given holds no client of the config's robot.
    #[error("the device is not an {0} robot")]
    NoBody(crate::config::MsgType),
    /// The robot's controller would not let go.
    #[error("cannot release the robot's controller: {0}")]
    Release(String),
    /// `rt/sportmodestate` could not be read (for `base_lin_vel`).
    #[error("cannot read rt/sportmodestate for base_lin_vel")]
    SportState(#[source] robowire_dds::DdsError),
    /// The runner's thread did not start.
    #[error("cannot start the policy's thread")]
    Thread(#[from] robowire_rt::RtError),
}

/// What the job and its owner share.
#[derive(Debug)]
struct Shared {
    stop: AtomicBool,
    /// The controller's [`Phase`] (`phase_code`): the job never waits to publish it.
    phase: AtomicU8,
    ended: watch::Sender<Option<Ended>>,
    report: Mutex<StepReport>,
    /// Each tick's lateness against its deadline on the `control_dt` grid, µs.
    lateness: SharedLateness<4096>,
}

/// A policy running on a robot.
pub struct Running<H: Send + Sync + 'static, B: Body> {
    runner: Option<Runner<PolicyJob<H, B>>>,
    waker: Waker,
    shared: Arc<Shared>,
}

impl<H: Send + Sync + 'static, B: Body> std::fmt::Debug for Running<H, B> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Running").field("phase", &self.phase()).finish_non_exhaustive()
    }
}

impl<H: Send + Sync + 'static, B: Body> Running<H, B> {
    /// Damps the robot and ends the run at the next tick.
    pub fn stop(&self) {
        self.shared.stop.store(true, Ordering::Release);
        self.waker.wake();
    }

    /// Where the sequence is.
    pub fn phase(&self) -> Phase {
        phase_of(self.shared.phase.load(Ordering::Acquire))
    }

    /// How late the ticks ran against their deadlines on the `control_dt` grid, µs (the last
    /// 4096).
    pub fn tick_lateness(&self) -> LatenessSummary {
        self.shared.lateness.summary()
    }

    /// The last policy step.
    pub fn last_step(&self) -> StepReport {
        robowire_rt::lock(&self.shared.report).clone()
    }

    /// How the run ended, once it has (any executor).
    pub async fn ended(&self) -> Ended {
        let mut ended = self.shared.ended.subscribe();
        match ended.wait_for(Option::is_some).await {
            Ok(end) => end.clone().unwrap_or(Ended::Stopped),
            Err(_) => Ended::Stopped,
        }
    }
}

impl<H: Send + Sync + 'static, B: Body> Drop for Running<H, B> {
    fn drop(&mut self) {
        self.stop();
        if let Some(runner) = self.runner.take() {
            runner.join();
        }
    }
}

/// Starts `policy` for `config` on the robot's client that `body` finds in `holder` (`Some` for
/// a client held as it is, `robowire_devices::AnyDevice::g1` for a device opened by address):
/// waits for the first LowState, releases the robot's controller (`options.release`), and runs
/// the sequence on its own thread. The holder is kept (and dropped) by the run.
pub async fn start<H, B>(
    holder: Arc<H>,
    body: fn(&H) -> Option<&B>,
    config: &PolicyConfig,
    policy: OnnxPolicy,
    options: RunOptions,
) -> Result<Running<H, B>, StartError>
where
    H: Send + Sync + 'static,
    B: Body,
{
    if config.msg_type != B::MSG_TYPE {
        return Err(StartError::MsgType { config: config.msg_type, device: B::MSG_TYPE });
    }
    let robot = body(&holder).ok_or(StartError::NoBody(B::MSG_TYPE))?;
    let velocity = match config.observation.contains(&Term::BaseLinVel) {
        true => robot.base_velocity().map_err(StartError::SportState)?,
        false => None,
    };
    let motors = config.msg_type.motors();
    let (mut q, mut dq) = (vec![0.0; motors], vec![0.0; motors]);
    if !robot.wait_state(FIRST_STATE).await {
        return Err(StartError::NoState);
    }
    let reading = robot.sense(&mut q, &mut dq).filter(|r| r.age <= STALE_STATE).ok_or(StartError::NoState)?;
    if options.release {
        robot.release().await.map_err(StartError::Release)?;
    }
    let mut controller = Controller::new(config, policy, B::joint_range);
    let sensed = Sensed {
        quaternion_wxyz: reading.quaternion_wxyz,
        gyroscope_rad_s: reading.gyroscope_rad_s,
        base_velocity_world_m_s: None,
        motor_q_rad: &q,
        motor_dq_rad_s: &dq,
    };
    let now = robowire_rt::now();
    controller.start(now, &sensed, options.stand);
    let shared = Arc::new(Shared {
        stop: AtomicBool::new(false),
        phase: AtomicU8::new(phase_code(controller.phase())),
        ended: watch::Sender::new(None),
        report: Mutex::new(StepReport::default()),
        lateness: SharedLateness::new(),
    });
    let job = PolicyJob {
        holder,
        body,
        controller,
        velocity,
        command: options.command,
        duration: options.duration,
        walking_since: None,
        period: Duration::from_secs_f64(config.control_dt),
        next: now,
        q,
        dq,
        last_reading: Some((reading, now - reading.age)),
        shared: shared.clone(),
        done: false,
        tap: options.tap,
        frame: Vec::with_capacity(64 + 4 * (config.num_obs + config.num_actions)),
    };
    let runner = Runner::spawn(RunnerOptions::named("policy"), job)?;
    Ok(Running { waker: runner.waker(), runner: Some(runner), shared })
}

fn phase_code(phase: Phase) -> u8 {
    match phase {
        Phase::Standing => 0,
        Phase::Holding => 1,
        Phase::Walking => 2,
        Phase::Damped => 3,
    }
}

fn phase_of(code: u8) -> Phase {
    match code {
        0 => Phase::Standing,
        1 => Phase::Holding,
        2 => Phase::Walking,
        _ => Phase::Damped,
    }
}

/// The run on the runner's thread.
struct PolicyJob<H, B> {
    holder: Arc<H>,
    body: fn(&H) -> Option<&B>,
    controller: Controller,
    velocity: Option<Arc<BaseVelocity>>,
    command: Arc<CommandSlot>,
    duration: Option<Duration>,
    walking_since: Option<Time>,
    period: Duration,
    next: Time,
    q: Vec<f32>,
    dq: Vec<f32>,
    /// The last state read, and when it arrived.
    last_reading: Option<(Reading, Time)>,
    shared: Arc<Shared>,
    done: bool,
    tap: Option<robowire_tap::Tap>,
    /// The last step's frame for the tap.
    frame: Vec<u8>,
}

impl<H: Send + Sync + 'static, B: Body> PolicyJob<H, B> {
    /// Damps the robot and ends the run with `why`.
    fn end(&mut self, why: Ended) {
        if let Some(body) = (self.body)(&self.holder) {
            body.damp();
        }
        self.controller.stop();
        self.done = true;
        self.shared.phase.store(phase_code(Phase::Damped), Ordering::Release);
        self.shared.ended.send_replace(Some(why));
    }
}

impl<H: Send + Sync + 'static, B: Body> Job for PolicyJob<H, B> {
    fn next_run(&mut self) -> Option<Time> {
        (!self.done).then_some(self.next)
    }

    fn run(&mut self, now: Time) {
        if self.shared.stop.load(Ordering::Acquire) {
            return self.end(Ended::Stopped);
        }
        if now < self.next {
            return;
        }
        self.shared.lateness.record(micros(now.saturating_duration_since(self.next)));
        // The next deadline on the grid, skipping ticks missed.
        while self.next <= now {
            self.next = self.next + self.period;
        }
        if let (Some(since), Some(duration)) = (self.walking_since, self.duration)
            && now.saturating_duration_since(since) >= duration
        {
            return self.end(Ended::Duration);
        }
        let holder = self.holder.clone();
        let Some(body) = (self.body)(&holder) else {
            return self.end(Ended::Refused("the device no longer holds the robot's client".into()));
        };
        // A state the body could not read this tick (a writer mid-write) is the last one read,
        // as old as it is.
        let reading = match body.sense(&mut self.q, &mut self.dq) {
            Some(reading) => {
                self.last_reading = Some((reading, now - reading.age));
                Some(reading)
            }
            None => self.last_reading.map(|(last, at)| Reading { age: now.saturating_duration_since(at), ..last }),
        };
        let read_velocity = || self.velocity.as_ref().and_then(|v| v.latest(STALE_STATE));
        let sensed = reading.map(|r| {
            let sensed = Sensed {
                quaternion_wxyz: r.quaternion_wxyz,
                gyroscope_rad_s: r.gyroscope_rad_s,
                base_velocity_world_m_s: r.base_velocity_world_mps.or_else(read_velocity),
                motor_q_rad: &self.q,
                motor_dq_rad_s: &self.dq,
            };
            (sensed, r.age)
        });
        let state = sensed.as_ref().map(|(s, age)| (s, *age));
        let outcome = match self.controller.tick(now, state, self.command.get()) {
            Tick::Command(targets) => body.command(targets).err().map(Ended::Refused),
            Tick::Damp(fault) => Some(Ended::Fault(fault)),
        };
        if let Some(why) = outcome {
            return self.end(why);
        }
        let phase = self.controller.phase();
        if phase == Phase::Walking {
            self.walking_since.get_or_insert(now);
            let report = self.controller.report();
            if let Some(tap) = &self.tap
                && report.step > 0
            {
                crate::record::encode(report, &mut self.frame);
                tap.record(robowire_core::Direction::Sent, &self.frame);
            }
            if let Ok(mut shared) = self.shared.report.try_lock() {
                shared.clone_from(report);
            }
        }
        self.shared.phase.store(phase_code(phase), Ordering::Release);
    }
}
