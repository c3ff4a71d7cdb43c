#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

pub mod dog;
mod joints;
pub mod kmc;
pub mod spline;
