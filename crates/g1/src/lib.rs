#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod arm_actions;
mod arm_job;
pub mod arm_stream;
mod battery;
mod client;
mod error;
mod loco;
mod options;

pub use arm_actions::ArmActions;
pub use battery::Battery;
pub use client::{ARM_JOINTS, G1, G1Stats};
pub use error::G1Error;
pub use go2::{Connection, Device, JointCommand, LowLevelOptions, ParticipantOptions, Placement, Stamped};
pub use loco::{
    BalanceMode, HEIGHT_MAX_M, Loco, VELOCITY_DURATION_MAX_S, VX_MAX_MPS, VY_MAX_MPS, Velocity, YAW_RATE_MAX_RADPS,
};
pub use lowcmd_proto::bms::HgBmsState;
pub use lowcmd_proto::g1::{ARM_SDK_JOINTS, DEFAULT_GAINS, G1Variant, JOINT_LIMITS, JOINT_NAMES, JOINTS, ModePr, slot};
pub use lowcmd_proto::robot::CommandError;
pub use lowcmd_proto::{HgLowCmd, HgLowState};
pub use options::G1Options;
