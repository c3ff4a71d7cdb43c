//! Parameter lists (SPDP/SEDP data, inline QoS): a checked view that iterates `(pid, value)`
//! without allocating, and a writer that emits one little-endian into a caller's buffer.

use super::{Endianness, WireError, pid};
use robowire_core::BufferTooSmall;

/// The `u16` at `at` in byte order `e`.
pub(crate) fn u16_in(bytes: &[u8], at: usize, e: Endianness) -> Option<u16> {
    let b = robowire_core::le::array_at::<2>(bytes, at)?;
    Some(match e {
        Endianness::Little => u16::from_le_bytes(b),
        Endianness::Big => u16::from_be_bytes(b),
    })
}

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
        let mut at = 0usize;
        loop {
            let (Some(pid), Some(length)) = (u16_in(bytes, at, endianness), u16_in(bytes, at + 2, endianness)) else {
                return Err(WireError::ParameterListUnterminated);
            };
            let available = bytes.len().saturating_sub(at + 4);
            if usize::from(length) > available {
                return Err(WireError::ParameterLength { pid, length, available });
            }
            at += 4 + usize::from(length);
            if pid == pid::SENTINEL {
                let list = bytes.get(..at).ok_or(WireError::ParameterListUnterminated)?;
                return Ok((Self { bytes: list, endianness }, at));
            }
        }
    }

    /// A little-endian list that takes all of `bytes` (what [`ParameterWriter`] wrote); bytes
    /// after the sentinel are refused as a list without one.
    pub fn little_endian(bytes: &'a [u8]) -> Result<Self, WireError> {
        match Self::parse(bytes, Endianness::Little)? {
            (list, used) if used == bytes.len() => Ok(list),
            _ => Err(WireError::ParameterListUnterminated),
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
        Parameters { bytes: self.bytes, at: 0, endianness: self.endianness }
    }

    /// The first parameter with `pid`.
    pub fn find(&self, pid: u16) -> Option<Parameter<'a>> {
        self.iter().find(|p| p.pid == pid)
    }
}

/// Walks a checked list; stops at the sentinel (or, never on a checked list, at a short value).
struct Parameters<'a> {
    bytes: &'a [u8],
    at: usize,
    endianness: Endianness,
}

impl<'a> Iterator for Parameters<'a> {
    type Item = Parameter<'a>;
    fn next(&mut self) -> Option<Parameter<'a>> {
        loop {
            let pid = u16_in(self.bytes, self.at, self.endianness)?;
            let length = usize::from(u16_in(self.bytes, self.at + 2, self.endianness)?);
            let start = self.at + 4;
            if pid == pid::SENTINEL {
                self.at = self.bytes.len();
                return None;
            }
            let value = self.bytes.get(start..start + length)?;
            self.at = start + length;
            if pid != pid::PAD {
                return Some(Parameter { pid, value });
            }
        }
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
    ///
    /// A value longer than 65532 bytes (its padded length would not fit the 16-bit length) is
    /// refused as `BufferTooSmall` too. Nothing is written on an error.
    pub fn push(&mut self, pid: u16, value: &[u8]) -> Result<(), BufferTooSmall> {
        self.push_with(pid, value.len(), |dst| dst.copy_from_slice(value))
    }

    /// Appends `pid` with a value of `len` bytes that `fill` writes (padded to 4 after it).
    /// `fill` gets exactly `len` bytes; nothing is written (and `fill` not called) on an error.
    pub fn push_with(&mut self, pid: u16, len: usize, fill: impl FnOnce(&mut [u8])) -> Result<(), BufferTooSmall> {
        let padded = len.checked_add(3).map(|n| n & !3);
        let end = padded.and_then(|p| self.len.checked_add(4 + p));
        let available = self.buf.len();
        let (Some(padded), Some(end)) = (padded, end) else {
            return Err(BufferTooSmall { needed: usize::MAX, available });
        };
        let Ok(length) = u16::try_from(padded) else {
            return Err(BufferTooSmall { needed: end, available });
        };
        let Some(dst) = self.buf.get_mut(self.len..end) else {
            return Err(BufferTooSmall { needed: end, available });
        };
        let (header, value) = dst.split_at_mut(4);
        header[..2].copy_from_slice(&pid.to_le_bytes());
        header[2..].copy_from_slice(&length.to_le_bytes());
        let (filled, padding) = value.split_at_mut(len);
        fill(filled);
        padding.fill(0);
        self.len = end;
        Ok(())
    }

    /// Bytes written so far (no sentinel yet).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Nothing written yet.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Writes PID_SENTINEL; returns the list's length in bytes.
    pub fn finish(self) -> Result<usize, BufferTooSmall> {
        let end = self.len + 4;
        let available = self.buf.len();
        let dst = self.buf.get_mut(self.len..end).ok_or(BufferTooSmall { needed: end, available })?;
        dst.copy_from_slice(&[0x01, 0x00, 0x00, 0x00]);
        Ok(end)
    }
}
