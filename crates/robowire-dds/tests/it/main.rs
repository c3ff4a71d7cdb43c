//! robowire-dds's integration tests on sockets, one binary with a module per subject (`cargo test
//! -p robowire-dds --test it rustdds::` runs one): two participants of ours on loopback, the
//! private network of `netns` itself, and robowire-dds against the other DDS implementations
//! (CycloneDDS through its Python binding, Fast DDS through a C++ peer, rustdds in-process), each
//! scenario in a private network of its own.
//!
//! `tests/alloc.rs` stays a binary of its own: it counts the allocations of its process with a
//! global allocator of its own.

mod cyclone;
mod fastdds;
mod loopback;
mod netns;
mod rustdds;
