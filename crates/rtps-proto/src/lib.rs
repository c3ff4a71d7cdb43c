#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]

extern crate alloc;

pub mod discovery;
pub mod endpoint;
#[cfg(feature = "fuzzing")]
#[doc(hidden)]
pub mod fuzzing;
pub mod limits;
pub mod participant;
pub mod types;
pub mod wire;

pub use limits::Limits;
pub use robowire_core::schedule::Time;
pub use types::{
    EntityId, FragmentNumberSet, Guid, GuidPrefix, Locator, ProtocolVersion, SequenceNumber, SequenceNumberSet,
    Timestamp, VendorId,
};
pub use wire::WireError;
