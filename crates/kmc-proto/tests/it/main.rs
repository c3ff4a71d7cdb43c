//! kmc-proto's integration tests, one binary with a module per subject (`cargo test -p kmc-proto
//! --test it roundtrip::` runs one): golden frames described to a recorder, typed errors, garbage
//! between frames, round trips, the command stream on a fake clock.

mod strategies;

mod description;
mod errors;
mod garbage;
mod roundtrip;
mod stream;
