//! kmc's integration tests against the chassis simulator on a pseudo-terminal, one binary with a
//! module per subject (`cargo test -p kmc --test it driver::` runs one).

mod client;
mod driver;
