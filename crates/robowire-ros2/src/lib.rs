#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod bridge;
mod device;
mod error;
mod graph;
pub mod guard;
mod node;
mod report;
mod service;

pub use bridge::{BridgeOptions, BridgedDevice, namespaces, run};
pub use error::BridgeError;
pub use graph::{NODE_NAME, RosDistro, UnknownDistro};
pub use report::{DeviceCounters, DeviceReport};
pub use robowire_devices::{AddressError, DeviceAddress, DeviceKind, SimPhysics};
