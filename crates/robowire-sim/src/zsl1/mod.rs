//! The ZSL-1 / ZSL-1W on UDP (spec `zsl1-udp.md` §11): HighLevel commands on 43997, LowLevel
//! on 43900, state to each client at 500 Hz, and at once when a command changes.
//!
//! - [`Zsl1Model`] ([`model`]): the robot, sans I/O: the vendor's modes with timed transitions,
//!   the commands it was given, battery, faults, and the state datagrams it reports.
//! - the body (`body.rs`): velocity with a lag, position and heading integrated from it,
//!   attitude, height, and the joints through the shared PD joint model.
//! - [`Zsl1Sim`] (`server.rs`): the model on two UDP ports through `robowire-udp`'s device side.

mod activity;
mod body;
pub mod model;
mod server;

pub use body::{LYING_HEIGHT_M, STANDING_HEIGHT_M};
pub use model::{Activity, COMMAND_TIMEOUT_S, Faults, Zsl1Fault, Zsl1Model};
pub use server::{PortStats, Zsl1Sim, Zsl1SimConfig, Zsl1Snapshot};
