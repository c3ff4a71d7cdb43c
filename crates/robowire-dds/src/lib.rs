#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod adapter;
mod error;
#[cfg(feature = "netns")]
pub mod netns;
mod participant;
pub mod qos;
pub mod rpc;
mod topic;

#[doc(hidden)]
#[doc(hidden)]
pub use adapter::fuzz_check_sample;
pub use error::DdsError;
pub use participant::{DiscoveredEndpoint, DiscoveredTopic, Participant, ParticipantOptions};
pub use topic::{RawSample, Reader, Sample, SampleIdentity, StatsHandle, TopicStats, WriteRefused, Writer};
