//! The robot's body: velocity with a first-order lag, position and heading integrated from it,
//! attitude, height, and the twelve (sixteen on the ZSL-1W) joints through the shared PD model.

use zsl_proto::udp::{Action, HighLevelCommand, LowLevelCommand, Model};

use super::activity::{Activity, LIE_DOWN_S, STAND_UP_S};
use crate::joints::{JointModel, PdTarget};
use crate::spline::{LYING_POSE_RAD, STANDING_POSE_RAD};

/// Body height standing, m.
pub const STANDING_HEIGHT_M: f32 = 0.30;
/// Body height lying, m.
pub const LYING_HEIGHT_M: f32 = 0.10;
/// Body height at the top of a jump, above standing, m.
const JUMP_HEIGHT_M: f32 = 0.15;
/// Wheel radius of the ZSL-1W, m (the foot joint angle integrates forward speed).
const WHEEL_RADIUS_M: f32 = 0.08;
/// Time constant of the body's velocity response, s.
const VELOCITY_TAU_S: f32 = 0.08;
/// Time constant of the body's height response, s.
const HEIGHT_TAU_S: f32 = 0.1;
/// Roll and pitch limit under attitude control, rad.
const ATTITUDE_LIMIT_RAD: f32 = 0.4;
/// Rate at which roll and pitch return to level, 1/s.
const LEVELLING_RATE_PER_S: f32 = 4.0;
/// Forward speed during a front jump, m/s.
const FRONT_JUMP_MPS: f32 = 0.5;
/// The shake-hand pose of the lifted front-left leg: abad, hip, knee, rad.
const SHAKE_HAND_POSE_RAD: [f32; 3] = [0.0, -0.3, -1.0];
/// Joint gains holding a pose: standing, and limp (passive).
const POSE_GAINS: (f32, f32) = (60.0, 2.0);
const PASSIVE_GAINS: (f32, f32) = (5.0, 1.0);

/// What moves: the trunk (velocity, pose in the world) and the joints.
#[derive(Debug, Clone)]
pub(crate) struct Body {
    pub(crate) joints: JointModel,
    /// Body-frame velocity x, y, m/s.
    pub(crate) velocity_mps: [f32; 2],
    /// Yaw rate, rad/s.
    pub(crate) yaw_rate_radps: f32,
    pub(crate) position_m: [f32; 3],
    pub(crate) rpy_rad: [f32; 3],
    pub(crate) rpy_rate_radps: [f32; 3],
    /// ZSL-1W wheel angle, rad.
    pub(crate) wheel_rad: f32,
    /// Distance walked, m.
    pub(crate) distance_m: f32,
}

/// What the body is told to do in one step.
pub(crate) struct Drive<'a> {
    pub(crate) model: Model,
    pub(crate) activity: Activity,
    /// Seconds left of the current transition or trick.
    pub(crate) remaining_s: f32,
    /// The latched HighLevel command.
    pub(crate) command: &'a HighLevelCommand,
    /// No HighLevel command for the robot's timeout: stop.
    pub(crate) stale: bool,
    /// LowLevel control, if active.
    pub(crate) low_level: Option<&'a LowLevelCommand>,
}

fn finite_or_zero(v: f32) -> f32 {
    if v.is_finite() { v } else { 0.0 }
}

impl Body {
    /// Lying on the floor, at rest.
    pub(crate) fn lying() -> Self {
        Self {
            joints: JointModel::at(LYING_POSE_RAD),
            velocity_mps: [0.0; 2],
            yaw_rate_radps: 0.0,
            position_m: [0.0, 0.0, LYING_HEIGHT_M],
            rpy_rad: [0.0; 3],
            rpy_rate_radps: [0.0; 3],
            wheel_rad: 0.0,
            distance_m: 0.0,
        }
    }

    /// Advances the body by `dt` seconds.
    pub(crate) fn step(&mut self, dt: f32, drive: &Drive<'_>) {
        self.step_trunk(dt, drive);
        self.step_joints(dt, drive);
    }

    fn step_trunk(&mut self, dt: f32, drive: &Drive<'_>) {
        let c = drive.command;
        let target = match drive.activity {
            _ if drive.stale => [0.0; 3],
            Activity::Walking => [c.vx.get(), c.vy.get(), c.yaw_rate.get()],
            Activity::TwoLegStand => [c.vx.get(), 0.0, c.yaw_rate.get()],
            Activity::Trick(Action::FrontJump) => [FRONT_JUMP_MPS, 0.0, 0.0],
            _ => [0.0; 3],
        }
        .map(finite_or_zero);
        let alpha = (dt / VELOCITY_TAU_S).min(1.0);
        for (v, t) in self.velocity_mps.iter_mut().zip(target) {
            *v += (t - *v) * alpha;
        }
        self.yaw_rate_radps += (target[2] - self.yaw_rate_radps) * alpha;
        let [vx, vy] = self.velocity_mps;
        let yaw = self.rpy_rad[2] + self.yaw_rate_radps * dt;
        self.rpy_rad[2] = (yaw + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU) - std::f32::consts::PI;
        let (sin, cos) = self.rpy_rad[2].sin_cos();
        self.position_m[0] += (vx * cos - vy * sin) * dt;
        self.position_m[1] += (vx * sin + vy * cos) * dt;
        self.distance_m += vx.hypot(vy) * dt;
        if drive.model == Model::Zsl1W {
            self.wheel_rad += vx / WHEEL_RADIUS_M * dt;
        }
        // Attitude: roll and pitch follow the commanded rates within the limit; elsewhere level.
        let attitude = drive.activity == Activity::Attitude && !drive.stale;
        let rates = if attitude {
            [c.roll_rate.get(), c.pitch_rate.get()].map(finite_or_zero)
        } else {
            [-self.rpy_rad[0] * LEVELLING_RATE_PER_S, -self.rpy_rad[1] * LEVELLING_RATE_PER_S]
        };
        for (axis, rate) in rates.into_iter().enumerate() {
            let before = self.rpy_rad[axis];
            self.rpy_rad[axis] = (before + rate * dt).clamp(-ATTITUDE_LIMIT_RAD, ATTITUDE_LIMIT_RAD);
            self.rpy_rate_radps[axis] = (self.rpy_rad[axis] - before) / dt;
        }
        self.rpy_rate_radps[2] = self.yaw_rate_radps;
        let rise = STANDING_HEIGHT_M - LYING_HEIGHT_M;
        let height = match drive.activity {
            Activity::Lying | Activity::Passive => LYING_HEIGHT_M,
            // Getting up and lying down take their whole duration.
            Activity::StandingUp => STANDING_HEIGHT_M - rise * drive.remaining_s / STAND_UP_S,
            Activity::LyingDown => LYING_HEIGHT_M + rise * drive.remaining_s / LIE_DOWN_S,
            Activity::LowLevel => {
                // Height from the mean knee angle: bent knees, low body.
                let knee = self.joints.q_rad.iter().map(|leg| leg[2]).sum::<f32>() / 4.0;
                (0.55 + 0.17 * knee).clamp(0.05, 0.40)
            }
            Activity::Trick(Action::Jump | Action::FrontJump | Action::Backflip) => STANDING_HEIGHT_M + JUMP_HEIGHT_M,
            _ => STANDING_HEIGHT_M,
        };
        let height_rate_mps = if attitude { finite_or_zero(c.height_rate.get()) } else { 0.0 };
        let z =
            self.position_m[2] + height_rate_mps * dt + (height - self.position_m[2]) * (dt / HEIGHT_TAU_S).min(1.0);
        self.position_m[2] = z.clamp(0.05, 0.45);
    }

    fn step_joints(&mut self, dt: f32, drive: &Drive<'_>) {
        if let Some(command) = drive.low_level {
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
        let pose = match drive.activity {
            Activity::Lying | Activity::LyingDown | Activity::Passive => LYING_POSE_RAD,
            Activity::Trick(Action::ShakeHand) => SHAKE_HAND_POSE_RAD,
            _ => STANDING_POSE_RAD,
        };
        let (kp, kd) = if drive.activity == Activity::Passive { PASSIVE_GAINS } else { POSE_GAINS };
        let wheel = self.wheel_rad;
        let shake = drive.activity == Activity::Trick(Action::ShakeHand);
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
}
