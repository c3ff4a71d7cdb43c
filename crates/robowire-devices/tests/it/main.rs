//! robowire-devices' integration tests, one binary with a module per subject (`cargo test -p
//! robowire-devices --test it conformance::` runs one): the conformance suite over every `sim:`
//! kind, the G1 by address, and with the feature `mujoco` the physics simulators by address
//! (`physics`, run by `cargo xtask test` as `--features mujoco --test it -- physics::`).

#[cfg(all(feature = "kmc", feature = "zsl1", feature = "unitree"))]
mod conformance;
mod g1;
#[cfg(feature = "mujoco")]
mod physics;
