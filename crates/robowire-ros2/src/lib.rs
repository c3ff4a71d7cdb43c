#![doc = include_str!("../README.md")]

pub mod address;
mod bridge;
mod go2;
pub mod guard;
mod kmc;
mod node;
pub mod odom;
mod report;
mod service;
mod zsl;

pub use address::{AddressError, DeviceAddress, SimKind};
pub use bridge::{BridgeError, BridgeOptions, BridgedDevice, run};
pub use report::{DeviceCounters, DeviceReport};
