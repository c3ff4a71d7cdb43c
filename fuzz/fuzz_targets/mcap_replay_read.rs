//! `robowire replay`'s reader on arbitrary bytes, with the ZSL-1 link descriptions the seeds
//! were recorded with: frames or a typed error, never a panic, and the summary agrees with the
//! frames.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| robowire_record::fuzz_read(data, &zsl_proto::description::DESCRIPTIONS));
