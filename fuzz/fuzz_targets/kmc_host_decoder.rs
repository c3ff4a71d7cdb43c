//! Host-side KMC decoder (chassis → host frames): chunked vs whole decoding, exact re-encoding,
//! byte accounting. Input: chunk-size byte, then the stream.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| kmc_proto::stream_consistency::chassis_frame_stream(data));
