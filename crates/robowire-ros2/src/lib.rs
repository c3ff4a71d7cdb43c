//! ROS 2 on the wire for every robowire device, without a ROS installation: each device a node
//! with the topics and services a ROS user expects, on robowire's DDS transport with the ROS 2
//! names, types and QoS of `ros2-proto`. `robowire ros2` is this crate's front end.
//!
//! Safe by default: without `armed` a bridge only publishes; armed, a `cmd_vel` older than the
//! deadman time stops the robot, and NaN, infinite or out-of-range twists are dropped and
//! counted, never sent.

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
