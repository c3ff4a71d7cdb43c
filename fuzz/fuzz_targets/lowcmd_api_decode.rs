//! Unitree service bodies (`Request_` or `Response_`, selected by byte 0): a value or a typed
//! error, and a decoded body re-encodes to one that decodes to the same value.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| unitree_proto::decode_roundtrip::api_decode(data));
