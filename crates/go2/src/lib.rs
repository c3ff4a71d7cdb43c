#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod client;
mod error;
mod options;
pub mod services;
mod stream;
pub mod trajectory;

pub use client::{Go2Stats, JointCommand, LowLevel};
pub use error::Go2Error;
pub use lowcmd_proto::robot::{CommandError, GO2_JOINT_LIMITS, GO2_JOINT_NAMES, Go2, Hg, JointLimits, Robot};
pub use lowcmd_proto::{HgLowCmd, HgLowState, LowCmd, LowState, MotorCmd};
pub use options::{FIRST_STATE_TIMEOUT, LowLevelOptions, STATE_TIMEOUT};
pub use robowire_core::schedule::Connection;
pub use robowire_dds::ParticipantOptions;
pub use robowire_rt::device::{Device, Stamped};
pub use robowire_rt::{Placement, RtError};

/// The stand pose of Unitree's examples, per leg (hip, thigh, calf), rad.
pub const STAND_POSE_RAD: [f32; 3] = [0.0, 0.67, -1.3];
