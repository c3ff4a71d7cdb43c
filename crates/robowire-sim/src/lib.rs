#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

pub mod dog;
pub mod go2;
mod joints;
pub mod kmc;
pub mod spline;
