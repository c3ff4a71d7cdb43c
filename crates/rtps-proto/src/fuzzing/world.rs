//! The world every fuzz run of a participant lives in: the two participants' GUID prefixes,
//! the topic they share, the start time and the payload cap.

use crate::{GuidPrefix, Time};

/// The fuzzed participant's GUID prefix.
pub const LOCAL_PREFIX: GuidPrefix = GuidPrefix([0x01; 12]);
/// The prefix of the fuzzer's peer (every templated datagram comes from it).
pub const PEER_PREFIX: GuidPrefix = GuidPrefix([0x0f; 12]);
/// The topic both participants write and read.
pub const TOPIC: &str = "rt/fuzz";
/// Its type name.
pub const TYPE_NAME: &str = "robowire::msg::dds_::Fuzz_";
/// When both participants start.
pub(super) const T0: Time = Time::from_nanos(1_000_000_000);
/// Bytes of a generated payload at most (a DATA's, a DATA_FRAG's, a local write's).
pub(super) const MAX_PAYLOAD: usize = 16 * 1024;
