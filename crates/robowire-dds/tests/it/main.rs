//! robowire-dds's integration tests on sockets, one binary with a module per subject (`cargo test
//! -p robowire-dds --test it rustdds::` runs one): two participants of ours on loopback, the
//! private network of `netns` itself, and robowire-dds against Fast DDS (a C++ peer) and rustdds
//! (in-process), each scenario in a private network of its own.
//!
//! Two binaries stay apart: `tests/alloc.rs` counts the allocations of its process with a global
//! allocator of its own; `tests/cyclone.rs` runs 18 CycloneDDS scenarios at once (Python peers,
//! two under loss), which beside Fast DDS's peers on two cores ran out of their 30 s.

mod fastdds;
mod loopback;
mod netns;
mod rustdds;
