//! `robowire.policy.PolicyConfig`: a deploy config (unitree_rl_gym's fields and robowire's
//! additions) read and checked by `robowire_policy`, its fields readable.

use std::path::PathBuf;

use pyo3::prelude::*;
use robowire_policy::{ConfigError, ImuType, MsgType, PolicyConfig};

use crate::errors::{Kind, chain, error};

/// A `ConfigError` as an exception: `ArgumentError` for a config that is not one, `robowire.Error`
/// for a file that cannot be read.
fn raise(e: &ConfigError) -> PyErr {
    match e {
        ConfigError::Read { .. } => error(Kind::Error, chain(e)),
        _ => error(Kind::Argument, chain(e)),
    }
}

/// A policy's deploy config: unitree_rl_gym's `deploy/deploy_real/configs/*.yaml` with its
/// fields unchanged, and robowire's optional additions.
#[pyclass(name = "PolicyConfig", module = "robowire.policy", frozen)]
pub(crate) struct PyPolicyConfig {
    pub(crate) config: PolicyConfig,
    path: PathBuf,
}

impl PyPolicyConfig {
    /// Reads and checks the config at `path`, the GIL released.
    pub(crate) fn read(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        py.detach(|| PolicyConfig::load(&path)).map(|config| Self { config, path }).map_err(|e| raise(&e))
    }
}

#[pymethods]
impl PyPolicyConfig {
    /// Reads and checks the config at `path` (a str or os.PathLike); `policy_path` becomes
    /// relative to its directory. A config whose fields are missing, unknown, out of range or
    /// sized against each other raises `ArgumentError` with one line naming the field; a file
    /// that cannot be read, `robowire.Error`.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        Self::read(py, path)
    }

    /// The file it was read from.
    #[getter]
    fn path(&self) -> String {
        self.path.to_string_lossy().into_owned()
    }

    /// Seconds between two policy steps.
    #[getter]
    fn control_dt(&self) -> f64 {
        self.config.control_dt
    }

    /// `"hg"` (G1, H1-2) or `"go"` (Go2).
    #[getter]
    fn msg_type(&self) -> &'static str {
        match self.config.msg_type {
            MsgType::Hg => "hg",
            MsgType::Go => "go",
        }
    }

    /// `"pelvis"` or `"torso"`.
    #[getter]
    fn imu_type(&self) -> &'static str {
        match self.config.imu_type {
            ImuType::Pelvis => "pelvis",
            ImuType::Torso => "torso",
        }
    }

    /// The ONNX model's path.
    #[getter]
    fn policy_path(&self) -> String {
        self.config.policy_path.to_string_lossy().into_owned()
    }

    /// The motor of each policy joint, in the policy's order.
    #[getter]
    fn leg_joint2motor_idx(&self) -> Vec<usize> {
        self.config.leg_joint2motor_idx.clone()
    }

    /// Stiffness of each policy joint, N·m/rad.
    #[getter]
    fn kps(&self) -> Vec<f32> {
        self.config.kps.clone()
    }

    /// Damping of each policy joint, N·m·s/rad.
    #[getter]
    fn kds(&self) -> Vec<f32> {
        self.config.kds.clone()
    }

    /// Each policy joint's default angle, rad.
    #[getter]
    fn default_angles(&self) -> Vec<f32> {
        self.config.default_angles.clone()
    }

    /// Motors held at `arm_waist_target`, not part of the policy.
    #[getter]
    fn arm_waist_joint2motor_idx(&self) -> Vec<usize> {
        self.config.arm_waist_joint2motor_idx.clone()
    }

    /// Radians of target per unit of action.
    #[getter]
    fn action_scale(&self) -> f32 {
        self.config.action_scale
    }

    /// Scale of the command (vx, vy, wz) in the observation.
    #[getter]
    fn cmd_scale(&self) -> [f32; 3] {
        self.config.cmd_scale
    }

    /// The largest command per axis: m/s, m/s, rad/s.
    #[getter]
    fn max_cmd(&self) -> [f32; 3] {
        self.config.max_cmd
    }

    /// The policy's outputs.
    #[getter]
    fn num_actions(&self) -> usize {
        self.config.num_actions
    }

    /// The observation's length.
    #[getter]
    fn num_obs(&self) -> usize {
        self.config.num_obs
    }

    /// The observation's terms in order (`"base_ang_vel"`, `"projected_gravity"`, …).
    #[getter]
    fn observation(&self) -> Vec<&'static str> {
        self.config.observation.iter().map(|t| t.name()).collect()
    }

    /// The gait period, s.
    #[getter]
    fn gait_period(&self) -> f64 {
        self.config.gait_period
    }

    /// The roll or pitch past which the robot is damped, rad.
    #[getter]
    fn max_tilt_rad(&self) -> f32 {
        self.config.max_tilt_rad
    }

    fn __repr__(&self) -> String {
        format!(
            "PolicyConfig({:?}, msg_type={:?}, num_obs={}, num_actions={})",
            self.path(),
            self.msg_type(),
            self.config.num_obs,
            self.config.num_actions
        )
    }
}
