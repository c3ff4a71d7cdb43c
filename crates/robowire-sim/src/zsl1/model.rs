//! The robot, sans I/O: a state machine over the vendor's modes with timed transitions, the
//! HighLevel and LowLevel commands it was given, battery drain and injectable faults, and the
//! state datagrams it reports. The body that moves (trunk and joints) is stepped by the robot's
//! body module.
//!
//! The reported mode mirrors the commanded mode as soon as a command changes it (spec §11.4: the
//! vendor's client counts a call as unacknowledged until it does); what the body does takes
//! time: standing up [`STAND_UP_S`], lying down [`LIE_DOWN_S`], tricks [`JUMP_S`] to
//! [`SHAKE_HAND_S`], after which the robot stands.

use zsl_proto::udp::{
    Action, ControlMode, HIGH_LEVEL_STATE_HEADER, HighLevelCommand, HighLevelState, LowLevelCommand, LowLevelState,
    MAGIC_ZSL1, Model, ReturnCode,
};
use zsl_proto::zerocopy::little_endian::F32;

pub use super::activity::{Activity, BACKFLIP_S, FRONT_JUMP_S, JUMP_S, LIE_DOWN_S, SHAKE_HAND_S, STAND_UP_S};
use super::body::{Body, Drive};

/// Battery drain by activity, %/s.
struct Drain {
    lying: f32,
    standing: f32,
    walking: f32,
    /// Added per m/s of walking speed.
    walking_per_mps: f32,
    trick: f32,
}

const DRAIN: Drain = Drain { lying: 0.005, standing: 0.01, walking: 0.02, walking_per_mps: 0.02, trick: 0.1 };
/// A LowLevel command keeps the motors under LowLevel control this long, s.
const LOW_LEVEL_HOLD_S: f32 = 0.1;
/// Without a HighLevel command for this long the robot stops walking (it keeps its mode), s.
pub const COMMAND_TIMEOUT_S: f32 = 0.5;

/// A fault the simulator can inject.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Zsl1Fault {
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
pub struct Zsl1Model {
    model: Model,
    mode: ControlMode,
    activity: Activity,
    /// Seconds left in the current transition or trick.
    remaining_s: f32,
    command: HighLevelCommand,
    command_age_s: f32,
    low_level: Option<LowLevelCommand>,
    low_level_age_s: f32,
    body: Body,
    battery_percent: f32,
    faults: Faults,
    tricks_done: u32,
}

impl Zsl1Model {
    /// A robot of `model` lying on the floor with a full battery.
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
            body: Body::lying(),
            battery_percent: 100.0,
            faults: Faults::default(),
            tricks_done: 0,
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
        self.body.position_m
    }

    /// Heading, rad.
    pub fn yaw_rad(&self) -> f32 {
        self.body.rpy_rad[2]
    }

    /// Body-frame velocity x, y, m/s.
    pub fn velocity_mps(&self) -> [f32; 2] {
        self.body.velocity_mps
    }

    /// Yaw rate, rad/s.
    pub fn yaw_rate_radps(&self) -> f32 {
        self.body.yaw_rate_radps
    }

    /// Distance walked, m.
    pub fn distance_m(&self) -> f32 {
        self.body.distance_m
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
    pub fn inject(&mut self, fault: Zsl1Fault) {
        match fault {
            Zsl1Fault::ErrorWord(word) => self.faults.error_word = Some(word),
            Zsl1Fault::SdkMismatch => self.faults.sdk_mismatch = true,
            Zsl1Fault::Silence => self.faults.silence = true,
            Zsl1Fault::Garbage => self.faults.garbage = true,
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
    /// changed what the robot was told to do.
    ///
    /// The idle stream a client sends before its first call (mode 0, no action, flag 0) is no
    /// request: the robot keeps doing what it did (robowire's reading of the flag word, which the
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
                    self.begin(Activity::LyingDown, LIE_DOWN_S);
                }
            }
            ControlMode::Stand => {
                if new_action && action == Action::ShakeHand && self.upright() {
                    self.begin(Activity::Trick(action), SHAKE_HAND_S);
                } else if matches!(self.activity, Activity::Lying | Activity::Passive | Activity::LyingDown) {
                    self.begin(Activity::StandingUp, STAND_UP_S);
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
                        Action::Jump => JUMP_S,
                        Action::FrontJump => FRONT_JUMP_S,
                        Action::Backflip => BACKFLIP_S,
                        _ => SHAKE_HAND_S,
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
        let drive = Drive {
            model: self.model,
            activity: self.activity,
            remaining_s: self.remaining_s,
            command: &self.command,
            stale: self.command_age_s > COMMAND_TIMEOUT_S,
            low_level: self.low_level.as_ref(),
        };
        self.body.step(dt_s, &drive);
        let [vx, vy] = self.body.velocity_mps;
        let drain_per_s = match self.activity {
            Activity::Lying | Activity::Passive => DRAIN.lying,
            Activity::Walking | Activity::TwoLegStand => DRAIN.walking + DRAIN.walking_per_mps * vx.hypot(vy),
            Activity::Trick(_) => DRAIN.trick,
            _ => DRAIN.standing,
        };
        self.battery_percent = (self.battery_percent - drain_per_s * dt_s).max(0.0);
    }

    /// The HighLevel state datagram now.
    pub fn high_level_state(&self) -> HighLevelState {
        let f = F32::new;
        let b = &self.body;
        let [vx, vy] = b.velocity_mps;
        let (sin, cos) = b.rpy_rad[2].sin_cos();
        let joints = |m: &[[f32; 4]; 4]| core::array::from_fn(|joint| core::array::from_fn(|leg| f(m[leg][joint])));
        HighLevelState {
            header: HIGH_LEVEL_STATE_HEADER,
            quaternion: quaternion_wxyz(b.rpy_rad).map(f),
            gyro: b.rpy_rate_radps.map(f),
            acc: [0.0, 0.0, GRAVITY_MPS2].map(f),
            rpy: b.rpy_rad.map(f),
            body_velocity: [vx, vy, 0.0].map(f),
            world_velocity: [vx * cos - vy * sin, vx * sin + vy * cos, 0.0].map(f),
            position: b.position_m.map(f),
            joint_angle: joints(&b.joints.q_rad),
            joint_velocity: joints(&b.joints.qd_radps),
            joint_torque: joints(&b.joints.tau_nm),
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
        let b = &self.body;
        for leg in 0..4 {
            for joint in 0..3 {
                state.motor.q[joint][leg] = f(b.joints.q_rad[leg][joint]);
                state.motor.qd[joint][leg] = f(b.joints.qd_radps[leg][joint]);
                state.motor.tau_fb[joint][leg] = f(b.joints.tau_nm[leg][joint]);
            }
        }
        state.quaternion = quaternion_wxyz(b.rpy_rad).map(f);
        state.gyro = b.rpy_rate_radps.map(f);
        state.acc = [0.0, 0.0, GRAVITY_MPS2].map(f);
        state.rpy = b.rpy_rad.map(f);
        state
    }
}

/// Gravity as the IMU reports it at rest, m/s².
const GRAVITY_MPS2: f32 = 9.81;

/// Roll, pitch, yaw (rad, ZYX) → quaternion w, x, y, z.
fn quaternion_wxyz([roll, pitch, yaw]: [f32; 3]) -> [f32; 4] {
    let (sr, cr) = (roll / 2.0).sin_cos();
    let (sp, cp) = (pitch / 2.0).sin_cos();
    let (sy, cy) = (yaw / 2.0).sin_cos();
    [cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy]
}

#[cfg(test)]
mod tests;
