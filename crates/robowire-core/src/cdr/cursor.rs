//! Cursors over a CDR body, little endian, alignment counted from the body's first byte (the
//! byte after the encapsulation header): what every codec with strings or sequences in its
//! messages writes and reads with, so that no codec carries its own.

use super::CdrEncoding;
use crate::BufferTooSmall;

/// Why a CDR body could not be read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum CdrError {
    /// The body ends before field `field`.
    #[error("the body ends in field {field}: {needed} bytes needed, {found} given")]
    Truncated {
        /// The field.
        field: &'static str,
        /// Bytes the field needs from the start of the body.
        needed: usize,
        /// The body's length.
        found: usize,
    },
    /// A string without its terminating NUL (or with a length of 0).
    #[error("string {field} is not NUL-terminated")]
    NoNul {
        /// The field.
        field: &'static str,
    },
    /// A string that is not UTF-8.
    #[error("string {field} is not UTF-8")]
    NotUtf8 {
        /// The field.
        field: &'static str,
    },
    /// A boolean byte other than 0 or 1.
    #[error("boolean {field} is {value}, not 0 or 1")]
    Bool {
        /// The field.
        field: &'static str,
        /// The byte.
        value: u8,
    },
    /// A sequence whose count cannot fit in what is left of the body.
    #[error("sequence {field} claims {count} elements, the body has {left} bytes left")]
    Count {
        /// The field.
        field: &'static str,
        /// The count read.
        count: usize,
        /// Bytes left in the body.
        left: usize,
    },
    /// A representation the message's codec does not read.
    #[error("{0:?} is not read for this type")]
    Encoding(CdrEncoding),
    /// A bounded string (`string<N>`) longer than its bound.
    #[error("string {field} is {len} bytes long, longer than its bound {bound}")]
    Bound {
        /// The field.
        field: &'static str,
        /// Its length in bytes, without the NUL.
        len: usize,
        /// The bound, bytes.
        bound: usize,
    },
    /// Bytes left after the last field beyond alignment padding.
    #[error("{extra} bytes after the last field")]
    Trailing {
        /// Bytes left.
        extra: usize,
    },
}

/// The largest alignment of a primitive: 8 in XCDR1, 4 in XCDR2.
const fn max_align(encoding: CdrEncoding) -> usize {
    match encoding {
        CdrEncoding::Xcdr1 => 8,
        CdrEncoding::Xcdr2 => 4,
    }
}

/// Writes a CDR body into a caller's buffer. Writing past the end is not an error until
/// [`finish`](Self::finish), which reports the length needed; [`CdrWriter::measure`] computes a
/// body's length with no buffer at all.
///
/// ```
/// use robowire_core::cdr::{CdrEncoding, CdrReader, CdrWriter};
///
/// let mut out = [0u8; 32];
/// let mut w = CdrWriter::new(CdrEncoding::Xcdr1, &mut out);
/// w.u8(7);
/// w.f64(1.5); // aligned to 8: seven bytes of padding
/// w.string("odom");
/// let n = w.finish().unwrap();
/// assert_eq!(n, 25);
///
/// let mut r = CdrReader::new(CdrEncoding::Xcdr1, &out[..n]);
/// assert_eq!((r.u8("a").unwrap(), r.f64("b").unwrap(), r.string("c").unwrap()), (7, 1.5, "odom"));
/// r.finish().unwrap();
/// ```
#[derive(Debug)]
pub struct CdrWriter<'a> {
    out: &'a mut [u8],
    pos: usize,
    max_align: usize,
}

impl<'a> CdrWriter<'a> {
    /// A writer at the start of `out`.
    pub fn new(encoding: CdrEncoding, out: &'a mut [u8]) -> Self {
        Self { out, pos: 0, max_align: max_align(encoding) }
    }

    /// A writer that only counts: [`position`](Self::position) is then the body's length.
    pub fn measure(encoding: CdrEncoding) -> CdrWriter<'static> {
        CdrWriter { out: &mut [], pos: 0, max_align: max_align(encoding) }
    }

    /// Bytes written so far, padding included.
    pub fn position(&self) -> usize {
        self.pos
    }

    /// `bytes` at the next multiple of `align` (capped at the encoding's largest alignment),
    /// zeroing the padding.
    pub fn bytes(&mut self, align: usize, bytes: &[u8]) {
        let start = self.pos.next_multiple_of(align.min(self.max_align));
        let end = start + bytes.len();
        if let Some(dst) = self.out.get_mut(self.pos..end) {
            dst[..start - self.pos].fill(0);
            dst[start - self.pos..].copy_from_slice(bytes);
        }
        self.pos = end;
    }

    /// An `octet` / `uint8`.
    pub fn u8(&mut self, value: u8) {
        self.bytes(1, &[value]);
    }

    /// A `boolean`: one byte, 0 or 1.
    pub fn bool(&mut self, value: bool) {
        self.u8(u8::from(value));
    }

    /// A `uint32`.
    pub fn u32(&mut self, value: u32) {
        self.bytes(4, &value.to_le_bytes());
    }

    /// An `int32`.
    pub fn i32(&mut self, value: i32) {
        self.bytes(4, &value.to_le_bytes());
    }

    /// A `uint64`.
    pub fn u64(&mut self, value: u64) {
        self.bytes(8, &value.to_le_bytes());
    }

    /// An `int64`.
    pub fn i64(&mut self, value: i64) {
        self.bytes(8, &value.to_le_bytes());
    }

    /// A `float`.
    pub fn f32(&mut self, value: f32) {
        self.bytes(4, &value.to_le_bytes());
    }

    /// A `double`.
    pub fn f64(&mut self, value: f64) {
        self.bytes(8, &value.to_le_bytes());
    }

    /// A `string`: its length with the NUL (`uint32`), the bytes, the NUL.
    pub fn string(&mut self, s: &str) {
        self.count(s.len() + 1);
        self.bytes(1, s.as_bytes());
        self.u8(0);
    }

    /// A sequence's element count (`uint32`); the elements follow.
    pub fn count(&mut self, count: usize) {
        self.u32(count as u32);
    }

    /// A `sequence<octet>`.
    pub fn octets(&mut self, bytes: &[u8]) {
        self.count(bytes.len());
        self.bytes(1, bytes);
    }

    /// A `sequence<double>`.
    pub fn f64s(&mut self, values: &[f64]) {
        self.count(values.len());
        values.iter().for_each(|&v| self.f64(v));
    }

    /// A `sequence<float>`.
    pub fn f32s(&mut self, values: &[f32]) {
        self.count(values.len());
        values.iter().for_each(|&v| self.f32(v));
    }

    /// The body's length, or how much `out` lacked.
    pub fn finish(self) -> Result<usize, BufferTooSmall> {
        let available = self.out.len();
        if self.pos <= available { Ok(self.pos) } else { Err(BufferTooSmall { needed: self.pos, available }) }
    }
}

/// Reads a CDR body; every read names its field for the error.
#[derive(Debug, Clone)]
pub struct CdrReader<'a> {
    body: &'a [u8],
    pos: usize,
    max_align: usize,
}

/// Bytes after the last field taken as padding (a writer may pad the body to 4 or 8).
const MAX_TRAILING_PADDING: usize = 7;

impl<'a> CdrReader<'a> {
    /// A reader at the start of `body`, in `encoding`'s alignment.
    pub fn new(encoding: CdrEncoding, body: &'a [u8]) -> Self {
        Self { body, pos: 0, max_align: max_align(encoding) }
    }

    /// Bytes read so far, padding included.
    pub fn position(&self) -> usize {
        self.pos
    }

    /// Bytes left after the cursor.
    pub fn left(&self) -> usize {
        self.body.len().saturating_sub(self.pos)
    }

    /// `len` bytes at the next multiple of `align`.
    pub fn take(&mut self, field: &'static str, align: usize, len: usize) -> Result<&'a [u8], CdrError> {
        let start = self.pos.next_multiple_of(align.min(self.max_align));
        let end = start.saturating_add(len);
        let bytes =
            self.body.get(start..end).ok_or(CdrError::Truncated { field, needed: end, found: self.body.len() })?;
        self.pos = end;
        Ok(bytes)
    }

    /// `N` bytes aligned to `N`.
    pub fn array<const N: usize>(&mut self, field: &'static str) -> Result<[u8; N], CdrError> {
        let bytes = self.take(field, N, N)?;
        let mut out = [0u8; N];
        out.copy_from_slice(bytes);
        Ok(out)
    }

    /// An `octet` / `uint8`.
    pub fn u8(&mut self, field: &'static str) -> Result<u8, CdrError> {
        self.array::<1>(field).map(|[b]| b)
    }

    /// A `boolean`; any byte but 0 or 1 is an error.
    pub fn bool(&mut self, field: &'static str) -> Result<bool, CdrError> {
        match self.u8(field)? {
            0 => Ok(false),
            1 => Ok(true),
            value => Err(CdrError::Bool { field, value }),
        }
    }

    /// A `uint32`.
    pub fn u32(&mut self, field: &'static str) -> Result<u32, CdrError> {
        self.array(field).map(u32::from_le_bytes)
    }

    /// An `int32`.
    pub fn i32(&mut self, field: &'static str) -> Result<i32, CdrError> {
        self.array(field).map(i32::from_le_bytes)
    }

    /// A `uint64`.
    pub fn u64(&mut self, field: &'static str) -> Result<u64, CdrError> {
        self.array(field).map(u64::from_le_bytes)
    }

    /// An `int64`.
    pub fn i64(&mut self, field: &'static str) -> Result<i64, CdrError> {
        self.array(field).map(i64::from_le_bytes)
    }

    /// A `float`.
    pub fn f32(&mut self, field: &'static str) -> Result<f32, CdrError> {
        self.array(field).map(f32::from_le_bytes)
    }

    /// A `double`.
    pub fn f64(&mut self, field: &'static str) -> Result<f64, CdrError> {
        self.array(field).map(f64::from_le_bytes)
    }

    /// A `string`: UTF-8, NUL-terminated.
    pub fn string(&mut self, field: &'static str) -> Result<&'a str, CdrError> {
        let len = self.u32(field)? as usize;
        let bytes = self.take(field, 1, len)?;
        let (&nul, text) = bytes.split_last().ok_or(CdrError::NoNul { field })?;
        if nul != 0 {
            return Err(CdrError::NoNul { field });
        }
        core::str::from_utf8(text).map_err(|_| CdrError::NotUtf8 { field })
    }

    /// A `string<bound>`: as [`string`](Self::string), at most `bound` bytes before the NUL.
    pub fn bounded_string(&mut self, field: &'static str, bound: usize) -> Result<&'a str, CdrError> {
        let s = self.string(field)?;
        if s.len() > bound { Err(CdrError::Bound { field, len: s.len(), bound }) } else { Ok(s) }
    }

    /// A sequence's element count, checked against what is left: each element takes at least
    /// `min_element_len` bytes (so that a corrupt count never sizes an allocation).
    pub fn count(&mut self, field: &'static str, min_element_len: usize) -> Result<usize, CdrError> {
        let count = self.u32(field)? as usize;
        let left = self.left();
        if count.saturating_mul(min_element_len.max(1)) > left {
            return Err(CdrError::Count { field, count, left });
        }
        Ok(count)
    }

    /// A `sequence<octet>`.
    pub fn octets(&mut self, field: &'static str) -> Result<&'a [u8], CdrError> {
        let len = self.count(field, 1)?;
        self.take(field, 1, len)
    }

    /// The end of the body: at most 7 bytes of padding may follow the last field.
    pub fn finish(self) -> Result<(), CdrError> {
        let extra = self.left();
        if extra <= MAX_TRAILING_PADDING { Ok(()) } else { Err(CdrError::Trailing { extra }) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn alignment_follows_the_encoding() {
        let mut out = [0xAAu8; 16];
        let mut w = CdrWriter::new(CdrEncoding::Xcdr1, &mut out);
        w.u8(1);
        w.f64(2.0);
        assert_eq!(w.finish(), Ok(16));
        assert_eq!(out[1..8], [0; 7], "padding is zeroed");
        let mut w = CdrWriter::measure(CdrEncoding::Xcdr2);
        w.u8(1);
        w.f64(2.0);
        assert_eq!(w.position(), 12, "XCDR2 aligns 8-byte primitives to 4");
    }

    #[test]
    fn a_short_buffer_reports_what_was_needed() {
        let mut out = [0u8; 4];
        let mut w = CdrWriter::new(CdrEncoding::Xcdr1, &mut out);
        w.string("base_link");
        assert_eq!(w.finish(), Err(BufferTooSmall { needed: 14, available: 4 }));
    }

    #[test]
    fn bad_bodies_are_typed_errors() {
        let mut r = CdrReader::new(CdrEncoding::Xcdr1, &[0xFF, 0xFF, 0xFF, 0x7F]);
        assert!(matches!(r.count("name", 5), Err(CdrError::Count { field: "name", .. })));
        let mut r = CdrReader::new(CdrEncoding::Xcdr1, &[2, 0, 0, 0, b'a', b'b']);
        assert_eq!(r.string("frame_id"), Err(CdrError::NoNul { field: "frame_id" }));
        let mut r = CdrReader::new(CdrEncoding::Xcdr1, &[2]);
        assert_eq!(r.bool("present"), Err(CdrError::Bool { field: "present", value: 2 }));
        let mut r = CdrReader::new(CdrEncoding::Xcdr1, &[1, 2, 3]);
        assert_eq!(r.f64("x"), Err(CdrError::Truncated { field: "x", needed: 8, found: 3 }));
        assert_eq!(CdrReader::new(CdrEncoding::Xcdr1, &[0; 8]).finish(), Err(CdrError::Trailing { extra: 8 }));
        let abc = [4, 0, 0, 0, b'a', b'b', b'c', 0];
        assert_eq!(CdrReader::new(CdrEncoding::Xcdr1, &abc).bounded_string("ns", 3), Ok("abc"));
        let bound = CdrReader::new(CdrEncoding::Xcdr1, &abc).bounded_string("ns", 2);
        assert_eq!(bound, Err(CdrError::Bound { field: "ns", len: 3, bound: 2 }));
    }
}
