//! The recorder's integration tests, one binary: captures written through taps and read back by
//! robowire's reader ([`capture`]), frames placed on channels ([`channels`]), and captures read
//! by an independent MCAP reader, the `mcap` Python package ([`independent_reader`],
//! `tests/interop/read_capture.py`, which the `robowire` crate's tests of its `--record`
//! captures run too). Links are the codecs' (`zsl-proto`'s descriptions) or toys: this crate
//! knows no device, nor do its tests.

mod capture;
mod channels;
mod independent_reader;
