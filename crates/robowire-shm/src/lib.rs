#![doc = include_str!("../README.md")]
#![deny(unsafe_code)]

mod heap;
mod mapped;
// The only module with `unsafe`.
#[allow(unsafe_code)]
mod raw;
mod region;

pub use heap::HeapRegion;
pub use mapped::{CreateOptions, MappedRegion, Ownership, ShmError};
pub use region::{RegionError, SharedRegion, VersionedRead, VersionedReadError};
pub use robowire_core::shm::{FlaggedBlock, VersionedRecord};
