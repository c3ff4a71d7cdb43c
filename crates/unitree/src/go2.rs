//! The Go2: the family's [`LowLevel`](crate::LowLevel) with the Go2's message and rules.

pub use unitree_proto::robot::{GO2_JOINT_LIMITS as JOINT_LIMITS, GO2_JOINT_NAMES as JOINT_NAMES, Go2};
pub use unitree_proto::{LowCmd, LowState, MotorCmd};

/// The Go2's low-level client.
pub type LowLevel = crate::LowLevel<Go2>;

/// The stand pose of Unitree's examples, per leg (hip, thigh, calf), rad.
pub const STAND_POSE_RAD: [f32; 3] = [0.0, 0.67, -1.3];
