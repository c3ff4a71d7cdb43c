#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

pub mod check;
pub mod dds;
pub mod firewall;
pub mod host;
pub mod kmc;
mod probe;
pub mod zsl1;

pub use check::{Check, Report, Verdict};
pub use probe::{DoctorError, Options, Simulated, Target, diagnose, prepare};
