#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod client;
mod error;
mod following;
pub mod g1;
pub mod go2;
pub mod hg;
mod options;
mod receive;
pub mod services;
mod stream;
pub mod trajectory;

pub use client::{JointCommand, LowLevel, LowLevelStats};
pub use error::UnitreeError;
pub use following::Following;
pub use options::{FIRST_STATE_TIMEOUT, LowLevelOptions, STATE_TIMEOUT};
pub use robowire_core::schedule::Connection;
pub use robowire_dds::ParticipantOptions;
pub use robowire_rt::device::{Device, Stamped};
pub use robowire_rt::{Placement, RtError};
pub use unitree_proto::robot::{CommandError, GO2_JOINT_LIMITS, GO2_JOINT_NAMES, Go2, Hg, JointLimits, Robot};
pub use unitree_proto::stream::MotionState;
pub use unitree_proto::{HgLowCmd, HgLowState, LowCmd, LowState, MotorCmd};

/// The DDS receive path of every Unitree message, for the fuzz target (not public API). Byte 0
/// selects the type (`% 6`: Go2 `LowCmd_`, Go2 `LowState_`, HG `LowCmd_`, HG `LowState_`,
/// `Request_`, `Response_`); the rest is a sample's serialized payload, checked by
/// `robowire_dds::fuzz_check_sample` (the reader agrees with the codec, a message read writes and
/// reads back the same) and, for the low-level messages, the CRC: a message is read only with a
/// CRC that matches (any CRC when built with `cfg(fuzzing)`), a checksum failure only with one
/// that does not. Panics otherwise.
#[doc(hidden)]
pub fn fuzz_receive(bytes: &[u8]) {
    use unitree_proto::api::{ApiRequest, ApiResponse};
    let Some((&selector, payload)) = bytes.split_first() else { return };
    match selector % 6 {
        0 => check_message::<LowCmd>(payload),
        1 => check_message::<LowState>(payload),
        2 => check_message::<HgLowCmd>(payload),
        3 => check_message::<HgLowState>(payload),
        4 => drop(robowire_dds::fuzz_check_sample::<ApiRequest>(payload)),
        _ => drop(robowire_dds::fuzz_check_sample::<ApiResponse>(payload)),
    }
}

fn check_message<M>(payload: &[u8])
where
    M: unitree_proto::Message + robowire_core::cdr::CdrType + std::fmt::Debug + Eq,
{
    let Some(sample) = robowire_dds::fuzz_check_sample::<M>(payload) else { return };
    // The codec sees what the reader decodes: the payload without the padding its options announce.
    match (sample, M::decode_cdr_unverified(robowire_dds::unpadded(payload))) {
        (Ok(message), Ok((unverified, _))) => {
            assert!(unverified.crc.is_ok() || cfg!(fuzzing), "a message with a wrong CRC was read");
            assert_eq!(message, unverified.message);
        }
        (Err(checksum), Ok((unverified, _))) => assert!(checksum && !unverified.crc.is_ok()),
        (Err(checksum), Err(_)) => assert!(!checksum, "a payload the codec refuses read as a checksum failure"),
        (Ok(message), Err(e)) => panic!("{message:?} read from a payload the codec refuses: {e:?}"),
    }
}
