//! DDS CDR encodings (spec §6): each primitive aligned to its size from the start of the body;
//! nested structs add no alignment of their own; XCDR2 puts a 4-byte DHEADER (the array's byte
//! length) in front of every array of structs. The field tables are walked by these rules once,
//! at compile time, into copy plans ([`plan`](crate::plan)).

pub use robowire_core::cdr::CdrEncoding;
