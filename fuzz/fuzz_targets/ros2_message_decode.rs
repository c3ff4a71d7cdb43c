//! Every ROS 2 message (selected by byte 0) on an arbitrary body: a value or a typed error,
//! XCDR2 refused, and a decoded body re-encodes to one that decodes to the same value.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| ros2_proto::decode_roundtrip::message_decode(data));
