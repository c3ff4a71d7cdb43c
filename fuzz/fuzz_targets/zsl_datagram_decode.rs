//! Every ZSL-1 datagram decoder (strict and lenient) on arbitrary bytes: no panic, exact
//! re-encoding, lenient updates touch exactly the prefix given.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| zsl_proto::decode_roundtrip::datagram_decode(data));
