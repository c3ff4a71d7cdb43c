#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod driver;
mod error;
#[cfg(feature = "netns")]
pub mod netns;
mod participant;
pub mod qos;
mod reader;
pub mod rpc;
mod sample;
mod slot;
mod sockets;
mod writer;

pub use driver::Incompatible;
pub use error::DdsError;
pub use participant::{DiscoveredEndpoint, DiscoveredParticipant, DiscoveredTopic, Participant, ParticipantOptions};
pub use reader::{Listener, Reader};
pub use sample::{RawSample, Sample, SampleIdentity, StatsHandle, TopicStats};
#[doc(hidden)]
pub use sample::{fuzz_check_sample, unpadded};
pub use writer::{WriteRefused, Writer};
