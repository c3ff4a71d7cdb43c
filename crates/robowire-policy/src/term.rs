//! The terms an observation is made of, as a config names them.

use serde::Deserialize;

/// A term of the observation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Term {
    /// The base's linear velocity in the body frame, × `lin_vel_scale` (3).
    BaseLinVel,
    /// The gyroscope, body frame, × `ang_vel_scale` (3).
    BaseAngVel,
    /// Gravity's direction in the body frame, (0, 0, −1) level (3).
    ProjectedGravity,
    /// The command (vx, vy, wz) clamped to `max_cmd`, × `cmd_scale` (3).
    Command,
    /// Joint angles less `default_angles`, × `dof_pos_scale` (`num_actions`).
    JointPos,
    /// Joint velocities × `dof_vel_scale` (`num_actions`).
    JointVel,
    /// The previous step's raw actions (`num_actions`).
    LastAction,
    /// sin and cos of the gait phase (2).
    GaitPhase,
}

impl Term {
    /// `deploy_real.py`'s observation.
    pub const DEPLOY_REAL: [Term; 7] = [
        Term::BaseAngVel,
        Term::ProjectedGravity,
        Term::Command,
        Term::JointPos,
        Term::JointVel,
        Term::LastAction,
        Term::GaitPhase,
    ];

    /// Its values for a policy of `num_actions` joints.
    pub fn len(self, num_actions: usize) -> usize {
        match self {
            Term::BaseLinVel | Term::BaseAngVel | Term::ProjectedGravity | Term::Command => 3,
            Term::JointPos | Term::JointVel | Term::LastAction => num_actions,
            Term::GaitPhase => 2,
        }
    }

    /// Its name in a config.
    pub fn name(self) -> &'static str {
        match self {
            Term::BaseLinVel => "base_lin_vel",
            Term::BaseAngVel => "base_ang_vel",
            Term::ProjectedGravity => "projected_gravity",
            Term::Command => "command",
            Term::JointPos => "joint_pos",
            Term::JointVel => "joint_vel",
            Term::LastAction => "last_action",
            Term::GaitPhase => "gait_phase",
        }
    }
}
