//! A policy as a simulated robot's own locomotion (`robowire sim go2|g1 --physics --walk`): the
//! [`Walker`] runs the policy on the simulator's onboard port ([`robowire_sim::go2::Onboard`])
//! whenever the robot's sport/loco service switches its locomotion on, and hands it the velocity
//! the service was asked (`SportClient.Move`, `LocoClient.SetVelocity`). Each start is
//! `deploy_real.py`'s sequence (stand, hold, walk); switched off, the run stops.

use std::sync::atomic::{AtomicBool, AtomicU8, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use robowire_sim::go2::Onboard;
use unitree_proto::robot::{Go2, Hg, Robot};
use unitree_proto::{HgLowCmd, HgLowState, LowCmd, LowState};

use crate::body::{BaseVelocity, Body, Reading};
use crate::config::{MsgType, PolicyConfig};
use crate::control::MotorTarget;
use crate::model::{ModelError, OnnxPolicy};
use crate::run::{CommandSlot, RunOptions, Running};

/// How often the walker reads the service's request.
pub const POLL: Duration = Duration::from_millis(20);

/// A message family a simulated robot's onboard port speaks.
pub trait OnboardRobot: Robot<State: Copy + Send + Sync, Cmd: Copy + Send + Sync> + Send + Sync + 'static {
    /// The policy config's family.
    const MSG_TYPE: MsgType;
    /// The facade's body of this family (its joint ranges).
    type Facade: Body;
    /// The IMU's quaternion (w, x, y, z) and gyroscope, rad/s; each motor's angle and velocity
    /// written into `q`, `dq`.
    fn read(state: &Self::State, q: &mut [f32], dq: &mut [f32]) -> ([f32; 4], [f32; 3]);
    /// The `mode_machine` a state says (the Go2's: 0).
    fn mode_machine(state: &Self::State) -> u8;
    /// The command holding `targets` (every other motor without gains), for a robot whose
    /// state says `mode_machine`.
    fn command(targets: &[MotorTarget], mode_machine: u8) -> Result<Self::Cmd, String>;
}

fn read_motors<'a>(q: &mut [f32], dq: &mut [f32], motors: impl Iterator<Item = (f32, f32)> + 'a) {
    for ((q, dq), (pos, vel)) in q.iter_mut().zip(dq.iter_mut()).zip(motors) {
        (*q, *dq) = (pos, vel);
    }
}

impl OnboardRobot for Hg {
    const MSG_TYPE: MsgType = MsgType::Hg;
    type Facade = unitree::g1::G1;

    fn read(s: &HgLowState, q: &mut [f32], dq: &mut [f32]) -> ([f32; 4], [f32; 3]) {
        read_motors(q, dq, s.motor_state.iter().map(|m| (m.q.get(), m.dq.get())));
        (s.imu_state.quaternion.map(|v| v.get()), s.imu_state.gyroscope.map(|v| v.get()))
    }

    fn mode_machine(state: &HgLowState) -> u8 {
        state.mode_machine
    }

    fn command(targets: &[MotorTarget], mode_machine: u8) -> Result<HgLowCmd, String> {
        let mut cmd = HgLowCmd::default();
        cmd.mode_machine = mode_machine;
        for t in targets {
            let m = cmd.motor_cmd.get_mut(t.motor).ok_or_else(|| format!("motor {} is past the robot's", t.motor))?;
            *m = unitree_proto::HgMotorCmd::servo(t.q_rad, 0.0, t.kp, t.kd, 0.0);
        }
        Ok(cmd)
    }
}

impl OnboardRobot for Go2 {
    const MSG_TYPE: MsgType = MsgType::Go;
    type Facade = unitree::LowLevel<Go2>;

    fn read(s: &LowState, q: &mut [f32], dq: &mut [f32]) -> ([f32; 4], [f32; 3]) {
        read_motors(q, dq, s.motor_state.iter().map(|m| (m.q.get(), m.dq.get())));
        (s.imu_state.quaternion.map(|v| v.get()), s.imu_state.gyroscope.map(|v| v.get()))
    }

    fn mode_machine(_: &LowState) -> u8 {
        0
    }

    fn command(targets: &[MotorTarget], _: u8) -> Result<LowCmd, String> {
        let mut cmd = LowCmd::default();
        for t in targets {
            let m = cmd.motor_cmd.get_mut(t.motor).ok_or_else(|| format!("motor {} is past the robot's", t.motor))?;
            *m = unitree_proto::go2::MotorCmd::servo(t.q_rad, 0.0, t.kp, t.kd, 0.0);
        }
        Ok(cmd)
    }
}

/// A simulated robot's onboard port as a policy's [`Body`]: the state it sent last, the base's
/// velocity with it, commands checked by the robot's rules ([`Robot::check`]) and driven in
/// place of its own controller's. Nothing to release: this is the robot's controller.
pub struct OnboardBody<R: OnboardRobot> {
    port: Onboard<R::State, R::Cmd>,
    /// The last state's `mode_machine`, which commands carry.
    mode_machine: AtomicU8,
}

impl<R: OnboardRobot> OnboardBody<R> {
    /// The body on `port`.
    pub fn new(port: Onboard<R::State, R::Cmd>) -> Self {
        Self { port, mode_machine: AtomicU8::new(0) }
    }
}

impl<R: OnboardRobot> Body for OnboardBody<R> {
    const MSG_TYPE: MsgType = R::MSG_TYPE;

    fn joint_range(motor: usize) -> Option<(f32, f32)> {
        R::Facade::joint_range(motor)
    }

    fn sense(&self, q: &mut [f32], dq: &mut [f32]) -> Option<Reading> {
        let (at, state) = self.port.state()?;
        self.mode_machine.store(R::mode_machine(&state), Ordering::Relaxed);
        let (quaternion_wxyz, gyroscope_rad_s) = R::read(&state, q, dq);
        Some(Reading {
            quaternion_wxyz,
            gyroscope_rad_s,
            base_velocity_world_mps: self.port.base_velocity_world_mps(),
            age: robowire_rt::now().saturating_duration_since(at),
        })
    }

    fn command(&self, targets: &[MotorTarget]) -> Result<(), String> {
        let cmd = R::command(targets, self.mode_machine.load(Ordering::Relaxed))?;
        R::check(&cmd).map_err(|e| e.to_string())?;
        self.port.drive(&cmd);
        Ok(())
    }

    fn damp(&self) {
        if let Ok(none) = R::command(&[], self.mode_machine.load(Ordering::Relaxed)) {
            self.port.drive(&R::damping(&none, unitree_proto::robot::DAMPING_KD));
        }
    }

    async fn wait_state(&self, timeout: Duration) -> bool {
        let deadline = tokio::time::Instant::now() + timeout;
        while self.port.state().is_none() {
            if tokio::time::Instant::now() >= deadline {
                return false;
            }
            tokio::time::sleep(Duration::from_millis(2)).await;
        }
        true
    }

    async fn release(&self) -> Result<u32, String> {
        Ok(0)
    }

    fn base_velocity(&self) -> Result<Option<Arc<BaseVelocity>>, robowire_dds::DdsError> {
        Ok(None)
    }
}

/// Why a walker could not start.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WalkError {
    /// The config is for the other family.
    #[error("msg_type: the config is for {config} robots, the simulator is a {robot} robot")]
    MsgType {
        /// The config's.
        config: MsgType,
        /// The simulator's.
        robot: MsgType,
    },
    /// The model does not load or fit the config.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The walker's thread did not start.
    #[error("cannot start the walker's thread: {0}")]
    Thread(#[source] std::io::Error),
}

/// A policy walking a simulated robot while its service asks it to; stopped (the robot damped)
/// on drop.
#[derive(Debug)]
pub struct Walker {
    stop: Arc<AtomicBool>,
    log: Arc<Mutex<Vec<String>>>,
    thread: Option<JoinHandle<()>>,
}

impl Walker {
    /// Runs the policy of `config` on `port` whenever the simulator's service switches its
    /// locomotion on. The model is loaded and checked now; each start loads it afresh (its
    /// recurrent state zero).
    pub fn start<R: OnboardRobot>(port: Onboard<R::State, R::Cmd>, config: PolicyConfig) -> Result<Self, WalkError> {
        if config.msg_type != R::MSG_TYPE {
            return Err(WalkError::MsgType { config: config.msg_type, robot: R::MSG_TYPE });
        }
        OnnxPolicy::load(&config.policy_path, config.num_obs, config.num_actions)?;
        let stop = Arc::new(AtomicBool::new(false));
        let log = Arc::new(Mutex::new(Vec::new()));
        let (thread_stop, thread_log) = (stop.clone(), log.clone());
        let body = Arc::new(OnboardBody::<R>::new(port.clone()));
        let thread = std::thread::Builder::new()
            .name("walker".into())
            .spawn(move || {
                let say = |line: String| robowire_rt::lock(&thread_log).push(line);
                match tokio::runtime::Builder::new_current_thread().enable_time().build() {
                    Ok(runtime) => runtime.block_on(walk(&port, body, &config, &thread_stop, say)),
                    Err(e) => say(format!("walker: cannot start its runtime: {e}")),
                }
            })
            .map_err(WalkError::Thread)?;
        Ok(Self { stop, log, thread: Some(thread) })
    }

    /// What the walker did since the last call (starts, stops, faults).
    pub fn take_log(&self) -> Vec<String> {
        std::mem::take(&mut robowire_rt::lock(&self.log))
    }
}

impl Drop for Walker {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// The walker's loop: a run per start of the service's locomotion, the asked velocity handed to
/// it every [`POLL`].
async fn walk<R: OnboardRobot>(
    port: &Onboard<R::State, R::Cmd>,
    body: Arc<OnboardBody<R>>,
    config: &PolicyConfig,
    stop: &AtomicBool,
    say: impl Fn(String),
) {
    type Run<R> = Running<OnboardBody<R>, OnboardBody<R>>;
    let command = CommandSlot::new([0.0; 3]);
    let mut running: Option<Run<R>> = None;
    let mut started = 0;
    while !stop.load(Ordering::Acquire) {
        let request = port.request();
        command.set(request.velocity);
        if running.is_some() && (!request.on || request.starts != started) {
            running = None; // dropped: stopped, damped
            say("walker: stopped".into());
        }
        if request.on && request.starts != started {
            started = request.starts;
            running = start_run(body.clone(), config, command.clone(), &say).await;
        }
        match &running {
            Some(run) => {
                if let Ok(end) = tokio::time::timeout(POLL, run.ended()).await {
                    say(format!("walker: the policy ended ({end}); the robot is damped until its next start"));
                    running = None;
                }
            }
            None => tokio::time::sleep(POLL).await,
        }
    }
}

async fn start_run<R: OnboardRobot>(
    body: Arc<OnboardBody<R>>,
    config: &PolicyConfig,
    command: Arc<CommandSlot>,
    say: &impl Fn(String),
) -> Option<Running<OnboardBody<R>, OnboardBody<R>>> {
    let policy = match OnnxPolicy::load(&config.policy_path, config.num_obs, config.num_actions) {
        Ok(policy) => policy,
        Err(e) => {
            say(format!("walker: {e}"));
            return None;
        }
    };
    let options = RunOptions { command, duration: None, stand: true, release: false, tap: None };
    match crate::run::start(body, |b| Some(b), config, policy, options).await {
        Ok(running) => {
            say("walker: standing up, then walking".into());
            Some(running)
        }
        Err(e) => {
            say(format!("walker: cannot start: {e}"));
            None
        }
    }
}
