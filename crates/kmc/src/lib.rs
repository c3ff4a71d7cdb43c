#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod client;
mod driver;
mod error;
pub mod odometry;

pub use client::{BlockingUartClient, UartClient};
pub use driver::{
    ALL_STATE_POLL_HZ, BATTERY_POLL_HZ, ChassisState, Driver, DriverOptions, DriverStats, LinkState,
    MAX_COMMAND_TIMEOUT, MAX_RATE_HZ,
};
pub use error::KmcError;
pub use kmc_proto::{AllState, BatteryVoltage, ChassisFrame, VehicleSpeed};
pub use robowire_core::NonFinite;
pub use robowire_rt::device::{Connection, Device, Stamped};
pub use robowire_rt::{Placement, RtError};
pub use robowire_serial::{Backoff, LinkCounters, SerialPortOptions, SerialTaps};
