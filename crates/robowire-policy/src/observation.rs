//! The observation, built as Unitree's deploy scripts build it.
//!
//! - Angular velocity is the IMU's gyroscope; projected gravity comes from the IMU's quaternion
//!   (w, x, y, z). A torso IMU is first turned into the pelvis frame by the waist yaw.
//! - The base's linear velocity is a world-frame velocity (`rt/sportmodestate`'s) rotated into
//!   the body frame.
//! - Joints are read through `leg_joint2motor_idx`, in the policy's order.
//! - The command is clamped to `max_cmd`, then scaled by `cmd_scale`.
//! - The gait phase at the k-th step (k from 1) is sin and cos of 2π·((k·control_dt) mod
//!   period)/period.
//! - The last action is the policy's raw output, zeros before the first step.

use robowire_core::kinematics::{multiply, rotate, rotate_into};

use crate::config::{ImuType, PolicyConfig};
pub use crate::term::Term;

/// What the robot reported, by motor index.
#[derive(Debug, Clone, Copy)]
pub struct Sensed<'a> {
    /// The IMU's orientation (w, x, y, z).
    pub quaternion_wxyz: [f32; 4],
    /// The IMU's angular velocity, rad/s, its own frame.
    pub gyroscope_rad_s: [f32; 3],
    /// The base's velocity in the world frame, m/s, when known (`rt/sportmodestate`).
    pub base_velocity_world_m_s: Option<[f32; 3]>,
    /// Every motor's angle, rad.
    pub motor_q_rad: &'a [f32],
    /// Every motor's velocity, rad/s.
    pub motor_dq_rad_s: &'a [f32],
}

/// Why an observation cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ObserveError {
    /// The observation has `base_lin_vel` and no base velocity was given.
    #[error("the observation needs the base's velocity (rt/sportmodestate), none is known")]
    NoBaseVelocity,
    /// A mapped motor past the state's motors.
    #[error("motor {motor} is past the state's {motors} motors")]
    Motor {
        /// The motor.
        motor: usize,
        /// The state's.
        motors: usize,
    },
}

/// Builds each step's observation; remembers the last action and the step count.
#[derive(Debug, Clone)]
pub struct Observer {
    terms: Vec<Term>,
    joints: Vec<usize>,
    default_angles: Vec<f32>,
    waist_yaw_motor: Option<usize>,
    scales: Scales,
    control_dt_s: f64,
    gait_period_s: f64,
    obs: Vec<f32>,
    last_action: Vec<f32>,
    /// Steps built so far.
    step: u64,
}

#[derive(Debug, Clone, Copy)]
struct Scales {
    lin_vel: f32,
    ang_vel: f32,
    dof_pos: f32,
    dof_vel: f32,
    cmd: [f32; 3],
    max_cmd: [f32; 3],
}

impl Observer {
    /// An observer for `config` (checked by [`PolicyConfig::check`]), before its first step.
    pub fn new(config: &PolicyConfig) -> Self {
        Self {
            terms: config.observation.clone(),
            joints: config.leg_joint2motor_idx.clone(),
            default_angles: config.default_angles.clone(),
            waist_yaw_motor: match config.imu_type {
                ImuType::Pelvis => None,
                ImuType::Torso => config.arm_waist_joint2motor_idx.first().copied(),
            },
            scales: Scales {
                lin_vel: config.lin_vel_scale,
                ang_vel: config.ang_vel_scale,
                dof_pos: config.dof_pos_scale,
                dof_vel: config.dof_vel_scale,
                cmd: config.cmd_scale,
                max_cmd: config.max_cmd,
            },
            control_dt_s: config.control_dt,
            gait_period_s: config.gait_period,
            obs: vec![0.0; config.observation_len()],
            last_action: vec![0.0; config.num_actions],
            step: 0,
        }
    }

    /// Back to before the first step: no last action, the phase from the start.
    pub fn reset(&mut self) {
        self.last_action.fill(0.0);
        self.step = 0;
    }

    /// `command` (vx m/s, vy m/s, wz rad/s) clamped to `max_cmd`; a non-finite axis is 0.
    pub fn clamp_command(&self, command: [f32; 3]) -> [f32; 3] {
        let max = self.scales.max_cmd;
        core::array::from_fn(|i| if command[i].is_finite() { command[i].clamp(-max[i], max[i]) } else { 0.0 })
    }

    /// The base's orientation (w, x, y, z) and angular velocity (rad/s) in the pelvis frame.
    pub fn base_frame(&self, sensed: &Sensed<'_>) -> Result<([f64; 4], [f64; 3]), ObserveError> {
        let quat = sensed.quaternion_wxyz.map(f64::from);
        let gyro = sensed.gyroscope_rad_s.map(f64::from);
        let Some(waist) = self.waist_yaw_motor else {
            return Ok((quat, gyro));
        };
        let yaw = f64::from(motor(sensed.motor_q_rad, waist)?);
        let yaw_rate = f64::from(motor(sensed.motor_dq_rad_s, waist)?);
        Ok(torso_to_pelvis(quat, gyro, yaw, yaw_rate))
    }

    /// The next step's observation: the step count moves on.
    pub fn observe(&mut self, sensed: &Sensed<'_>, command: [f32; 3]) -> Result<&[f32], ObserveError> {
        let (quat, gyro) = self.base_frame(sensed)?;
        let command = self.clamp_command(command);
        let step = self.step + 1;
        let mut at = 0;
        for i in 0..self.terms.len() {
            let term = self.terms[i];
            let len = term.len(self.joints.len());
            let out = &mut self.obs[at..at + len];
            let s = self.scales;
            match term {
                Term::BaseLinVel => {
                    let v = sensed.base_velocity_world_m_s.ok_or(ObserveError::NoBaseVelocity)?;
                    let body = rotate_into_body(quat, v.map(f64::from));
                    fill(out, |k| body[k] as f32 * s.lin_vel);
                }
                Term::BaseAngVel => fill(out, |k| gyro[k] as f32 * s.ang_vel),
                Term::ProjectedGravity => {
                    let g = projected_gravity(quat);
                    fill(out, |k| g[k] as f32);
                }
                Term::Command => fill(out, |k| (f64::from(command[k]) * f64::from(s.cmd[k])) as f32),
                Term::JointPos => {
                    for (k, &m) in self.joints.iter().enumerate() {
                        out[k] = (motor(sensed.motor_q_rad, m)? - self.default_angles[k]) * s.dof_pos;
                    }
                }
                Term::JointVel => {
                    for (k, &m) in self.joints.iter().enumerate() {
                        out[k] = motor(sensed.motor_dq_rad_s, m)? * s.dof_vel;
                    }
                }
                Term::LastAction => out.copy_from_slice(&self.last_action),
                Term::GaitPhase => {
                    let [sin, cos] = gait_phase(step, self.control_dt_s, self.gait_period_s);
                    out[0] = sin as f32;
                    out[1] = cos as f32;
                }
            }
            at += len;
        }
        self.step = step;
        Ok(&self.obs)
    }

    /// Remembers the policy's raw output as the next step's last action.
    pub fn act(&mut self, action: &[f32]) {
        let n = self.last_action.len().min(action.len());
        self.last_action[..n].copy_from_slice(&action[..n]);
    }

    /// Steps built so far.
    pub fn steps(&self) -> u64 {
        self.step
    }
}

fn fill(out: &mut [f32], value: impl Fn(usize) -> f32) {
    for (k, v) in out.iter_mut().enumerate() {
        *v = value(k);
    }
}

fn motor(values: &[f32], motor: usize) -> Result<f32, ObserveError> {
    values.get(motor).copied().ok_or(ObserveError::Motor { motor, motors: values.len() })
}

/// Gravity's direction in the body frame of orientation `q` (w, x, y, z): (0, 0, −1) level.
pub fn projected_gravity([w, x, y, z]: [f64; 4]) -> [f64; 3] {
    [2.0 * (-z * x + w * y), -2.0 * (z * y + w * x), 1.0 - 2.0 * (w * w + z * z)]
}

/// Roll and pitch, rad, of a body whose projected gravity is `g`.
pub fn roll_pitch_rad([gx, gy, gz]: [f64; 3]) -> (f64, f64) {
    ((-gy).atan2(-gz), gx.clamp(-1.0, 1.0).asin())
}

/// A world-frame vector `v` in the body frame of orientation `q` (w, x, y, z): q⁻¹ v q.
pub fn rotate_into_body(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    rotate_into(q, v)
}

/// sin and cos of the gait phase at the `step`-th step (from 1).
pub fn gait_phase(step: u64, control_dt_s: f64, period_s: f64) -> [f64; 2] {
    let phase = (step as f64 * control_dt_s) % period_s / period_s;
    let angle = 2.0 * core::f64::consts::PI * phase;
    [angle.sin(), angle.cos()]
}

/// A torso IMU's orientation and angular velocity turned into the pelvis frame, below a waist
/// yaw joint at `yaw` rad turning at `yaw_rate` rad/s: R_pelvis = R_torso · Rz(yaw)ᵀ,
/// ω_pelvis = Rz(yaw) · ω_torso − (0, 0, yaw_rate).
pub fn torso_to_pelvis(torso: [f64; 4], gyro: [f64; 3], yaw: f64, yaw_rate: f64) -> ([f64; 4], [f64; 3]) {
    let (s, c) = (yaw / 2.0).sin_cos();
    let pelvis = multiply(torso, [c, 0.0, 0.0, -s]);
    let turned = rotate([c, 0.0, 0.0, s], gyro);
    (pelvis, [turned[0], turned[1], turned[2] - yaw_rate])
}
