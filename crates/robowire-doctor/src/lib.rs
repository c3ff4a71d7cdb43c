#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

pub mod check;
pub mod dds;
pub mod firewall;
pub mod host;
mod probe;

pub use check::{Check, Report, Verdict};
pub use probe::{DoctorError, Options, Target, diagnose, simulate};
