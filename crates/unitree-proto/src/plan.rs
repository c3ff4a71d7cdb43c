//! Precomputed CDR copy plans: the walk of the field tables by the CDR rules done once, at compile
//! time, and flattened into a few block copies between the struct image and the CDR body.
//!
//! Two scalars whose body offset and image offset differ by the same amount belong to one
//! copy, with whatever lies between them: in a sealed image that is zeroed C padding, in a body
//! CDR alignment padding. The Go2 `LowCmd_` in XCDR1 is three copies (spec §6.4:
//! `img[0..22] ++ img[24..25] ++ 00 ++ img[28..812]`, the pad byte riding along with the third);
//! in XCDR2, two copies and the array's DHEADER. Decoding copies the same runs the other way, then
//! zeroes the image's padding (a body may carry anything in its alignment bytes).

use robowire_core::BufferTooSmall;

use crate::cdr::CdrEncoding;
use crate::error::DecodeError;
use crate::layout::{Shape, StructLayout};

/// One block copy: `len` bytes between body offset `body` and image offset `image`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CopyRun {
    /// Offset in the CDR body (after the 4-byte encapsulation header).
    pub body: usize,
    /// Offset in the struct image.
    pub image: usize,
    /// Bytes.
    pub len: usize,
}

/// An XCDR2 DHEADER: at body offset `at`, the byte length `len` of the array `field`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ArrayHeader {
    /// Body offset of the header.
    pub at: usize,
    /// The array's body length, the header's value.
    pub len: u32,
    /// The array's IDL name.
    pub field: &'static str,
}

/// How one message type maps to one CDR encoding.
#[derive(Debug, Clone, Copy)]
pub struct CdrPlan {
    /// The copies, in body order.
    pub runs: &'static [CopyRun],
    /// XCDR2's array headers (none in XCDR1).
    pub headers: &'static [ArrayHeader],
    /// Body length, bytes (the 4-byte encapsulation header not included).
    pub body_len: usize,
}

/// The walk's state: the body position, the run being grown, what was emitted.
struct Walk<const R: usize, const H: usize> {
    pos: usize,
    current: Option<CopyRun>,
    runs: [CopyRun; R],
    run_count: usize,
    headers: [ArrayHeader; H],
    header_count: usize,
}

const EMPTY_RUN: CopyRun = CopyRun { body: 0, image: 0, len: 0 };
const EMPTY_HEADER: ArrayHeader = ArrayHeader { at: 0, len: 0, field: "" };

impl<const R: usize, const H: usize> Walk<R, H> {
    const fn new() -> Self {
        Self { pos: 0, current: None, runs: [EMPTY_RUN; R], run_count: 0, headers: [EMPTY_HEADER; H], header_count: 0 }
    }

    /// Closes the run being grown (counted always, stored when there is room).
    const fn close(&mut self) {
        if let Some(run) = self.current {
            if self.run_count < R {
                self.runs[self.run_count] = run;
            }
            self.run_count += 1;
            self.current = None;
        }
    }

    /// `len` scalar bytes at body `body`, image `image`: extends the current run if the offsets
    /// keep their difference, else starts a new one.
    const fn scalar(&mut self, body: usize, image: usize, len: usize) {
        if let Some(run) = &mut self.current
            && body >= run.body + run.len
            && image >= run.image + run.len
            && body - run.body == image - run.image
        {
            run.len = body + len - run.body;
            return;
        }
        self.close();
        self.current = Some(CopyRun { body, image, len });
    }

    const fn header(&mut self, at: usize, len: usize, field: &'static str) {
        if self.header_count < H {
            self.headers[self.header_count] = ArrayHeader { at, len: len as u32, field };
        }
        self.header_count += 1;
    }

    /// The CDR rules (spec §6.2) over `layout` at image offset `base`.
    const fn walk(&mut self, layout: &StructLayout, base: usize, xcdr2: bool) {
        let mut i = 0;
        while i < layout.fields.len() {
            let field = &layout.fields[i];
            match field.shape {
                Shape::Scalar(scalar) => {
                    self.pos = self.pos.next_multiple_of(scalar.size());
                    let len = scalar.size() * field.len();
                    self.scalar(self.pos, base + field.offset, len);
                    self.pos += len;
                }
                Shape::Pad => {}
                Shape::Struct(sub) => {
                    let array_header = xcdr2 && field.count.is_some();
                    let mut header_at = 0;
                    if array_header {
                        self.close();
                        self.pos = self.pos.next_multiple_of(4);
                        header_at = self.pos;
                        self.pos += 4;
                    }
                    let start = self.pos;
                    let mut k = 0;
                    while k < field.len() {
                        self.walk(sub, base + field.offset + k * sub.size, xcdr2);
                        k += 1;
                    }
                    if array_header {
                        self.header(header_at, self.pos - start, field.name);
                    }
                }
            }
            i += 1;
        }
    }

    const fn run(layout: &StructLayout, xcdr2: bool) -> Self {
        let mut walk = Self::new();
        walk.walk(layout, 0, xcdr2);
        walk.close();
        walk
    }
}

/// Runs of `layout` in one encoding (`xcdr2`): the `R` of [`plan_runs`].
pub const fn run_count(layout: &StructLayout, xcdr2: bool) -> usize {
    Walk::<0, 0>::run(layout, xcdr2).run_count
}

/// Array headers of `layout` in one encoding: the `H` of [`plan_headers`].
pub const fn header_count(layout: &StructLayout, xcdr2: bool) -> usize {
    Walk::<0, 0>::run(layout, xcdr2).header_count
}

/// Body length of `layout` in one encoding.
pub const fn plan_body_len(layout: &StructLayout, xcdr2: bool) -> usize {
    Walk::<0, 0>::run(layout, xcdr2).pos
}

/// The `R` runs of `layout` in one encoding.
pub const fn plan_runs<const R: usize>(layout: &StructLayout, xcdr2: bool) -> [CopyRun; R] {
    Walk::<R, 0>::run(layout, xcdr2).runs
}

/// The `H` array headers of `layout` in one encoding.
pub const fn plan_headers<const H: usize>(layout: &StructLayout, xcdr2: bool) -> [ArrayHeader; H] {
    Walk::<0, H>::run(layout, xcdr2).headers
}

/// The [`CdrPlan`] of the layout constant `$layout` in XCDR1 (`false`) or XCDR2 (`true`), built at
/// compile time.
macro_rules! cdr_plan {
    ($layout:expr, $xcdr2:literal) => {
        $crate::plan::CdrPlan {
            runs: &$crate::plan::plan_runs::<{ $crate::plan::run_count(&$layout, $xcdr2) }>(&$layout, $xcdr2),
            headers: &$crate::plan::plan_headers::<{ $crate::plan::header_count(&$layout, $xcdr2) }>(&$layout, $xcdr2),
            body_len: $crate::plan::plan_body_len(&$layout, $xcdr2),
        }
    };
}
pub(crate) use cdr_plan;

/// Why a body does not fit a plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum PlanError {
    /// A DHEADER disagrees with its array.
    ArrayHeader { field: &'static str, expected: u32, found: u32 },
}

impl CdrPlan {
    /// Image → body. `body` is exactly `body_len` long; `image` is a sealed image.
    #[inline]
    pub(crate) fn encode(&self, image: &[u8], body: &mut [u8]) {
        // Bytes between runs are CDR alignment padding or DHEADERs: zero, then headers.
        let mut end = 0;
        for run in self.runs {
            body[end..run.body].fill(0);
            body[run.body..run.body + run.len].copy_from_slice(&image[run.image..run.image + run.len]);
            end = run.body + run.len;
        }
        body[end..].fill(0);
        for header in self.headers {
            body[header.at..header.at + 4].copy_from_slice(&header.len.to_le_bytes());
        }
    }

    /// Image → body at the start of `out`: [`encode`](Self::encode) after checking room; the
    /// body's length.
    #[inline]
    pub(crate) fn encode_into(&self, image: &[u8], out: &mut [u8]) -> Result<usize, BufferTooSmall> {
        let (needed, available) = (self.body_len, out.len());
        let dst = out.get_mut(..needed).ok_or(BufferTooSmall { needed, available })?;
        self.encode(image, dst);
        Ok(needed)
    }

    /// Body (in `encoding`, this plan's) → image: [`decode`](Self::decode) after checking the
    /// body's length, with the crate's typed errors. The caller zeroes the image's padding.
    #[inline]
    pub(crate) fn decode_from<M>(
        &self,
        encoding: CdrEncoding,
        body: &[u8],
        image: &mut [u8],
    ) -> Result<(), DecodeError<M>> {
        if body.len() != self.body_len {
            return Err(DecodeError::CdrLength { encoding, expected: self.body_len, found: body.len() });
        }
        self.decode(body, image).map_err(|e| match e {
            PlanError::ArrayHeader { field, expected, found } => DecodeError::ArrayHeader { field, expected, found },
        })
    }

    /// Body → image (then zero the image's padding). `body` is exactly `body_len` long.
    #[inline]
    pub(crate) fn decode(&self, body: &[u8], image: &mut [u8]) -> Result<(), PlanError> {
        for header in self.headers {
            let bytes = &body[header.at..header.at + 4];
            let found = u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]);
            if found != header.len {
                return Err(PlanError::ArrayHeader { field: header.field, expected: header.len, found });
            }
        }
        for run in self.runs {
            image[run.image..run.image + run.len].copy_from_slice(&body[run.body..run.body + run.len]);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Message;
    use crate::{HgLowCmd, HgLowState, LowCmd, LowState};

    #[test]
    fn the_go2_plans_are_the_spec_relations() {
        // Spec §6.4.
        assert_eq!(
            LowCmd::XCDR1.runs,
            [
                CopyRun { body: 0, image: 0, len: 22 },
                CopyRun { body: 22, image: 24, len: 1 },
                CopyRun { body: 24, image: 28, len: 784 }
            ]
        );
        assert_eq!(LowCmd::XCDR1.body_len, 808);
        assert!(LowCmd::XCDR1.headers.is_empty());
        assert_eq!(
            LowCmd::XCDR2.runs,
            [CopyRun { body: 0, image: 0, len: 22 }, CopyRun { body: 28, image: 24, len: 788 }]
        );
        assert_eq!(LowCmd::XCDR2.headers, [ArrayHeader { at: 24, len: 720, field: "motor_cmd" }]);
        assert_eq!(LowCmd::XCDR2.body_len, 816);
        assert_eq!(
            LowState::XCDR1.runs,
            [
                CopyRun { body: 0, image: 0, len: 77 },
                CopyRun { body: 77, image: 80, len: 1 },
                CopyRun { body: 80, image: 84, len: 1096 }
            ]
        );
        assert_eq!(LowState::XCDR2.headers, [ArrayHeader { at: 80, len: 960, field: "motor_state" }]);
        assert_eq!((LowState::XCDR1.body_len, LowState::XCDR2.body_len), (1176, 1184));
        assert_eq!((HgLowCmd::XCDR1.body_len, HgLowState::XCDR1.body_len), (1000, 2088));
    }
}
