//! The ZSL-1 / ZSL-1W dog on UDP (spec `zsl1-udp.md` §11): HighLevel commands on 43997, LowLevel
//! on 43900, state to each client at 500 Hz, and at once when a command changes.
//!
//! [`DogModel`] is the robot, sans I/O: a state machine over the vendor's modes with timed
//! transitions, body velocity and position integrated from `move`, joint poses driven through
//! the shared PD joint model, LowLevel PD control of the twelve motors, battery drain, and
//! injectable faults. [`DogSim`] runs it on a thread with two sockets.
//!
//! The reported mode mirrors the commanded mode as soon as a command changes it (§11.4: the
//! vendor's client counts a call as unacknowledged until it does); what the body does takes
//! time: standing up 1.2 s, lying down 1.0 s, tricks 0.8–2.0 s, after which the dog stands.

use std::io;
use std::net::{IpAddr, Ipv4Addr, SocketAddr, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use robowire_core::DatagramCodec;
use rustix::event::{PollFd, PollFlags, Timespec, poll};
use zsl_proto::codec::{HighLevelDogCodec, LowLevelDogCodec};
use zsl_proto::udp::{
    Action, ControlMode, HIGH_LEVEL_PORT, HIGH_LEVEL_STATE_HEADER, HighLevelCommand, HighLevelState, LOW_LEVEL_PORT,
    LowLevelCommand, LowLevelState, MAGIC_ZSL1, Model, ReturnCode,
};
use zsl_proto::zerocopy::little_endian::F32;

use crate::joints::{JointModel, PdTarget};
use crate::spline::{LYING_POSE_RAD, STANDING_POSE_RAD};

/// Body height standing and lying, m.
pub const STANDING_HEIGHT_M: f32 = 0.30;
/// Body height lying, m.
pub const LYING_HEIGHT_M: f32 = 0.10;
/// Wheel radius of the ZSL-1W, m (foot joint angle integrates forward speed).
const WHEEL_RADIUS_M: f32 = 0.08;
/// Time constant of the body's velocity response, s.
const VELOCITY_TAU_S: f32 = 0.08;
/// A LowLevel command keeps the motors under LowLevel control this long, s.
const LOW_LEVEL_HOLD_S: f32 = 0.1;
/// Without a HighLevel command for this long the dog stops walking (it keeps its mode), s.
pub const COMMAND_TIMEOUT_S: f32 = 0.5;

/// What the body is doing (the mode says what was asked).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Activity {
    /// Lying, joints locked (mode 51) or free (10).
    Lying,
    /// Motors damped (mode 0).
    Passive,
    /// Getting up.
    StandingUp,
    /// Standing still or walking in place.
    Standing,
    /// Walking (mode 18); ZSL-1W crawling or climbing too.
    Walking,
    /// Lying down.
    LyingDown,
    /// A trick in progress.
    Trick(Action),
    /// Standing on the hind legs (sticky action 7).
    TwoLegStand,
    /// Attitude control in mode 21.
    Attitude,
    /// The twelve motors follow LowLevel commands.
    LowLevel,
}

/// A fault the simulator can inject.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DogFault {
    /// Report this error word at state 0x1F4 (e.g. 0x3011 motor fault).
    ErrorWord(ReturnCode),
    /// Raise the "SDK mismatch" flag (state 0x1F8 = 1).
    SdkMismatch,
    /// Send no state at all.
    Silence,
    /// Send 600-byte junk datagrams instead of state.
    Garbage,
}

/// The faults active now.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Faults {
    /// Error word reported, if any.
    pub error_word: Option<ReturnCode>,
    /// SDK mismatch flag raised (injected, or a command with the other model's magic arrived).
    pub sdk_mismatch: bool,
    /// No state sent.
    pub silence: bool,
    /// Junk sent instead of state.
    pub garbage: bool,
}

/// The robot, sans I/O. Feed it commands and time; read its state datagrams.
#[derive(Debug, Clone)]
pub struct DogModel {
    model: Model,
    mode: ControlMode,
    activity: Activity,
    /// Seconds left in the current transition or trick.
    remaining_s: f32,
    command: HighLevelCommand,
    command_age_s: f32,
    low_level: Option<LowLevelCommand>,
    low_level_age_s: f32,
    joints: JointModel,
    /// Body-frame velocity x, y (m/s) and yaw rate (rad/s).
    velocity: [f32; 3],
    position_m: [f32; 3],
    rpy_rad: [f32; 3],
    rpy_rate_radps: [f32; 3],
    wheel_rad: f32,
    battery_percent: f32,
    faults: Faults,
    tricks_done: u32,
    distance_m: f32,
}

impl DogModel {
    /// A dog of `model` lying on the floor with a full battery.
    pub fn new(model: Model) -> Self {
        Self {
            model,
            mode: ControlMode::LieDown,
            activity: Activity::Lying,
            remaining_s: 0.0,
            command: HighLevelCommand::lie_down(),
            command_age_s: 0.0,
            low_level: None,
            low_level_age_s: 0.0,
            joints: JointModel::at(LYING_POSE_RAD),
            velocity: [0.0; 3],
            position_m: [0.0, 0.0, LYING_HEIGHT_M],
            rpy_rad: [0.0; 3],
            rpy_rate_radps: [0.0; 3],
            wheel_rad: 0.0,
            battery_percent: 100.0,
            faults: Faults::default(),
            tricks_done: 0,
            distance_m: 0.0,
        }
    }

    /// The model simulated.
    pub fn model(&self) -> Model {
        self.model
    }

    /// The reported control mode.
    pub fn mode(&self) -> ControlMode {
        self.mode
    }

    /// What the body is doing.
    pub fn activity(&self) -> Activity {
        self.activity
    }

    /// World position x, y, z, m.
    pub fn position_m(&self) -> [f32; 3] {
        self.position_m
    }

    /// Heading, rad.
    pub fn yaw_rad(&self) -> f32 {
        self.rpy_rad[2]
    }

    /// Body-frame velocity x, y (m/s) and yaw rate (rad/s).
    pub fn velocity(&self) -> [f32; 3] {
        self.velocity
    }

    /// Distance walked, m.
    pub fn distance_m(&self) -> f32 {
        self.distance_m
    }

    /// Tricks completed.
    pub fn tricks_done(&self) -> u32 {
        self.tricks_done
    }

    /// Battery, %.
    pub fn battery_percent(&self) -> f32 {
        self.battery_percent
    }

    /// Sets the battery level, %.
    pub fn set_battery_percent(&mut self, percent: f32) {
        self.battery_percent = percent.clamp(0.0, 100.0);
    }

    /// The faults active now.
    pub fn faults(&self) -> Faults {
        self.faults
    }

    /// Injects a fault.
    pub fn inject(&mut self, fault: DogFault) {
        match fault {
            DogFault::ErrorWord(word) => self.faults.error_word = Some(word),
            DogFault::SdkMismatch => self.faults.sdk_mismatch = true,
            DogFault::Silence => self.faults.silence = true,
            DogFault::Garbage => self.faults.garbage = true,
        }
    }

    /// Clears every fault.
    pub fn clear_faults(&mut self) {
        self.faults = Faults::default();
    }

    fn upright(&self) -> bool {
        matches!(
            self.activity,
            Activity::Standing | Activity::Walking | Activity::Trick(_) | Activity::TwoLegStand | Activity::Attitude
        )
    }

    /// A HighLevel command arrived (decoded strictly; `model` from its magic). Returns whether it
    /// changed what the dog was told to do.
    ///
    /// The idle stream a client sends before its first call (mode 0, no action, flag 0) is no
    /// request: the dog keeps doing what it did (robowire's reading of the flag word, which the
    /// vendor sets to 1 on every call that asks for something).
    pub fn on_high_level(&mut self, command: &HighLevelCommand, model: Model) -> bool {
        if model != self.model {
            // robowire's reading of spec §10: the robot flags the other model's magic.
            self.faults.sdk_mismatch = true;
        }
        self.command_age_s = 0.0;
        if command.flag.get() == 0 && command.mode.get() == 0 && command.action.get() == 0 {
            return false;
        }
        let same = |a: &HighLevelCommand| {
            (a.mode, a.action, a.vx, a.vy, a.roll_rate, a.pitch_rate, a.yaw_rate, a.height_rate)
                == (
                    command.mode,
                    command.action,
                    command.vx,
                    command.vy,
                    command.roll_rate,
                    command.pitch_rate,
                    command.yaw_rate,
                    command.height_rate,
                )
        };
        if same(&self.command) {
            return false;
        }
        let previous = self.command;
        self.command = *command;
        let mode = command.control_mode();
        let action = command.action_code();
        self.mode = mode;
        let new_action = action != previous.action_code() && action != Action::None;
        match mode {
            ControlMode::Passive => self.begin(Activity::Passive, 0.0),
            ControlMode::LieDown | ControlMode::LieDownFree => {
                if self.upright() || self.activity == Activity::StandingUp {
                    self.begin(Activity::LyingDown, 1.0);
                }
            }
            ControlMode::Stand => {
                if new_action && action == Action::ShakeHand && self.upright() {
                    self.begin(Activity::Trick(action), 2.0);
                } else if matches!(self.activity, Activity::Lying | Activity::Passive | Activity::LyingDown) {
                    self.begin(Activity::StandingUp, 1.2);
                } else if self.upright() && !matches!(self.activity, Activity::Trick(_)) {
                    self.begin(Activity::Standing, 0.0);
                }
            }
            ControlMode::Move => {
                if self.upright() && !matches!(self.activity, Activity::Trick(_)) {
                    self.begin(Activity::Walking, 0.0);
                }
            }
            ControlMode::Action => {
                if !self.upright() {
                } else if new_action && action.is_one_shot() {
                    let duration = match action {
                        Action::Jump => 0.8,
                        Action::FrontJump => 1.0,
                        Action::Backflip => 1.5,
                        _ => 2.0,
                    };
                    self.begin(Activity::Trick(action), duration);
                } else if action == Action::TwoLegStand {
                    self.begin(Activity::TwoLegStand, 0.0);
                } else if !matches!(self.activity, Activity::Trick(_)) {
                    self.begin(Activity::Attitude, 0.0);
                }
            }
            ControlMode::Unknown(_) => {}
        }
        true
    }

    /// Standing again after getting up or a trick: take up what the latched command asks for.
    fn settle_upright(&mut self) {
        self.activity = match (self.command.control_mode(), self.command.action_code()) {
            (ControlMode::Move, _) => Activity::Walking,
            (ControlMode::Action, Action::TwoLegStand) => Activity::TwoLegStand,
            (ControlMode::Action, Action::None) => Activity::Attitude,
            _ => Activity::Standing,
        };
    }

    fn begin(&mut self, activity: Activity, duration_s: f32) {
        self.activity = activity;
        self.remaining_s = duration_s;
    }

    /// A LowLevel command arrived: the motors follow it for the next 0.1 s.
    pub fn on_low_level(&mut self, command: &LowLevelCommand) -> bool {
        let changed = self.low_level.as_ref() != Some(command);
        self.low_level = Some(*command);
        self.low_level_age_s = 0.0;
        changed
    }

    /// Advances the robot by `dt_s` seconds.
    pub fn step(&mut self, dt_s: f32) {
        self.low_level_age_s += dt_s;
        self.command_age_s += dt_s;
        if self.low_level.is_some() && self.low_level_age_s > LOW_LEVEL_HOLD_S {
            self.low_level = None;
            if self.activity == Activity::LowLevel {
                self.activity = Activity::Passive;
            }
        }
        if self.low_level.is_some() {
            self.activity = Activity::LowLevel;
        }
        self.remaining_s = (self.remaining_s - dt_s).max(0.0);
        if self.remaining_s == 0.0 {
            match self.activity {
                Activity::StandingUp => self.settle_upright(),
                Activity::LyingDown => self.activity = Activity::Lying,
                Activity::Trick(_) => {
                    self.tricks_done += 1;
                    self.settle_upright();
                }
                _ => {}
            }
        }
        self.step_body(dt_s);
        self.step_joints(dt_s);
        let drain_per_s = match self.activity {
            Activity::Lying | Activity::Passive => 0.005,
            Activity::Walking | Activity::TwoLegStand => 0.02 + 0.02 * self.velocity[0].hypot(self.velocity[1]),
            Activity::Trick(_) => 0.1,
            _ => 0.01,
        };
        self.battery_percent = (self.battery_percent - drain_per_s * dt_s).max(0.0);
    }

    fn step_body(&mut self, dt: f32) {
        let c = &self.command;
        let stale = self.command_age_s > COMMAND_TIMEOUT_S;
        let target = match self.activity {
            _ if stale => [0.0; 3],
            Activity::Walking => [c.vx.get(), c.vy.get(), c.yaw_rate.get()],
            Activity::TwoLegStand => [c.vx.get(), 0.0, c.yaw_rate.get()],
            Activity::Trick(Action::FrontJump) => [0.5, 0.0, 0.0],
            _ => [0.0; 3],
        };
        let target = target.map(|v| if v.is_finite() { v } else { 0.0 });
        let alpha = (dt / VELOCITY_TAU_S).min(1.0);
        for (v, t) in self.velocity.iter_mut().zip(target) {
            *v += (t - *v) * alpha;
        }
        let [vx, vy, wz] = self.velocity;
        let yaw = self.rpy_rad[2] + wz * dt;
        self.rpy_rad[2] = (yaw + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU) - std::f32::consts::PI;
        let (sin, cos) = self.rpy_rad[2].sin_cos();
        self.position_m[0] += (vx * cos - vy * sin) * dt;
        self.position_m[1] += (vx * sin + vy * cos) * dt;
        self.distance_m += vx.hypot(vy) * dt;
        if self.model == Model::Zsl1W {
            self.wheel_rad += vx / WHEEL_RADIUS_M * dt;
        }
        // Attitude: roll and pitch follow the commanded rates within ±0.4 rad; elsewhere level.
        let rates = if self.activity == Activity::Attitude && !stale {
            [c.roll_rate.get(), c.pitch_rate.get()].map(|r| if r.is_finite() { r } else { 0.0 })
        } else {
            [-self.rpy_rad[0] * 4.0, -self.rpy_rad[1] * 4.0]
        };
        for (axis, rate) in rates.into_iter().enumerate() {
            let before = self.rpy_rad[axis];
            self.rpy_rad[axis] = (before + rate * dt).clamp(-0.4, 0.4);
            self.rpy_rate_radps[axis] = (self.rpy_rad[axis] - before) / dt;
        }
        self.rpy_rate_radps[2] = wz;
        let height = match self.activity {
            Activity::Lying | Activity::Passive => LYING_HEIGHT_M,
            // Getting up and lying down take their whole duration.
            Activity::StandingUp => STANDING_HEIGHT_M - (STANDING_HEIGHT_M - LYING_HEIGHT_M) * self.remaining_s / 1.2,
            Activity::LyingDown => LYING_HEIGHT_M + (STANDING_HEIGHT_M - LYING_HEIGHT_M) * self.remaining_s / 1.0,
            Activity::LowLevel => {
                // Height from the mean knee angle: bent knees, low body.
                let knee = self.joints.q_rad.iter().map(|leg| leg[2]).sum::<f32>() / 4.0;
                (0.55 + 0.17 * knee).clamp(0.05, 0.40)
            }
            Activity::Trick(Action::Jump | Action::FrontJump | Action::Backflip) => STANDING_HEIGHT_M + 0.15,
            _ => STANDING_HEIGHT_M,
        };
        let rate = if self.activity == Activity::Attitude && !stale { c.height_rate.get() } else { 0.0 };
        let rate = if rate.is_finite() { rate } else { 0.0 };
        let z = self.position_m[2] + rate * dt + (height - self.position_m[2]) * (dt / 0.1).min(1.0);
        self.position_m[2] = z.clamp(0.05, 0.45);
    }

    fn step_joints(&mut self, dt: f32) {
        if let Some(command) = &self.low_level {
            let m = &command.motor;
            self.joints.step(dt, |leg, joint| match joint {
                0..=2 => PdTarget {
                    q_rad: m.q_des[joint][leg].get(),
                    qd_radps: m.qd_des[joint][leg].get(),
                    kp: m.kp[joint][leg].get(),
                    kd: m.kd[joint][leg].get(),
                    tau_ff_nm: m.tau_ff[joint][leg].get(),
                },
                _ => PdTarget::default(),
            });
            return;
        }
        let pose = match self.activity {
            Activity::Lying | Activity::LyingDown => LYING_POSE_RAD,
            Activity::Passive => LYING_POSE_RAD,
            Activity::Trick(Action::ShakeHand) => [0.0, -0.3, -1.0],
            _ => STANDING_POSE_RAD,
        };
        let (kp, kd) = if self.activity == Activity::Passive { (5.0, 1.0) } else { (60.0, 2.0) };
        let wheel = self.wheel_rad;
        let shake = self.activity == Activity::Trick(Action::ShakeHand);
        self.joints.step(dt, |leg, joint| {
            let q_rad = match joint {
                // Shake hand: the front-left leg lifts; the others stand.
                0..=2 if shake && leg != 1 => STANDING_POSE_RAD[joint],
                0..=2 => pose[joint],
                _ => wheel,
            };
            PdTarget { q_rad, kp, kd, ..PdTarget::default() }
        });
    }

    /// The HighLevel state datagram now.
    pub fn high_level_state(&self) -> HighLevelState {
        let f = F32::new;
        let [vx, vy, _] = self.velocity;
        let (sin, cos) = self.rpy_rad[2].sin_cos();
        let joints = |m: &[[f32; 4]; 4]| core::array::from_fn(|joint| core::array::from_fn(|leg| f(m[leg][joint])));
        HighLevelState {
            header: HIGH_LEVEL_STATE_HEADER,
            quaternion: quaternion_wxyz(self.rpy_rad).map(f),
            gyro: self.rpy_rate_radps.map(f),
            acc: [0.0, 0.0, 9.81].map(f),
            rpy: self.rpy_rad.map(f),
            body_velocity: [vx, vy, 0.0].map(f),
            world_velocity: [vx * cos - vy * sin, vx * sin + vy * cos, 0.0].map(f),
            position: self.position_m.map(f),
            joint_angle: joints(&self.joints.q_rad),
            joint_velocity: joints(&self.joints.qd_radps),
            joint_torque: joints(&self.joints.tau_nm),
            control_mode: self.mode.raw().into(),
            battery_percent: (self.battery_percent.ceil() as u32).into(),
            error_word: self.faults.error_word.map_or(0, ReturnCode::raw).into(),
            sdk_mismatch: u32::from(self.faults.sdk_mismatch).into(),
            ..HighLevelState::default()
        }
    }

    /// The LowLevel state datagram now.
    pub fn low_level_state(&self) -> LowLevelState {
        let f = F32::new;
        let mut state = LowLevelState { magic: MAGIC_ZSL1.into(), ..LowLevelState::default() };
        for leg in 0..4 {
            for joint in 0..3 {
                state.motor.q[joint][leg] = f(self.joints.q_rad[leg][joint]);
                state.motor.qd[joint][leg] = f(self.joints.qd_radps[leg][joint]);
                state.motor.tau_fb[joint][leg] = f(self.joints.tau_nm[leg][joint]);
            }
        }
        state.quaternion = quaternion_wxyz(self.rpy_rad).map(f);
        state.gyro = self.rpy_rate_radps.map(f);
        state.acc = [0.0, 0.0, 9.81].map(f);
        state.rpy = self.rpy_rad.map(f);
        state
    }
}

/// Roll, pitch, yaw (rad, ZYX) → quaternion w, x, y, z.
fn quaternion_wxyz([roll, pitch, yaw]: [f32; 3]) -> [f32; 4] {
    let (sr, cr) = (roll / 2.0).sin_cos();
    let (sp, cp) = (pitch / 2.0).sin_cos();
    let (sy, cy) = (yaw / 2.0).sin_cos();
    [cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy]
}

/// Simulator settings.
#[derive(Debug, Clone, PartialEq)]
pub struct DogSimConfig {
    /// Address to bind both ports on. Default 127.0.0.1.
    pub bind: IpAddr,
    /// HighLevel port (default 43997; 0 picks a free one).
    pub high_level_port: u16,
    /// LowLevel port (default 43900; 0 picks a free one).
    pub low_level_port: u16,
    /// Where to send state; default: learned from each port's command datagrams.
    pub client: Option<SocketAddr>,
    /// ZSL-1 or ZSL-1W.
    pub model: Model,
    /// State period. Default 2 ms (500 Hz).
    pub state_period: Duration,
    /// Pin the simulator's thread to this CPU (Linux), to keep it off a control loop's core.
    pub cpu: Option<usize>,
}

impl Default for DogSimConfig {
    fn default() -> Self {
        Self {
            bind: Ipv4Addr::LOCALHOST.into(),
            high_level_port: HIGH_LEVEL_PORT,
            low_level_port: LOW_LEVEL_PORT,
            client: None,
            model: Model::Zsl1,
            state_period: Duration::from_millis(2),
            cpu: None,
        }
    }
}

impl DogSimConfig {
    /// On 127.0.0.1 with free ports (tests, demos): several can run at once.
    pub fn loopback() -> Self {
        Self { high_level_port: 0, low_level_port: 0, ..Self::default() }
    }
}

/// Counters of one port.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PortStats {
    /// Valid commands received.
    pub commands: u64,
    /// Datagrams that failed strict decoding (counted, ignored).
    pub invalid: u64,
    /// State datagrams sent.
    pub states_sent: u64,
    /// Junk datagrams sent (garbage fault).
    pub garbage_sent: u64,
    /// Where state goes (learned or configured).
    pub client: Option<SocketAddr>,
}

/// What the simulator has seen and done.
#[derive(Debug, Clone)]
pub struct DogSnapshot {
    /// The robot.
    pub dog: DogModel,
    /// HighLevel port.
    pub high_level: PortStats,
    /// LowLevel port.
    pub low_level: PortStats,
    /// State cycles run.
    pub cycles: u64,
}

struct Shared {
    dog: DogModel,
    high_level: PortStats,
    low_level: PortStats,
    cycles: u64,
}

fn lock(shared: &Mutex<Shared>) -> MutexGuard<'_, Shared> {
    shared.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// The dog on two UDP sockets, on its own thread; stopped on drop.
#[derive(Debug)]
pub struct DogSim {
    shared: Arc<Mutex<Shared>>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
    high_level_addr: SocketAddr,
    low_level_addr: SocketAddr,
}

impl std::fmt::Debug for Shared {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Shared").field("mode", &self.dog.mode).finish_non_exhaustive()
    }
}

impl DogSim {
    /// Binds both ports and starts the robot lying down.
    pub fn spawn(config: DogSimConfig) -> io::Result<Self> {
        let bind = |port| {
            UdpSocket::bind(SocketAddr::new(config.bind, port))
                .map_err(|e| io::Error::new(e.kind(), format!("dog simulator cannot bind {}:{port}: {e}", config.bind)))
        };
        let high = bind(config.high_level_port)?;
        let low = bind(config.low_level_port)?;
        high.set_nonblocking(true)?;
        low.set_nonblocking(true)?;
        let (high_level_addr, low_level_addr) = (high.local_addr()?, low.local_addr()?);
        let shared = Arc::new(Mutex::new(Shared {
            dog: DogModel::new(config.model),
            high_level: PortStats { client: config.client, ..PortStats::default() },
            low_level: PortStats { client: config.client, ..PortStats::default() },
            cycles: 0,
        }));
        let stop = Arc::new(AtomicBool::new(false));
        let (pinned_tx, pinned) = std::sync::mpsc::sync_channel(1);
        let thread = std::thread::Builder::new().name("dog-sim".into()).spawn({
            let (shared, stop) = (shared.clone(), stop.clone());
            move || {
                let pinned = config.cpu.map_or(Ok(()), pin_current_thread);
                let ok = pinned.is_ok();
                let _ = pinned_tx.send(pinned);
                if ok {
                    run(&high, &low, &config, &shared, &stop);
                }
            }
        })?;
        let sim = Self { shared, stop, thread: Some(thread), high_level_addr, low_level_addr };
        pinned.recv().map_err(|_| io::Error::other("the dog simulator thread died"))??;
        Ok(sim)
    }

    /// Where HighLevel commands go.
    pub fn high_level_addr(&self) -> SocketAddr {
        self.high_level_addr
    }

    /// Where LowLevel commands go.
    pub fn low_level_addr(&self) -> SocketAddr {
        self.low_level_addr
    }

    /// Injects a fault.
    pub fn inject(&self, fault: DogFault) {
        lock(&self.shared).dog.inject(fault);
    }

    /// Clears every fault.
    pub fn clear_faults(&self) {
        lock(&self.shared).dog.clear_faults();
    }

    /// Sets the battery level, %.
    pub fn set_battery_percent(&self, percent: f32) {
        lock(&self.shared).dog.set_battery_percent(percent);
    }

    /// The robot and the counters now.
    pub fn snapshot(&self) -> DogSnapshot {
        let s = lock(&self.shared);
        DogSnapshot { dog: s.dog.clone(), high_level: s.high_level, low_level: s.low_level, cycles: s.cycles }
    }
}

impl Drop for DogSim {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// Pins the calling thread to `cpu`.
fn pin_current_thread(cpu: usize) -> io::Result<()> {
    use rustix::thread::{CpuSet, sched_setaffinity};
    if cpu >= CpuSet::MAX_CPU {
        return Err(io::Error::new(io::ErrorKind::InvalidInput, format!("CPU {cpu} is beyond CPU_SETSIZE")));
    }
    let mut set = CpuSet::new();
    set.set(cpu);
    sched_setaffinity(None, &set)
        .map_err(|e| io::Error::new(io::Error::from(e).kind(), format!("pinning the dog simulator to CPU {cpu}: {e}")))
}

/// Junk the garbage fault sends: longer than any state, so no decoder accepts it.
const GARBAGE: [u8; 600] = [0xEE; 600];

fn run(high: &UdpSocket, low: &UdpSocket, config: &DogSimConfig, shared: &Mutex<Shared>, stop: &AtomicBool) {
    let period = config.state_period;
    let mut next = Instant::now() + period;
    let mut last_step = Instant::now();
    let mut buf = [0u8; 1024];
    let mut high_codec = HighLevelDogCodec::default();
    let mut low_codec = LowLevelDogCodec::default();
    while !stop.load(Ordering::Relaxed) {
        let wait = next.saturating_duration_since(Instant::now()).min(Duration::from_millis(50));
        let timeout = Timespec::try_from(wait).unwrap_or(Timespec { tv_sec: 0, tv_nsec: 2_000_000 });
        let mut fds = [PollFd::new(high, PollFlags::IN), PollFd::new(low, PollFlags::IN)];
        let _ = poll(&mut fds, Some(&timeout));
        let readable = fds.map(|fd| !fd.revents().is_empty());
        // A command that changes something is answered at once, before the socket is drained
        // further (low latency for the client's acknowledgement).
        if readable[0] {
            let mut s = lock(shared);
            while let Ok((len, from)) = high.recv_from(&mut buf) {
                match high_codec.decode(&buf[..len]) {
                    Ok((command, model)) => {
                        s.high_level.commands += 1;
                        if config.client.is_none() {
                            s.high_level.client = Some(from);
                        }
                        if s.dog.on_high_level(&command, model) {
                            send_state(high, &mut s, true, &mut buf);
                        }
                    }
                    Err(_) => s.high_level.invalid += 1,
                }
            }
        }
        if readable[1] {
            let mut s = lock(shared);
            while let Ok((len, from)) = low.recv_from(&mut buf) {
                match low_codec.decode(&buf[..len]) {
                    Ok((command, _)) => {
                        s.low_level.commands += 1;
                        if config.client.is_none() {
                            s.low_level.client = Some(from);
                        }
                        if s.dog.on_low_level(&command) {
                            send_state(low, &mut s, false, &mut buf);
                        }
                    }
                    Err(_) => s.low_level.invalid += 1,
                }
            }
        }
        let now = Instant::now();
        if now >= next {
            let dt = now.duration_since(last_step).as_secs_f32().min(0.05);
            last_step = now;
            let mut s = lock(shared);
            s.dog.step(dt);
            s.cycles += 1;
            next += period;
            if now > next + period * 10 {
                next = now + period;
            }
            send_state(high, &mut s, true, &mut buf);
            send_state(low, &mut s, false, &mut buf);
        }
    }
}

fn send_state(socket: &UdpSocket, s: &mut Shared, high: bool, buf: &mut [u8]) {
    let faults = s.dog.faults();
    let port = if high { &s.high_level } else { &s.low_level };
    let Some(client) = port.client else { return };
    if faults.silence {
        return;
    }
    let datagram: &[u8] = if faults.garbage {
        &GARBAGE
    } else if high {
        let Ok(n) = HighLevelDogCodec::default().encode(&s.dog.high_level_state(), buf) else { return };
        &buf[..n]
    } else {
        let Ok(n) = LowLevelDogCodec::default().encode(&s.dog.low_level_state(), buf) else { return };
        &buf[..n]
    };
    if socket.send_to(datagram, client).is_ok() {
        let port = if high { &mut s.high_level } else { &mut s.low_level };
        if faults.garbage {
            port.garbage_sent += 1;
        } else {
            port.states_sent += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `seconds` of a client streaming the latched command every 2 ms.
    fn run_for(dog: &mut DogModel, seconds: f32) {
        for _ in 0..(seconds / 0.002) as usize {
            let (command, model) = (dog.command, dog.model);
            dog.on_high_level(&command, model);
            dog.step(0.002);
        }
    }

    /// `seconds` without any command.
    fn run_silent(dog: &mut DogModel, seconds: f32) {
        for _ in 0..(seconds / 0.002) as usize {
            dog.step(0.002);
        }
    }

    #[test]
    fn stands_up_in_time_walks_and_lies_down() {
        let mut dog = DogModel::new(Model::Zsl1);
        assert!(dog.on_high_level(&HighLevelCommand::stand_up(), Model::Zsl1));
        assert_eq!(dog.mode(), ControlMode::Stand, "the mode mirrors the command at once");
        run_for(&mut dog, 0.5);
        assert_eq!(dog.activity(), Activity::StandingUp);
        run_for(&mut dog, 1.0);
        assert_eq!(dog.activity(), Activity::Standing);
        assert!((dog.position_m()[2] - STANDING_HEIGHT_M).abs() < 0.01);

        dog.on_high_level(&HighLevelCommand::move_velocity(0.5, 0.0, 0.0), Model::Zsl1);
        run_for(&mut dog, 2.0);
        let x = dog.position_m()[0];
        assert!((0.8..1.0).contains(&x), "about 2 s at 0.5 m/s minus the lag: {x}");
        dog.on_high_level(&HighLevelCommand::move_velocity(0.0, 0.0, 0.0), Model::Zsl1);
        run_for(&mut dog, 1.0);
        assert!(dog.velocity()[0].abs() < 0.01);

        dog.on_high_level(&HighLevelCommand::lie_down(), Model::Zsl1);
        run_for(&mut dog, 1.1);
        assert_eq!(dog.activity(), Activity::Lying);
        assert!(dog.battery_percent() < 100.0);
    }

    #[test]
    fn a_trick_returns_to_stand_and_the_other_models_magic_raises_the_mismatch_flag() {
        let mut dog = DogModel::new(Model::Zsl1);
        dog.on_high_level(&HighLevelCommand::stand_up(), Model::Zsl1);
        run_for(&mut dog, 1.3);
        dog.on_high_level(&HighLevelCommand::jump(), Model::Zsl1);
        assert_eq!(dog.activity(), Activity::Trick(Action::Jump));
        run_for(&mut dog, 1.0);
        assert_eq!((dog.activity(), dog.tricks_done()), (Activity::Standing, 1));
        assert_eq!(dog.high_level_state().sdk_mismatch.get(), 0);
        dog.on_high_level(&HighLevelCommand::stand_up(), Model::Zsl1W);
        assert_eq!(dog.high_level_state().sdk_mismatch.get(), 1);
    }

    #[test]
    fn the_idle_stream_is_no_request_and_a_silent_client_stops_the_walk() {
        let mut dog = DogModel::new(Model::Zsl1);
        assert!(!dog.on_high_level(&HighLevelCommand::default(), Model::Zsl1));
        assert_eq!(dog.mode(), ControlMode::LieDown);
        dog.on_high_level(&HighLevelCommand::stand_up(), Model::Zsl1);
        run_for(&mut dog, 1.3);
        dog.on_high_level(&HighLevelCommand::move_velocity(0.5, 0.0, 0.0), Model::Zsl1);
        run_for(&mut dog, 0.4);
        assert!(dog.velocity()[0] > 0.4);
        run_silent(&mut dog, 1.0);
        assert!(dog.velocity()[0] < 0.05, "no command for 0.5 s: the dog stops");
        assert_eq!(dog.mode(), ControlMode::Move);
    }

    #[test]
    fn pinning_to_a_cpu_that_does_not_exist_is_an_error_not_a_silent_default() {
        let err = DogSim::spawn(DogSimConfig { cpu: Some(100_000), ..DogSimConfig::loopback() }).unwrap_err();
        assert!(err.to_string().contains("CPU 100000"), "{err}");
        assert!(DogSim::spawn(DogSimConfig { cpu: Some(0), ..DogSimConfig::loopback() }).is_ok());
    }

    #[test]
    fn low_level_pd_moves_the_joints() {
        let mut dog = DogModel::new(Model::Zsl1);
        let stand = LowLevelCommand::new(zsl_proto::udp::MotorCommand::pd_hold(
            [[0.0; 4], [0.8; 4], [-1.5; 4]],
            [80.0; 3],
            [1.0; 3],
        ));
        for _ in 0..500 {
            dog.on_low_level(&stand);
            dog.step(0.002);
        }
        let state = dog.low_level_state();
        assert!((state.motor.q[2][0].get() + 1.5).abs() < 0.01, "{:?}", state.motor.q);
        assert_eq!(dog.activity(), Activity::LowLevel);
        run_silent(&mut dog, 0.2);
        assert_eq!(dog.activity(), Activity::Passive, "motors released when LowLevel commands stop");
    }
}
