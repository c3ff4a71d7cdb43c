//! The deploy sequence of Unitree's `deploy_real.py` as a sans-IO machine on caller time: move to
//! the default pose in [`STAND_S`] with the config's gains, hold it for [`HOLD_S`], then run the
//! policy every `control_dt`. Each tick takes the latest state and gives the motor targets to
//! latch, or why the robot must be damped now:
//!
//! - the state is older than [`STALE_STATE`] (or there is none);
//! - the body is tilted past `max_tilt_rad` in roll or pitch;
//! - the policy gave an action that is not finite, or failed;
//! - the observation could not be built (a motor missing from the state).
//!
//! Every target is clamped into its joint's range (the robot's hardware stops, the URDF's limits
//! in training): the PD pushes toward the stop as it would toward the target beyond it (a joint
//! resting just past its stop, a policy's target beyond it). Targets between ticks are the LowCmd stream's to hold.

use std::time::{Duration, Instant};

use robowire_core::schedule::Time;

use crate::config::PolicyConfig;
use crate::model::OnnxPolicy;
use crate::observation::{Observer, Sensed, projected_gravity, roll_pitch_rad};

/// The move from where the joints are to the default pose.
pub const STAND_S: f64 = 2.0;
/// The default pose held before the policy runs.
pub const HOLD_S: f64 = 1.0;
/// The oldest state the controller acts on.
pub const STALE_STATE: Duration = Duration::from_millis(100);

/// One motor's command: position target and gains (velocity target and torque 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotorTarget {
    /// The LowCmd slot.
    pub motor: usize,
    /// rad.
    pub q_rad: f32,
    /// N·m/rad.
    pub kp: f32,
    /// N·m·s/rad.
    pub kd: f32,
}

/// Why the controller damped the robot.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Fault {
    /// No state, or the latest is too old.
    #[error("no LowState for {age_ms} ms (limit {} ms)", STALE_STATE.as_millis())]
    StaleState {
        /// Age of the latest state, ms (`u64::MAX`: none).
        age_ms: u64,
    },
    /// Tilted past the limit.
    #[error("tilted {roll_rad:.2} rad in roll, {pitch_rad:.2} rad in pitch (limit {limit_rad} rad)")]
    Tilt {
        /// rad.
        roll_rad: f32,
        /// rad.
        pitch_rad: f32,
        /// rad.
        limit_rad: f32,
    },
    /// An action that is not finite.
    #[error("the policy gave {value} for joint {joint}")]
    NotFinite {
        /// The policy's joint.
        joint: usize,
        /// The action.
        value: f32,
    },
    /// The observation could not be built or the model failed.
    #[error("{0}")]
    Policy(String),
    /// Ticked after [`Controller::stop`] or a fault.
    #[error("the controller was stopped")]
    Stopped,
}

/// Where the sequence is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Moving to the default pose.
    Standing,
    /// Holding the default pose.
    Holding,
    /// The policy runs.
    Walking,
    /// Damped: nothing more is sent.
    Damped,
}

impl Phase {
    /// `standing`, `holding`, `walking` or `damped`.
    pub fn name(self) -> &'static str {
        match self {
            Phase::Standing => "standing",
            Phase::Holding => "holding",
            Phase::Walking => "walking",
            Phase::Damped => "damped",
        }
    }
}

/// What a tick decided.
#[derive(Debug, PartialEq)]
pub enum Tick<'a> {
    /// Latch these targets.
    Command(&'a [MotorTarget]),
    /// Damp now, for this reason.
    Damp(Fault),
}

/// What the last policy step saw and did (for a recorder and statistics).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StepReport {
    /// The step's number (from 1).
    pub step: u64,
    /// The observation.
    pub obs: Vec<f32>,
    /// The raw actions.
    pub action: Vec<f32>,
    /// The command after clamping to `max_cmd`.
    pub command: [f32; 3],
    /// The inference's duration.
    pub inference: Duration,
    /// Targets clamped into their joint's range so far (every phase).
    pub clamped: u64,
}

/// The deploy sequence and the policy, on caller time.
#[derive(Debug)]
pub struct Controller {
    policy: OnnxPolicy,
    observer: Observer,
    max_tilt_rad: f32,
    action_scale: f32,
    default_angles: Vec<f32>,
    /// Legs, then arm and waist: motor, pose, gains.
    held: Vec<MotorTarget>,
    targets: Vec<MotorTarget>,
    /// Each target's joint range, rad (by target; unbounded without one).
    ranges: Vec<(f32, f32)>,
    /// Where the joints were when the stand began.
    from_rad: Vec<f32>,
    phase: Phase,
    /// When the phase began.
    since: Time,
    report: StepReport,
}

impl Controller {
    /// A controller for `config` running `policy`, before its first tick; each motor's range
    /// from `range` (`None`: unbounded).
    pub fn new(config: &PolicyConfig, policy: OnnxPolicy, range: impl Fn(usize) -> Option<(f32, f32)>) -> Self {
        let legs =
            config.leg_joint2motor_idx.iter().zip(&config.default_angles).zip(config.kps.iter().zip(&config.kds));
        let arms = config
            .arm_waist_joint2motor_idx
            .iter()
            .zip(&config.arm_waist_target)
            .zip(config.arm_waist_kps.iter().zip(&config.arm_waist_kds));
        let held: Vec<MotorTarget> =
            legs.chain(arms).map(|((&motor, &q_rad), (&kp, &kd))| MotorTarget { motor, q_rad, kp, kd }).collect();
        Self {
            policy,
            observer: Observer::new(config),
            max_tilt_rad: config.max_tilt_rad,
            action_scale: config.action_scale,
            default_angles: config.default_angles.clone(),
            ranges: held.iter().map(|t| range(t.motor).unwrap_or((f32::NEG_INFINITY, f32::INFINITY))).collect(),
            from_rad: vec![0.0; held.len()],
            targets: held.clone(),
            held,
            phase: Phase::Standing,
            since: Time::ZERO,
            report: StepReport { action: vec![0.0; config.num_actions], ..StepReport::default() },
        }
    }

    /// Starts the sequence at `now` from the joints of `sensed`: standing (`stand`), else the
    /// policy at once.
    pub fn start(&mut self, now: Time, sensed: &Sensed<'_>, stand: bool) {
        for (from, target) in self.from_rad.iter_mut().zip(&self.held) {
            *from = sensed.motor_q_rad.get(target.motor).copied().unwrap_or(target.q_rad);
        }
        self.phase = if stand { Phase::Standing } else { Phase::Walking };
        self.since = now;
        self.observer.reset();
        self.policy.reset();
    }

    /// Where the sequence is.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// The last policy step.
    pub fn report(&self) -> &StepReport {
        &self.report
    }

    /// Damps from now on (Ctrl-C, the end of the run).
    pub fn stop(&mut self) {
        self.phase = Phase::Damped;
    }

    /// The tick at `now`: `state` is the latest state and its age (`None`: none yet), `command`
    /// the velocity asked (vx m/s, vy m/s, wz rad/s).
    pub fn tick(&mut self, now: Time, state: Option<(&Sensed<'_>, Duration)>, command: [f32; 3]) -> Tick<'_> {
        match self.decide(now, state, command) {
            Ok(()) => {
                for (target, (min, max)) in self.targets.iter_mut().zip(&self.ranges) {
                    let q = target.q_rad;
                    target.q_rad = q.clamp(*min, *max);
                    self.report.clamped += u64::from(target.q_rad != q);
                }
                Tick::Command(&self.targets)
            }
            Err(fault) => {
                self.phase = Phase::Damped;
                Tick::Damp(fault)
            }
        }
    }

    fn decide(&mut self, now: Time, state: Option<(&Sensed<'_>, Duration)>, command: [f32; 3]) -> Result<(), Fault> {
        let Some((sensed, _)) = state.filter(|(_, age)| *age <= STALE_STATE) else {
            let age_ms = state.map_or(u64::MAX, |(_, age)| age.as_millis().try_into().unwrap_or(u64::MAX));
            return Err(Fault::StaleState { age_ms });
        };
        let (quat, _) = self.observer.base_frame(sensed).map_err(|e| Fault::Policy(e.to_string()))?;
        let (roll, pitch) = roll_pitch_rad(projected_gravity(quat));
        let limit = f64::from(self.max_tilt_rad);
        if roll.abs() > limit || pitch.abs() > limit {
            return Err(Fault::Tilt { roll_rad: roll as f32, pitch_rad: pitch as f32, limit_rad: self.max_tilt_rad });
        }
        let elapsed = now.saturating_duration_since(self.since).as_secs_f64();
        match self.phase {
            Phase::Standing if elapsed < STAND_S => {
                let alpha = (elapsed / STAND_S) as f32;
                for ((target, held), from) in self.targets.iter_mut().zip(&self.held).zip(&self.from_rad) {
                    target.q_rad = from * (1.0 - alpha) + held.q_rad * alpha;
                }
                Ok(())
            }
            Phase::Standing => {
                self.targets.copy_from_slice(&self.held);
                (self.phase, self.since) = (Phase::Holding, now);
                Ok(())
            }
            Phase::Holding => {
                if elapsed >= HOLD_S {
                    (self.phase, self.since) = (Phase::Walking, now);
                }
                Ok(())
            }
            Phase::Walking => self.walk(sensed, command),
            Phase::Damped => Err(Fault::Stopped),
        }
    }

    /// A policy step: targets = action × action_scale + default for the policy's joints.
    fn walk(&mut self, sensed: &Sensed<'_>, command: [f32; 3]) -> Result<(), Fault> {
        let obs = self.observer.observe(sensed, command).map_err(|e| Fault::Policy(e.to_string()))?;
        let started = Instant::now();
        let action = self.policy.step(obs).map_err(|e| Fault::Policy(e.to_string()))?;
        let inference = started.elapsed();
        if let Some((joint, &value)) = action.iter().enumerate().find(|(_, a)| !a.is_finite()) {
            return Err(Fault::NotFinite { joint, value });
        }
        for ((target, a), default) in self.targets.iter_mut().zip(action).zip(&self.default_angles) {
            target.q_rad = a * self.action_scale + default;
        }
        let report = &mut self.report;
        report.obs.clear();
        report.obs.extend_from_slice(obs);
        report.action.copy_from_slice(action);
        report.inference = inference;
        report.step = self.observer.steps();
        report.command = self.observer.clamp_command(command);
        self.observer.act(action);
        Ok(())
    }
}
