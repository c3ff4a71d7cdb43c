//! robowire-sim's integration tests, one binary with a module per subject (`cargo test -p
//! robowire-sim --test it zsl1::` runs one): each simulator from its client's end (the KMC chassis
//! on a pseudo-terminal, the ZSL-1 on UDP, the spline daemon on shared memory, the Go2 and the G1
//! on DDS), the replay devices, the Unitree conformance checks every simulated robot passes, and
//! with the feature `mujoco` the bodies in MuJoCo (`physics`; `cargo xtask test` runs the physics
//! tests as `--features mujoco --test it -- physics:: unitree_conformance::`).
//!
//! A module is built with the features its simulator needs, as its `[[test]]` target's
//! `required-features` were. `tests/go2_cyclone.rs` stays a binary of its own: its two tests run
//! Unitree's Python clients on CycloneDDS against a simulated Go2 one at a time, alone in their
//! process (`one_at_a_time`), where this binary's other robots would share the two cores with
//! them.

#[cfg(all(feature = "go2", feature = "g1"))]
mod conformance;
#[cfg(any(feature = "kmc", feature = "zsl", feature = "go2"))]
mod hammer;
#[cfg(feature = "g1")]
mod unitree_wire;

#[cfg(feature = "kmc")]
mod chassis;
#[cfg(feature = "g1")]
mod g1;
#[cfg(feature = "go2")]
mod go2;
#[cfg(all(feature = "mujoco", feature = "go2", feature = "g1"))]
mod physics;
#[cfg(feature = "zsl")]
mod replay;
#[cfg(feature = "go2")]
mod replay_dds;
#[cfg(feature = "kmc")]
mod replay_serial;
#[cfg(feature = "zsl")]
mod spline;
#[cfg(all(feature = "go2", feature = "g1"))]
mod unitree_conformance;
#[cfg(feature = "zsl")]
mod zsl1;
