//! zsl-proto's integration tests, one binary with a module per subject (`cargo test -p zsl-proto
//! --test it stream::` runs one): datagrams' round trips and errors, the links described to a
//! recorder, the client's command stream on a fake clock.

mod datagrams;
mod description;
mod stream;
