//! The stand (and lie) motion of Unitree's low-level examples as one sans-IO trajectory: the 12
//! leg joints moved linearly from where they are to a pose over a duration, then held, with
//! fixed gains. A pure function of the elapsed time, and a [`Motion`] of the Go2: handed to
//! [`LowLevel::follow`](crate::LowLevel::follow), the LowCmd stream steps it on its own grid
//! (no loop on the caller's side). Any other motion: a [`Motion`] of the robot's command, or a
//! function of the elapsed time ([`from_fn`]).
//!
//! ```
//! use std::time::Duration;
//! use unitree::trajectory::{JointTrajectory, STAND_KP, stand_pose};
//!
//! let lying = [0.0, 1.36, -2.65].repeat(4).try_into().unwrap();
//! let stand = JointTrajectory::stand_up(lying, Duration::from_secs(2));
//! let halfway = stand.joints_at(Duration::from_secs(1));
//! assert!((halfway[1].q_rad - (1.36 + 0.67) / 2.0).abs() < 1e-6);
//! assert_eq!(halfway[1].kp, STAND_KP);
//! assert_eq!(stand.positions_at(Duration::from_secs(5)), stand_pose());
//! ```

use std::time::Duration;

use unitree_proto::LowCmd;
use unitree_proto::robot::CommandError;
pub use unitree_proto::stream::{FromFn, Motion, from_fn};

use crate::JointCommand;
use crate::go2::STAND_POSE_RAD;

/// Position gain of Unitree's stand example, N·m/rad.
pub const STAND_KP: f32 = 60.0;
/// Velocity gain of Unitree's stand example, N·m·s/rad.
pub const STAND_KD: f32 = 5.0;
/// The pose of a Go2 lying down with its legs folded (Unitree's stand-down target), per leg
/// (hip, thigh, calf), rad.
pub const LIE_POSE_RAD: [f32; 3] = [0.0, 1.36, -2.65];

/// The stand pose for all 12 joints, motor order (FR, FL, RR, RL × hip, thigh, calf), rad.
pub fn stand_pose() -> [f32; 12] {
    std::array::from_fn(|i| STAND_POSE_RAD[i % 3])
}

/// The lying pose for all 12 joints, motor order, rad.
pub fn lie_pose() -> [f32; 12] {
    std::array::from_fn(|i| LIE_POSE_RAD[i % 3])
}

/// `q` (motor order) with each joint clamped to the Go2's range.
fn within_range(q: [f32; 12]) -> [f32; 12] {
    let limits = &unitree_proto::robot::GO2_JOINT_LIMITS;
    std::array::from_fn(|m| q[m].clamp(limits[m].q_min, limits[m].q_max))
}

/// A linear move of the 12 leg joints from `from` to `to` over `duration`, then a hold at `to`,
/// with gains `kp`, `kd`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointTrajectory {
    from: [f32; 12],
    to: [f32; 12],
    duration: Duration,
    kp: f32,
    kd: f32,
}

impl JointTrajectory {
    /// From `from` to `to` (rad, motor order) over `duration`, then held.
    pub fn new(from: [f32; 12], to: [f32; 12], duration: Duration, kp: f32, kd: f32) -> Self {
        Self { from, to, duration, kp, kd }
    }

    /// Unitree's stand-up: from `from` to the stand pose over `duration` at kp 60, kd 5. A
    /// start a hair past a joint's range (a joint pressed against its stop, as a lying robot's
    /// calves are) starts at the range's end, so that every target is within the Go2's ranges.
    pub fn stand_up(from: [f32; 12], duration: Duration) -> Self {
        Self::new(within_range(from), stand_pose(), duration, STAND_KP, STAND_KD)
    }

    /// Unitree's stand-down: from `from` (as [`JointTrajectory::stand_up`] takes it) to the
    /// lying pose over `duration` at kp 60, kd 5.
    pub fn lie_down(from: [f32; 12], duration: Duration) -> Self {
        Self::new(within_range(from), lie_pose(), duration, STAND_KP, STAND_KD)
    }

    /// How far along the move is at `elapsed`: 0 at the start, 1 from `duration` on.
    pub fn fraction_at(&self, elapsed: Duration) -> f32 {
        if self.duration.is_zero() { 1.0 } else { (elapsed.as_secs_f32() / self.duration.as_secs_f32()).min(1.0) }
    }

    /// The joint positions at `elapsed`, rad.
    pub fn positions_at(&self, elapsed: Duration) -> [f32; 12] {
        let s = self.fraction_at(elapsed);
        std::array::from_fn(|i| if s >= 1.0 { self.to[i] } else { self.from[i] + (self.to[i] - self.from[i]) * s })
    }

    /// The joint commands at `elapsed`: the positions, zero velocity and torque, the gains.
    pub fn joints_at(&self, elapsed: Duration) -> [JointCommand; 12] {
        self.positions_at(elapsed).map(|q| JointCommand::hold(q, self.kp, self.kd))
    }

    /// The pose the move ends at, rad.
    pub fn target(&self) -> [f32; 12] {
        self.to
    }

    /// The move's duration.
    pub fn duration(&self) -> Duration {
        self.duration
    }

    /// The gains, (kp N·m/rad, kd N·m·s/rad).
    pub fn gains(&self) -> (f32, f32) {
        (self.kp, self.kd)
    }

    /// The largest |q − target| over the joints, rad.
    pub fn largest_error_rad(&self, q_rad: &[f32; 12]) -> f32 {
        q_rad.iter().zip(self.to).map(|(q, t)| (q - t).abs()).fold(0.0, f32::max)
    }
}

/// The Go2's command at `elapsed`: [`JointTrajectory::joints_at`] on the 12 leg joints (as
/// [`LowLevel::set_joints`](crate::LowLevel::set_joints) sends them).
impl Motion<LowCmd> for JointTrajectory {
    fn command_at(&self, elapsed: Duration) -> Result<LowCmd, CommandError> {
        Ok(crate::client::go2_command(&self.joints_at(elapsed)))
    }

    fn duration(&self) -> Duration {
        self.duration
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stand_up_from_past_a_stop_starts_at_the_stop() {
        let mut lying = lie_pose();
        lying[2] = -2.7231; // a calf pressed a hair past its stop at −2.7227
        let stand = JointTrajectory::stand_up(lying, Duration::from_secs(1));
        assert_eq!(stand.positions_at(Duration::ZERO)[2], -2.7227);
        assert_eq!(stand.positions_at(Duration::ZERO)[1], lying[1]);
    }

    #[test]
    fn a_linear_move_then_a_hold() {
        let from = [0.0; 12];
        let t = JointTrajectory::new(from, [1.0; 12], Duration::from_millis(100), 20.0, 1.0);
        assert_eq!(t.positions_at(Duration::ZERO), from);
        assert_eq!(t.positions_at(Duration::from_millis(25)), [0.25; 12]);
        assert_eq!(t.positions_at(Duration::from_secs(60)), [1.0; 12]);
        assert_eq!(t.joints_at(Duration::from_millis(50))[3], JointCommand::hold(0.5, 20.0, 1.0));
        assert_eq!(t.largest_error_rad(&[0.9; 12]), 0.100000024);
        let at_once = JointTrajectory::stand_up(from, Duration::ZERO);
        assert_eq!(at_once.positions_at(Duration::ZERO), stand_pose());
        assert_eq!(JointTrajectory::lie_down(stand_pose(), Duration::ZERO).target(), lie_pose());
    }
}
