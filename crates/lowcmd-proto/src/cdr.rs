//! DDS CDR encoding (spec §6) by the rules, walking the field tables: each primitive aligned to
//! its size from the start of the body; nested structs add no alignment of their own; XCDR2
//! puts a 4-byte DHEADER (the array's byte length) in front of every array of structs.
//! Scalars are copied as little-endian bytes between the body and the struct image.

use crate::layout::{Shape, StructLayout};

/// A CDR representation with its 4-byte encapsulation header (little endian).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CdrEncoding {
    /// XCDR1, plain CDR_LE: `00 01 00 00`. What the vendor's publishers write.
    Xcdr1,
    /// XCDR2, CDR2_LE: `00 07 00 00`.
    Xcdr2,
}

impl CdrEncoding {
    /// The encapsulation header.
    pub const fn header(self) -> [u8; 4] {
        match self {
            Self::Xcdr1 => [0x00, 0x01, 0x00, 0x00],
            Self::Xcdr2 => [0x00, 0x07, 0x00, 0x00],
        }
    }

    /// The encoding a header announces.
    pub fn from_header(header: [u8; 4]) -> Option<Self> {
        [Self::Xcdr1, Self::Xcdr2].into_iter().find(|e| e.header() == header)
    }
}

/// What the walker does at each primitive and each XCDR2 array header.
pub(crate) trait Visitor {
    type Error;
    /// `size` bytes of primitives (one, or a whole array) at body offset `body` and image offset
    /// `image`.
    fn scalar(&mut self, body: usize, image: usize, size: usize) -> Result<(), Self::Error>;
    /// The DHEADER at body offset `at` of an array of structs that took `len` body bytes.
    fn array_header(&mut self, at: usize, len: u32, field: &'static str) -> Result<(), Self::Error>;
}

const fn align(pos: usize, to: usize) -> usize {
    pos.next_multiple_of(to)
}

/// Walks `layout` at image offset `base`, advancing the body position `pos`.
pub(crate) fn walk<V: Visitor>(
    layout: &StructLayout,
    base: usize,
    pos: &mut usize,
    xcdr2: bool,
    visitor: &mut V,
) -> Result<(), V::Error> {
    for field in layout.fields {
        match field.shape {
            Shape::Scalar(scalar) => {
                // Once the first element is aligned, an array's elements are contiguous in the
                // body as in the image: one copy for the whole array.
                let len = scalar.size() * field.len();
                *pos = align(*pos, scalar.size());
                visitor.scalar(*pos, base + field.offset, len)?;
                *pos += len;
            }
            Shape::Struct(sub) => {
                let header_at = (xcdr2 && field.count.is_some()).then(|| {
                    *pos = align(*pos, 4);
                    let at = *pos;
                    *pos += 4;
                    at
                });
                let start = *pos;
                for i in 0..field.len() {
                    walk(sub, base + field.offset + i * sub.size, pos, xcdr2, visitor)?;
                }
                if let Some(at) = header_at {
                    let len = u32::try_from(*pos - start).unwrap_or(u32::MAX);
                    visitor.array_header(at, len, field.name)?;
                }
            }
        }
    }
    Ok(())
}

/// Counts body bytes.
struct Length;

impl Visitor for Length {
    type Error = core::convert::Infallible;
    fn scalar(&mut self, _: usize, _: usize, _: usize) -> Result<(), Self::Error> {
        Ok(())
    }
    fn array_header(&mut self, _: usize, _: u32, _: &'static str) -> Result<(), Self::Error> {
        Ok(())
    }
}

/// Body length of `layout` in the given encoding (header not included).
pub(crate) fn body_len(layout: &StructLayout, encoding: CdrEncoding) -> usize {
    let mut pos = 0;
    let _ = walk(layout, 0, &mut pos, encoding == CdrEncoding::Xcdr2, &mut Length);
    pos
}

/// A pending copy that grows while the walk stays contiguous in both buffers.
#[derive(Default)]
struct Run {
    body: usize,
    image: usize,
    len: usize,
}

impl Run {
    /// Extends the run with `len` bytes at (`body`, `image`) if contiguous; else returns the
    /// finished run and starts a new one.
    fn push(&mut self, body: usize, image: usize, len: usize) -> Option<Run> {
        if self.len > 0 && body == self.body + self.len && image == self.image + self.len {
            self.len += len;
            None
        } else {
            Some(core::mem::replace(self, Run { body, image, len }))
        }
    }
}

/// Copies image scalars into a zeroed body in as few runs as the layout allows; fills in
/// DHEADERs. Call [`Encoder::finish`] after the walk.
pub(crate) struct Encoder<'a> {
    pub(crate) image: &'a [u8],
    pub(crate) body: &'a mut [u8],
    run: Run,
}

/// The walk left the buffers' bounds (a layout bug; never with the crate's own layouts).
#[derive(Debug)]
pub(crate) struct OutOfBounds;

impl<'a> Encoder<'a> {
    pub(crate) fn new(image: &'a [u8], body: &'a mut [u8]) -> Self {
        Self { image, body, run: Run::default() }
    }

    fn copy(&mut self, run: &Run) -> Result<(), OutOfBounds> {
        let src = self.image.get(run.image..run.image + run.len).ok_or(OutOfBounds)?;
        self.body.get_mut(run.body..run.body + run.len).ok_or(OutOfBounds)?.copy_from_slice(src);
        Ok(())
    }

    /// Copies the last pending run.
    pub(crate) fn finish(mut self) -> Result<(), OutOfBounds> {
        let run = core::mem::take(&mut self.run);
        self.copy(&run)
    }
}

impl Visitor for Encoder<'_> {
    type Error = OutOfBounds;
    fn scalar(&mut self, body: usize, image: usize, size: usize) -> Result<(), OutOfBounds> {
        match self.run.push(body, image, size) {
            Some(done) => self.copy(&done),
            None => Ok(()),
        }
    }
    fn array_header(&mut self, at: usize, len: u32, _: &'static str) -> Result<(), OutOfBounds> {
        self.body.get_mut(at..at + 4).ok_or(OutOfBounds)?.copy_from_slice(&len.to_le_bytes());
        Ok(())
    }
}

/// Copies body scalars into a zeroed image in as few runs as the layout allows; checks
/// DHEADERs. Call [`Decoder::finish`] after the walk.
pub(crate) struct Decoder<'a> {
    pub(crate) body: &'a [u8],
    pub(crate) image: &'a mut [u8],
    run: Run,
}

/// Why a body did not decode.
#[derive(Debug)]
pub(crate) enum BodyError {
    OutOfBounds,
    ArrayHeader { field: &'static str, expected: u32, found: u32 },
}

impl<'a> Decoder<'a> {
    pub(crate) fn new(body: &'a [u8], image: &'a mut [u8]) -> Self {
        Self { body, image, run: Run::default() }
    }

    fn copy(&mut self, run: &Run) -> Result<(), BodyError> {
        let src = self.body.get(run.body..run.body + run.len).ok_or(BodyError::OutOfBounds)?;
        self.image.get_mut(run.image..run.image + run.len).ok_or(BodyError::OutOfBounds)?.copy_from_slice(src);
        Ok(())
    }

    /// Copies the last pending run.
    pub(crate) fn finish(mut self) -> Result<(), BodyError> {
        let run = core::mem::take(&mut self.run);
        self.copy(&run)
    }
}

impl Visitor for Decoder<'_> {
    type Error = BodyError;
    fn scalar(&mut self, body: usize, image: usize, size: usize) -> Result<(), BodyError> {
        match self.run.push(body, image, size) {
            Some(done) => self.copy(&done),
            None => Ok(()),
        }
    }
    fn array_header(&mut self, at: usize, len: u32, field: &'static str) -> Result<(), BodyError> {
        let bytes = self.body.get(at..at + 4).ok_or(BodyError::OutOfBounds)?;
        let found = u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]);
        if found == len { Ok(()) } else { Err(BodyError::ArrayHeader { field, expected: len, found }) }
    }
}
