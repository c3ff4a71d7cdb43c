//! Parameter lists (SPDP/SEDP data, inline QoS): a checked view that iterates `(pid, value)`
//! without allocating, and a writer that emits one little-endian into a caller's buffer.

use super::{Endianness, WireError};
use robowire_core::BufferTooSmall;

/// One parameter: its id (the must-understand and vendor-specific bits included) and value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Parameter<'a> {
    /// The PID (see [`super::pid`]).
    pub pid: u16,
    /// The value's bytes (its length as the wire gives it, checked to fit).
    pub value: &'a [u8],
}

/// A parameter list checked up to and including its PID_SENTINEL: every parameter's length
/// fits, the sentinel is there. Iterating yields each parameter but PID_PAD and the sentinel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ParameterList<'a> {
    bytes: &'a [u8],
    endianness: Endianness,
}

impl<'a> ParameterList<'a> {
    /// Checks the list at the start of `bytes`; returns it and the bytes it takes (sentinel
    /// included), so that what follows (a DATA's payload) can be found.
    pub fn parse(bytes: &'a [u8], endianness: Endianness) -> Result<(Self, usize), WireError> {
        let _ = (bytes, endianness);
        todo!()
    }

    /// The byte order of the values.
    pub fn endianness(&self) -> Endianness {
        self.endianness
    }

    /// The list's bytes, sentinel included.
    pub fn as_bytes(&self) -> &'a [u8] {
        self.bytes
    }

    /// The parameters in order (PID_PAD and the sentinel left out).
    pub fn iter(&self) -> impl Iterator<Item = Parameter<'a>> + 'a {
        let _ = self.bytes;
        core::iter::empty()
    }

    /// The first parameter with `pid`.
    pub fn find(&self, pid: u16) -> Option<Parameter<'a>> {
        self.iter().find(|p| p.pid == pid)
    }
}

/// Emits a little-endian parameter list into a caller's buffer; `finish` writes the sentinel.
#[derive(Debug)]
pub struct ParameterWriter<'b> {
    buf: &'b mut [u8],
    len: usize,
}

impl<'b> ParameterWriter<'b> {
    /// A writer at the start of `buf`.
    pub fn new(buf: &'b mut [u8]) -> Self {
        Self { buf, len: 0 }
    }

    /// Appends `pid` with `value`, padded with zeros to a multiple of 4.
    pub fn push(&mut self, pid: u16, value: &[u8]) -> Result<(), BufferTooSmall> {
        let _ = (pid, value, &mut self.buf, self.len);
        todo!()
    }

    /// Appends `pid` with a value of `len` bytes that `fill` writes (padded to 4 after it).
    pub fn push_with(&mut self, pid: u16, len: usize, fill: impl FnOnce(&mut [u8])) -> Result<(), BufferTooSmall> {
        let _ = (pid, len, fill);
        todo!()
    }

    /// Writes PID_SENTINEL; returns the list's length in bytes.
    pub fn finish(self) -> Result<usize, BufferTooSmall> {
        todo!()
    }
}
