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
        let read_header = move |h: &[u8]| {
            let (p, l) = ([h[0], h[1]], [h[2], h[3]]);
            match endianness {
                Endianness::Big => (u16::from_be_bytes(p), u16::from_be_bytes(l)),
                Endianness::Little => (u16::from_le_bytes(p), u16::from_le_bytes(l)),
            }
        };
        let mut pos = 0usize;
        loop {
            let header = bytes.get(pos..pos + 4).ok_or(WireError::NotRtps)?;
            let (pid, len) = read_header(header);
            if pid == super::pid::SENTINEL {
                let end = pos + 4;
                return Ok((Self { bytes: &bytes[..end], endianness }, end));
            }
            let end = pos + 4 + usize::from(len);
            if end > bytes.len() {
                return Err(WireError::NotRtps);
            }
            pos = end;
        }
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
        let (bytes, endianness) = (self.bytes, self.endianness);
        let read_header = move |h: &[u8]| {
            let (p, l) = ([h[0], h[1]], [h[2], h[3]]);
            match endianness {
                Endianness::Big => (u16::from_be_bytes(p), u16::from_be_bytes(l)),
                Endianness::Little => (u16::from_le_bytes(p), u16::from_le_bytes(l)),
            }
        };
        let mut pos = 0usize;
        core::iter::from_fn(move || {
            loop {
                let (pid, len) = read_header(bytes.get(pos..pos + 4)?);
                if pid == super::pid::SENTINEL {
                    return None;
                }
                let value = bytes.get(pos + 4..pos + 4 + usize::from(len))?;
                pos += 4 + usize::from(len);
                if pid != super::pid::PAD {
                    return Some(Parameter { pid, value });
                }
            }
        })
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
        self.push_with(pid, value.len(), |dst| dst.copy_from_slice(value))
    }

    /// Appends `pid` with a value of `len` bytes that `fill` writes (padded to 4 after it).
    pub fn push_with(&mut self, pid: u16, len: usize, fill: impl FnOnce(&mut [u8])) -> Result<(), BufferTooSmall> {
        let padded = len.saturating_add(3) & !3;
        let available = self.buf.len();
        let too_small = BufferTooSmall { needed: self.len.saturating_add(4).saturating_add(padded), available };
        let wire_len = u16::try_from(padded).map_err(|_| too_small)?;
        let end = self.len + 4 + padded;
        let dst = self.buf.get_mut(self.len..end).ok_or(too_small)?;
        dst[..2].copy_from_slice(&pid.to_le_bytes());
        dst[2..4].copy_from_slice(&wire_len.to_le_bytes());
        fill(&mut dst[4..4 + len]);
        dst[4 + len..].fill(0);
        self.len = end;
        Ok(())
    }

    /// Writes PID_SENTINEL; returns the list's length in bytes.
    pub fn finish(self) -> Result<usize, BufferTooSmall> {
        let end = self.len + 4;
        let available = self.buf.len();
        let dst = self.buf.get_mut(self.len..end).ok_or(BufferTooSmall { needed: end, available })?;
        dst[..2].copy_from_slice(&super::pid::SENTINEL.to_le_bytes());
        dst[2..].fill(0);
        Ok(end)
    }
}
