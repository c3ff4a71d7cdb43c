//! The `robowire` command line's integration tests, one binary: the binary under test run as users
//! run it (its commands, flags, exit codes, what it prints and records), one module per command or
//! subject. What a library does is tested with its crate: the ROS 2 bridge in-process with
//! `robowire-ros2`, the recorder's captures with `robowire-record`.
//!
//! Two binaries stay apart: `tests/dds_flood` (it floods every DDS port of the programs it starts
//! and measures their memory; run alone, it shares the two cores with no other test) and
//! `tests/physics/` (built only with the feature `mujoco`, by `cargo xtask mujoco`'s runs).

mod support;

mod bad_input;
mod cli;
mod decode_rtps;
mod devices;
mod doctor;
mod g1;
mod g1_cli;
mod go2;
mod live;
mod lowlevel;
mod policy;
mod record;
mod record_demo;
mod record_devices;
mod record_go2;
mod replay_device;
mod ros2;
mod zsl;
mod zsl1;
