//! Unitree CDR decoding (XCDR1/XCDR2, Go2 and HG, selected by byte 0), CRC check bypassed
//! under `cfg(fuzzing)`: re-encoding and verified re-decoding must agree.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| unitree_proto::decode_roundtrip::cdr_decode(data));
