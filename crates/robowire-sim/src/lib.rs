#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

#[cfg(feature = "zsl")]
pub mod dog;
#[cfg(feature = "go2")]
pub mod go2;
mod handover;
#[cfg(any(feature = "zsl", feature = "go2"))]
mod joints;
#[cfg(feature = "kmc")]
pub mod kmc;
#[cfg(feature = "zsl")]
pub mod spline;
