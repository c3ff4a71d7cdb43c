#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]

pub mod codec;
#[doc(hidden)]
pub mod harness;
pub mod rules;
pub mod shm;
pub mod udp;

pub use zerocopy;

pub use shm::{
    ConsumerIndex, JointControl, JointFaults, JointFlags, JointIndex, JointState, Leg, LegControl, LegState, NavImu,
    SplineCommandBlock, SplineData, SplineStateBlock,
};
