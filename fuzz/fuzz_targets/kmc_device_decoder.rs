//! Device-side KMC decoder (host → chassis frames): chunked vs whole decoding, exact
//! re-encoding, byte accounting. Input: chunk-size byte, then the stream.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| kmc_proto::stream_consistency::host_frame_stream(data));
