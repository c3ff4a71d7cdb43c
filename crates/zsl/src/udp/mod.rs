//! The ZSL-1 UDP clients: [`HighLevel`] (walk, tricks, attitude) and [`LowLevel`] (twelve motors),
//! wire-compatible with the vendor SDK v0.2.7 (spec `zsl1-udp.md`), safer where the spec's
//! robowire decisions say so.
//!
//! Both are a session with the robot: a stream thread (robowire's runner, optionally
//! `SCHED_FIFO` and pinned) sends their latched command every 2 ms on absolute deadlines and a
//! new command the moment a call latches it; they decode state leniently by default
//! (anomalies counted), drop state from any IP but the robot's (its sending port is not
//! documented, so any port of that IP), and keep a 3 s watchdog that reports
//! [`Connection::Disconnected`], zeroes every latched velocity, and recovers by itself when state
//! returns.
//!
//! State and commands come typed, with units in the names ([`RobotState`], [`LowLevelState`],
//! [`MotorCommand`]). The datagrams as the vendor lays them out are `zsl_proto::udp`'s; the
//! `wire_*` accessors return them for logging and inspection.

mod error;
mod high_level;
mod low_level;
mod options;
mod session;
mod shared;
mod snapshot;
mod stream;

pub use error::{CallError, ConnectError, Latched};
pub use high_level::HighLevel;
pub use low_level::LowLevel;
pub use options::{ClientOptions, MIN_PERIOD};
pub use robowire_rt::device::{Device, Stamped};
pub use robowire_rt::{Placement, RtError};
pub use session::ClientStats;
pub use snapshot::{BodyState, Imu, JointArrays, LegJoints, LowLevelState, MotorCommand, MotorState, RobotState};
pub use zsl_proto::codec::StateDecoding;
pub use zsl_proto::gate::{HighLevelCall, Refusal};
pub use zsl_proto::stream::Connection;
pub use zsl_proto::udp::{Action, ControlMode, Model, ReturnCode};
