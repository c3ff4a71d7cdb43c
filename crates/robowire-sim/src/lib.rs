#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

#[cfg(feature = "zsl")]
#[deprecated(note = "renamed `robowire_sim::zsl1` (`DogSim` is `Zsl1Sim`, `DogSimConfig` is `Zsl1SimConfig`, …)")]
pub mod dog;
#[cfg(feature = "g1")]
pub mod g1;
#[cfg(feature = "go2")]
pub mod go2;
#[cfg(any(feature = "kmc", feature = "zsl", feature = "go2", feature = "g1"))]
mod handover;
#[cfg(any(feature = "zsl", feature = "go2", feature = "g1"))]
mod joints;
#[cfg(feature = "kmc")]
pub mod kmc;
#[cfg(feature = "mujoco")]
pub mod physics;
#[cfg(any(feature = "go2", feature = "g1"))]
mod plant;
#[cfg(any(feature = "replay", feature = "replay-serial", feature = "replay-dds"))]
pub mod replay;
#[cfg(feature = "zsl")]
pub mod spline;
#[cfg(any(feature = "go2", feature = "g1"))]
mod unitree;
#[cfg(feature = "zsl")]
pub mod zsl1;
