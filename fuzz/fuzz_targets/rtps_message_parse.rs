//! RTPS datagrams on arbitrary bytes: no panic in the wire layer; every submessage parsed is
//! emitted and parsed again to the same repr (`rtps_proto::fuzzing::parse_all`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| rtps_proto::fuzzing::parse_all(data));
