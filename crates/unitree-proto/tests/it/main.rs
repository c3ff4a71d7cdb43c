//! unitree-proto's integration tests, one binary with a module per subject (`cargo test -p
//! unitree-proto --test it messages::` runs one): layouts, CRC and CDR round trips, field access by
//! IDL path, the G1's command checks, the command streams on a fake clock, the links described to
//! a recorder, and the codecs against Unitree's IDL classes (CycloneDDS' Python binding) and
//! Foxglove's OMG IDL reader (both gated like every interop test).

mod golden;
#[path = "../../benches/oracle.rs"]
mod oracle;

mod description;
mod fields;
mod g1;
mod hg_bms_state;
mod messages;
mod omgidl;
mod sport_mode_state;
mod stream;
