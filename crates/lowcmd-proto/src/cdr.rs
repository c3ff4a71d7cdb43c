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
            // C padding has no place in CDR.
            Shape::Pad => {}
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

/// Which way a [`Transcoder`] copies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Direction {
    /// Struct image → CDR body; DHEADERs are written.
    Encode,
    /// CDR body → struct image; DHEADERs are checked.
    Decode,
}

/// Why a walk over a body failed.
#[derive(Debug)]
pub(crate) enum BodyError {
    /// The walk left a buffer (a short body; never with the crate's own layouts when encoding).
    OutOfBounds,
    /// An XCDR2 DHEADER disagrees with its array.
    ArrayHeader { field: &'static str, expected: u32, found: u32 },
}

/// Copies scalars between a struct image and a CDR body, in as few runs as the layout allows.
/// Call [`Transcoder::finish`] after the walk to copy the last run.
pub(crate) struct Transcoder<'a> {
    from: &'a [u8],
    to: &'a mut [u8],
    direction: Direction,
    run: Run,
}

impl<'a> Transcoder<'a> {
    /// Image → zeroed body.
    pub(crate) fn encoder(image: &'a [u8], body: &'a mut [u8]) -> Self {
        Self { from: image, to: body, direction: Direction::Encode, run: Run::default() }
    }

    /// Body → zeroed image.
    pub(crate) fn decoder(body: &'a [u8], image: &'a mut [u8]) -> Self {
        Self { from: body, to: image, direction: Direction::Decode, run: Run::default() }
    }

    fn copy(&mut self, run: &Run) -> Result<(), BodyError> {
        let (src, dst) = match self.direction {
            Direction::Encode => (run.image, run.body),
            Direction::Decode => (run.body, run.image),
        };
        let bytes = self.from.get(src..src + run.len).ok_or(BodyError::OutOfBounds)?;
        self.to.get_mut(dst..dst + run.len).ok_or(BodyError::OutOfBounds)?.copy_from_slice(bytes);
        Ok(())
    }

    /// Copies the last pending run.
    pub(crate) fn finish(mut self) -> Result<(), BodyError> {
        let run = core::mem::take(&mut self.run);
        self.copy(&run)
    }
}

impl Visitor for Transcoder<'_> {
    type Error = BodyError;
    fn scalar(&mut self, body: usize, image: usize, size: usize) -> Result<(), BodyError> {
        match self.run.push(body, image, size) {
            Some(done) => self.copy(&done),
            None => Ok(()),
        }
    }
    fn array_header(&mut self, at: usize, len: u32, field: &'static str) -> Result<(), BodyError> {
        match self.direction {
            Direction::Encode => {
                self.to.get_mut(at..at + 4).ok_or(BodyError::OutOfBounds)?.copy_from_slice(&len.to_le_bytes());
                Ok(())
            }
            Direction::Decode => {
                let bytes = self.from.get(at..at + 4).ok_or(BodyError::OutOfBounds)?;
                let found = u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]);
                if found == len { Ok(()) } else { Err(BodyError::ArrayHeader { field, expected: len, found }) }
            }
        }
    }
}
