//! The HG robots (G1, H1-2) at the family's level: [`LowLevel<Hg>`](crate::LowLevel) with the HG
//! messages, without a robot's own rules (the G1's are [`crate::g1`]'s).

pub use unitree_proto::robot::Hg;
pub use unitree_proto::{HgLowCmd, HgLowState, HgMotorCmd};

/// An HG robot's low-level client.
pub type LowLevel = crate::LowLevel<Hg>;
