#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]

pub mod shm;

pub use zerocopy;

pub use shm::{
    ConsumerIndex, JointControl, JointFaults, JointFlags, JointIndex, JointState, Leg, LegControl, LegState, NavImu,
    SplineCommandBlock, SplineData, SplineStateBlock,
};
