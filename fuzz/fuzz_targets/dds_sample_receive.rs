//! A received DDS payload (encapsulation header, body; Go2 and HG LowCmd/LowState, service
//! requests and answers, selected by byte 0) through rustdds and robowire's reader adapter:
//! what the codec decodes, CRC check included, or a counted failure; written back, read back.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| unitree::fuzz_receive(data));
