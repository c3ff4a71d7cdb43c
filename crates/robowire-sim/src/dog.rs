//! The ZSL-1 simulator under its old name, kept for one release: everything of
//! [`zsl1`](crate::zsl1), and its types under their `Dog*` names. New code uses
//! [`zsl1`](crate::zsl1); this module goes in the next release.

pub use crate::zsl1::*;

/// Renamed [`Zsl1Sim`].
#[deprecated(note = "renamed `robowire_sim::zsl1::Zsl1Sim`")]
pub type DogSim = Zsl1Sim;
/// Renamed [`Zsl1SimConfig`].
#[deprecated(note = "renamed `robowire_sim::zsl1::Zsl1SimConfig`")]
pub type DogSimConfig = Zsl1SimConfig;
/// Renamed [`Zsl1Snapshot`], whose field `dog` is now `robot`.
#[deprecated(note = "renamed `robowire_sim::zsl1::Zsl1Snapshot` (its field `dog` is now `robot`)")]
pub type DogSnapshot = Zsl1Snapshot;
/// Renamed [`Zsl1Model`].
#[deprecated(note = "renamed `robowire_sim::zsl1::Zsl1Model`")]
pub type DogModel = Zsl1Model;
/// Renamed [`Zsl1Fault`].
#[deprecated(note = "renamed `robowire_sim::zsl1::Zsl1Fault`")]
pub type DogFault = Zsl1Fault;
