//! A policy's deploy config: unitree_rl_gym's `deploy/deploy_real/configs/*.yaml` with its fields
//! unchanged, and robowire's optional additions, each defaulting to what `deploy_real.py` does.

use std::path::{Path, PathBuf};

use serde::Deserialize;
use unitree_proto::go2::MOTOR_COUNT;
use unitree_proto::hg::HG_MOTOR_COUNT;

use crate::term::Term;

/// The LowCmd/LowState family a config drives (`msg_type`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MsgType {
    /// `unitree_hg`: the G1 and H1-2.
    Hg,
    /// `unitree_go`: the Go2 and H1.
    Go,
}

impl std::fmt::Display for MsgType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            MsgType::Hg => "hg (G1, H1-2)",
            MsgType::Go => "go (Go2)",
        })
    }
}

impl MsgType {
    /// The motors of its LowCmd.
    pub fn motors(self) -> usize {
        match self {
            MsgType::Hg => HG_MOTOR_COUNT,
            MsgType::Go => MOTOR_COUNT,
        }
    }
}

/// Where the robot's IMU sits (`imu_type`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ImuType {
    /// On the pelvis, the policy's base: read as it is.
    Pelvis,
    /// On the torso, above the waist yaw joint (the first of `arm_waist_joint2motor_idx`):
    /// turned into the pelvis frame.
    Torso,
}

/// A deploy config, as read.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PolicyConfig {
    /// Seconds between two policy steps.
    pub control_dt: f64,
    /// The message family.
    pub msg_type: MsgType,
    /// Where the IMU sits.
    #[serde(default = "pelvis")]
    pub imu_type: ImuType,
    /// The LowCmd topic (`rt/lowcmd`).
    #[serde(default = "lowcmd_topic")]
    pub lowcmd_topic: String,
    /// The LowState topic (`rt/lowstate`).
    #[serde(default = "lowstate_topic")]
    pub lowstate_topic: String,
    /// The ONNX model, relative to the config's directory.
    pub policy_path: PathBuf,
    /// The motor of each policy joint, in the policy's order.
    pub leg_joint2motor_idx: Vec<usize>,
    /// Stiffness of each policy joint, N·m/rad.
    pub kps: Vec<f32>,
    /// Damping of each policy joint, N·m·s/rad.
    pub kds: Vec<f32>,
    /// Each policy joint's default angle, rad: the pose moved to, and `target = action ×
    /// action_scale + default`.
    pub default_angles: Vec<f32>,
    /// Motors held at `arm_waist_target` and not part of the policy.
    #[serde(default)]
    pub arm_waist_joint2motor_idx: Vec<usize>,
    /// Their stiffness, N·m/rad.
    #[serde(default)]
    pub arm_waist_kps: Vec<f32>,
    /// Their damping, N·m·s/rad.
    #[serde(default)]
    pub arm_waist_kds: Vec<f32>,
    /// Their angle, rad.
    #[serde(default)]
    pub arm_waist_target: Vec<f32>,
    /// Scale of the gyroscope's angular velocity in the observation.
    pub ang_vel_scale: f32,
    /// Scale of joint positions (less their defaults) in the observation.
    pub dof_pos_scale: f32,
    /// Scale of joint velocities in the observation.
    pub dof_vel_scale: f32,
    /// Radians of target per unit of action.
    pub action_scale: f32,
    /// Scale of the command (vx, vy, wz) in the observation.
    pub cmd_scale: [f32; 3],
    /// The policy's outputs (its joints).
    pub num_actions: usize,
    /// The observation's length.
    pub num_obs: usize,
    /// The largest command magnitude per axis: m/s, m/s, rad/s. Commands are clamped to it.
    pub max_cmd: [f32; 3],
    /// Motors in the Go family's weak mode (mode 1 instead of 0x0A).
    #[serde(default)]
    pub weak_motor: Vec<usize>,
    /// robowire: the observation's terms in order. Default: `deploy_real.py`'s.
    #[serde(default = "default_observation")]
    pub observation: Vec<Term>,
    /// robowire: scale of the body-frame linear velocity in the observation.
    #[serde(default = "one")]
    pub lin_vel_scale: f32,
    /// robowire: the gait period, s.
    #[serde(default = "gait_period")]
    pub gait_period: f64,
    /// robowire: the roll or pitch past which the robot is damped, rad.
    #[serde(default = "max_tilt")]
    pub max_tilt_rad: f32,
}

/// Why a config cannot run: each names the field.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ConfigError {
    /// The file could not be read.
    #[error("cannot read {path}")]
    Read {
        /// The config's path.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// Not YAML of a deploy config (a field missing, unknown or of the wrong type).
    #[error("{path}: {message}")]
    Parse {
        /// The config's path.
        path: PathBuf,
        /// The parser's line, with the field.
        message: String,
    },
    /// A field out of range or sized against another.
    #[error("{field}: {why}")]
    Field {
        /// The field.
        field: &'static str,
        /// What is wrong with it.
        why: String,
    },
}

impl PolicyConfig {
    /// Reads and checks the config at `path`; `policy_path` becomes relative to its directory.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let text =
            std::fs::read_to_string(path).map_err(|source| ConfigError::Read { path: path.to_owned(), source })?;
        let mut config = Self::parse(&text).map_err(|e| match e {
            ConfigError::Parse { message, .. } => ConfigError::Parse { path: path.to_owned(), message },
            other => other,
        })?;
        if config.policy_path.is_relative() {
            config.policy_path = path.parent().unwrap_or(Path::new("")).join(&config.policy_path);
        }
        Ok(config)
    }

    /// Parses and checks a config's text; `policy_path` as written.
    pub fn parse(text: &str) -> Result<Self, ConfigError> {
        let config: Self = serde_saphyr::from_str(text)
            .map_err(|e| ConfigError::Parse { path: PathBuf::new(), message: one_line(&e.to_string()) })?;
        config.check()?;
        Ok(config)
    }

    /// The observation's length from its terms.
    pub fn observation_len(&self) -> usize {
        self.observation.iter().map(|t| t.len(self.num_actions)).sum()
    }

    /// Checks every size and range against the others.
    pub fn check(&self) -> Result<(), ConfigError> {
        let n = self.num_actions;
        if !(self.control_dt.is_finite() && self.control_dt > 0.0 && self.control_dt <= 1.0) {
            return field("control_dt", format!("{} s is not in (0, 1]", self.control_dt));
        }
        if n == 0 {
            return field("num_actions", "must be above 0".into());
        }
        for (name, len) in [
            ("leg_joint2motor_idx", self.leg_joint2motor_idx.len()),
            ("kps", self.kps.len()),
            ("kds", self.kds.len()),
            ("default_angles", self.default_angles.len()),
        ] {
            if len != n {
                return field(name, format!("has {len} entries, num_actions is {n}"));
            }
        }
        let held = self.arm_waist_joint2motor_idx.len();
        for (name, len) in [
            ("arm_waist_kps", self.arm_waist_kps.len()),
            ("arm_waist_kds", self.arm_waist_kds.len()),
            ("arm_waist_target", self.arm_waist_target.len()),
        ] {
            if len != held {
                return field(name, format!("has {len} entries, arm_waist_joint2motor_idx has {held}"));
            }
        }
        if self.imu_type == ImuType::Torso && held == 0 {
            return field("imu_type", "torso needs the waist yaw motor first in arm_waist_joint2motor_idx".into());
        }
        let motors = self.msg_type.motors();
        let mut seen = [false; HG_MOTOR_COUNT];
        for (name, list) in [
            ("leg_joint2motor_idx", &self.leg_joint2motor_idx),
            ("arm_waist_joint2motor_idx", &self.arm_waist_joint2motor_idx),
        ] {
            for &motor in list {
                match seen.get_mut(motor).filter(|_| motor < motors) {
                    None => return field(name, format!("motor {motor} is past the LowCmd's {motors}")),
                    Some(true) => return field(name, format!("motor {motor} is listed twice")),
                    Some(s) => *s = true,
                }
            }
        }
        let finite = |name: &'static str, values: &[f32]| match values.iter().find(|v| !v.is_finite()) {
            Some(v) => field(name, format!("{v} is not finite")),
            None => Ok(()),
        };
        finite("kps", &self.kps)?;
        finite("kds", &self.kds)?;
        finite("default_angles", &self.default_angles)?;
        finite("arm_waist_kps", &self.arm_waist_kps)?;
        finite("arm_waist_kds", &self.arm_waist_kds)?;
        finite("arm_waist_target", &self.arm_waist_target)?;
        finite("cmd_scale", &self.cmd_scale)?;
        finite("max_cmd", &self.max_cmd)?;
        for (name, gains) in [
            ("kps", &self.kps),
            ("kds", &self.kds),
            ("arm_waist_kps", &self.arm_waist_kps),
            ("arm_waist_kds", &self.arm_waist_kds),
        ] {
            if let Some(v) = gains.iter().find(|v| **v < 0.0) {
                return field(name, format!("gain {v} is negative"));
            }
        }
        if let Some(v) = self.max_cmd.iter().find(|v| **v < 0.0) {
            return field("max_cmd", format!("{v} is negative"));
        }
        for (name, v) in [
            ("ang_vel_scale", self.ang_vel_scale),
            ("dof_pos_scale", self.dof_pos_scale),
            ("dof_vel_scale", self.dof_vel_scale),
            ("action_scale", self.action_scale),
            ("lin_vel_scale", self.lin_vel_scale),
        ] {
            finite(name, &[v])?;
        }
        if !(self.gait_period.is_finite() && self.gait_period > 0.0) {
            return field("gait_period", format!("{} s is not above 0", self.gait_period));
        }
        if !(self.max_tilt_rad.is_finite() && self.max_tilt_rad > 0.0) {
            return field("max_tilt_rad", format!("{} rad is not above 0", self.max_tilt_rad));
        }
        for (i, term) in self.observation.iter().enumerate() {
            if self.observation[..i].contains(term) {
                return field("observation", format!("{} is listed twice", term.name()));
            }
        }
        let len = self.observation_len();
        if len != self.num_obs {
            return field("num_obs", format!("is {}, the observation's terms make {len}", self.num_obs));
        }
        Ok(())
    }
}

fn field(field: &'static str, why: String) -> Result<(), ConfigError> {
    Err(ConfigError::Field { field, why })
}

/// The parser's message on one line.
fn one_line(message: &str) -> String {
    message.split_whitespace().collect::<Vec<_>>().join(" ")
}

fn pelvis() -> ImuType {
    ImuType::Pelvis
}

fn lowcmd_topic() -> String {
    "rt/lowcmd".into()
}

fn lowstate_topic() -> String {
    "rt/lowstate".into()
}

fn one() -> f32 {
    1.0
}

fn gait_period() -> f64 {
    0.8
}

fn max_tilt() -> f32 {
    1.0
}

fn default_observation() -> Vec<Term> {
    Term::DEPLOY_REAL.to_vec()
}
