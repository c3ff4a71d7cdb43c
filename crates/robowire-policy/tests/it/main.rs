//! robowire-policy's integration tests: one binary.

mod config;
mod control;
mod model;
mod observation;
mod shipped;
