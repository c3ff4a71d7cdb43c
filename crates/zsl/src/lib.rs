#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

pub mod spline;
pub mod udp;

pub use spline::{
    CommandUpdate, ImuError, ImuReader, ImuSample, ImuWriter, SplineClient, SplineClientCounters, SplineDaemon,
    SplineDaemonCounters, SplineError,
};
pub use zsl_proto::shm::{
    ConsumerIndex, JointControl, JointFlags, JointIndex, Leg, SplineCommandBlock, SplineStateBlock,
};
