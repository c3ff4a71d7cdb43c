//! unitree's integration tests over real DDS, one binary with a module per subject (`cargo test
//! -p unitree --test it go2_sim::` runs one), where loopback carries multicast
//! (`robowire_dds::netns`): the Go2 and G1 clients against the simulators, the HG client's stream
//! with nothing answering, and the G1 client against CycloneDDS with Unitree's IDL classes (gated
//! like every interop test).
//!
//! Every test takes `robowire_fixtures::wait::one_at_a_time`: one robot and its client at a time
//! on the two cores, and no two tests on domain 0's topics at once where `lo` already carries
//! multicast (then they share this host's network), as when each file was a binary of its own.

mod common;

mod g1_cyclone;
mod g1_dds;
mod g1_follow;
mod go2_sim;
mod hg_sim;
