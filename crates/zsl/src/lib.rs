#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

pub mod spline;
pub mod udp;

pub use spline::{ImuError, ImuReader, ImuSample, SplineClient, SplineClientCounters, SplineError, SplineFlags};
pub use zsl_proto::shm::{
    ConsumerIndex, JointControl, JointFlags, JointIndex, Leg, SplineCommandBlock, SplineStateBlock,
};
