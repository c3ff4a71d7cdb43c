//! The ZSL-1 UDP clients: [`HighLevel`] (walk, tricks, attitude) and [`LowLevel`] (twelve motors),
//! wire-compatible with the vendor SDK v0.2.7 (spec `zsl1-udp.md`), safer where the spec's
//! robowire decisions say so.
//!
//! Both stream their latched command every 2 ms on absolute deadlines, send a new command the
//! moment it is accepted, decode state leniently by default (anomalies counted), drop state from
//! any IP but the robot's, and keep a 3 s watchdog that reports [`Connection::Disconnected`],
//! zeroes every latched velocity, and recovers by itself when state returns.

mod core;
mod high_level;
mod low_level;
mod snapshot;

pub use self::core::{CallError, ClientOptions, ClientStats, ConnectError, Connection};
pub use high_level::HighLevel;
pub use low_level::LowLevel;
pub use snapshot::{BodyState, Imu, JointArrays, LegJoints};
pub use zsl_proto::codec::StateDecoding;
pub use zsl_proto::udp::{
    Action, ControlMode, HighLevelCommand, HighLevelState, LowLevelCommand, LowLevelState, Model, MotorCommand,
    MotorState, ReturnCode,
};
