#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]

pub mod codec;
#[cfg(feature = "fuzzing")]
#[doc(hidden)]
pub mod decode_roundtrip;
#[cfg(feature = "serde")]
pub mod description;
pub mod gate;
pub mod rules;
#[cfg(feature = "serde")]
mod serde_impl;
pub mod shm;
pub mod stream;
pub mod udp;

pub use zerocopy;

pub use shm::{
    ConsumerIndex, JointControl, JointFaults, JointFlags, JointIndex, JointState, Leg, LegControl, LegState, NavImu,
    NavImuSample, SplineCommandBlock, SplineData, SplineStateBlock,
};
