//! A slot holds the largest frame of every protocol robowire records.

use robowire_tap::SLOT_BYTES;
use unitree_proto::{CdrEncoding, HgLowState, LowState, Message};
use zsl_proto::udp::HighLevelState;

#[test]
fn the_largest_frames_fit_a_slot() {
    let largest = [
        ("HG LowState_, XCDR1", HgLowState::cdr_len(CdrEncoding::Xcdr1)),
        ("HG LowState_, XCDR2", HgLowState::cdr_len(CdrEncoding::Xcdr2)),
        ("Go2 LowState_, XCDR2", LowState::cdr_len(CdrEncoding::Xcdr2)),
        ("ZSL-1 HighLevel state", HighLevelState::LEN),
        ("KMC frame", kmc_proto::MAX_FRAME_LEN),
    ];
    for (what, len) in largest {
        assert!(len <= SLOT_BYTES, "{what}: {len} bytes");
    }
    assert_eq!(HgLowState::cdr_len(CdrEncoding::Xcdr2), 2100, "the size SLOT_BYTES documents");
}
