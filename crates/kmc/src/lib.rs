#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod client;
mod driver;
mod error;

pub use client::{BlockingUartClient, UartClient};
pub use driver::{ALL_STATE_POLL_HZ, BATTERY_POLL_HZ, Driver, DriverOptions, DriverStats, LinkState, MAX_RATE_HZ};
pub use error::KmcError;
pub use kmc_proto::{AllState, BatteryVoltage, ChassisFrame, VehicleSpeed};
pub use robowire_core::NonFinite;
pub use robowire_rt::RtError;
pub use robowire_serial::{Backoff, LinkCounters, SerialPortOptions};
