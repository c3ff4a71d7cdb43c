//! rtps-proto's integration tests without an allocator of their own, one binary with a module per
//! subject (`cargo test -p rtps-proto --test it world::` runs one): the wire layer on hand-built
//! bytes and its properties, discovery data, participants in an in-memory world on a fake clock,
//! a participant table crowded by forged announcements.
//!
//! Two binaries stay apart, as each counts the allocations of its process with a global allocator
//! of its own: `tests/alloc.rs` (the steady state allocates nothing) and `tests/hostile.rs`
//! (hostile datagrams allocate within bounds). `tests/pair/` is shared by them and this one.

#[allow(dead_code)] // each test binary uses a part of it
#[path = "../pair/mod.rs"]
mod pair;

mod crowded;
mod discovery;
mod wire;
mod wire_props;
mod world;
