//! Bounds-checked little-endian reading and writing.
//!
//! Every robowire wire format is little-endian. These helpers keep the offset arithmetic in one
//! place and turn a short buffer into `None` or [`BufferTooSmall`] instead of a panic.

use crate::BufferTooSmall;

/// The `N` bytes at `offset`, or `None` if `bytes` is too short.
#[inline]
pub fn array_at<const N: usize>(bytes: &[u8], offset: usize) -> Option<[u8; N]> {
    let end = offset.checked_add(N)?;
    bytes.get(offset..end)?.try_into().ok()
}

/// The little-endian `u16` at `offset`.
#[inline]
pub fn u16_at(bytes: &[u8], offset: usize) -> Option<u16> {
    array_at(bytes, offset).map(u16::from_le_bytes)
}

/// The little-endian `u32` at `offset`.
#[inline]
pub fn u32_at(bytes: &[u8], offset: usize) -> Option<u32> {
    array_at(bytes, offset).map(u32::from_le_bytes)
}

/// The little-endian IEEE-754 binary32 at `offset`, bit for bit (NaN payloads preserved).
#[inline]
pub fn f32_at(bytes: &[u8], offset: usize) -> Option<f32> {
    array_at(bytes, offset).map(f32::from_le_bytes)
}

/// Writes little-endian values one after the other into a caller's buffer.
///
/// ```
/// # use robowire_core::le::LeWriter;
/// let mut buf = [0u8; 5];
/// let mut w = LeWriter::new(&mut buf);
/// w.put_u8(0xB3).unwrap();
/// w.put_f32(1.25).unwrap();
/// assert_eq!(w.written(), 5);
/// assert_eq!(buf, [0xb3, 0x00, 0x00, 0xa0, 0x3f]);
/// assert!(LeWriter::new(&mut [0u8; 3]).put_f32(1.0).is_err());
/// ```
#[derive(Debug)]
pub struct LeWriter<'a> {
    buf: &'a mut [u8],
    pos: usize,
}

impl<'a> LeWriter<'a> {
    /// A writer at the start of `buf`.
    #[inline]
    pub fn new(buf: &'a mut [u8]) -> Self {
        Self { buf, pos: 0 }
    }

    /// Bytes written so far.
    #[inline]
    pub fn written(&self) -> usize {
        self.pos
    }

    /// Appends raw bytes.
    #[inline]
    pub fn put_bytes(&mut self, bytes: &[u8]) -> Result<(), BufferTooSmall> {
        let end = self.pos + bytes.len();
        let available = self.buf.len();
        let dst = self.buf.get_mut(self.pos..end).ok_or(BufferTooSmall { needed: end, available })?;
        dst.copy_from_slice(bytes);
        self.pos = end;
        Ok(())
    }

    /// Appends one byte.
    #[inline]
    pub fn put_u8(&mut self, value: u8) -> Result<(), BufferTooSmall> {
        self.put_bytes(&[value])
    }

    /// Appends a little-endian `u16`.
    #[inline]
    pub fn put_u16(&mut self, value: u16) -> Result<(), BufferTooSmall> {
        self.put_bytes(&value.to_le_bytes())
    }

    /// Appends a little-endian `u32`.
    #[inline]
    pub fn put_u32(&mut self, value: u32) -> Result<(), BufferTooSmall> {
        self.put_bytes(&value.to_le_bytes())
    }

    /// Appends a little-endian binary32, bit for bit.
    #[inline]
    pub fn put_f32(&mut self, value: f32) -> Result<(), BufferTooSmall> {
        self.put_bytes(&value.to_le_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_are_bounds_checked() {
        let bytes = [1, 2, 3, 4, 5];
        assert_eq!(u32_at(&bytes, 1), Some(0x0504_0302));
        assert_eq!(u32_at(&bytes, 2), None);
        assert_eq!(u16_at(&bytes, usize::MAX), None);
        assert_eq!(f32_at(&[0, 0, 0xa0, 0x3f], 0), Some(1.25));
    }

    #[test]
    fn writer_reports_what_it_needed() {
        let mut buf = [0u8; 4];
        let mut w = LeWriter::new(&mut buf);
        w.put_u16(0xBEEF).unwrap();
        assert_eq!(w.put_u32(1), Err(BufferTooSmall { needed: 6, available: 4 }));
        // A failed write leaves the position where it was.
        assert_eq!(w.written(), 2);
        w.put_u16(0x0102).unwrap();
        assert_eq!(buf, [0xEF, 0xBE, 0x02, 0x01]);
    }
}
