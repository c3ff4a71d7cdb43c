//! A region on the heap: the same behaviour as a mapping, for threads of one process, for
//! tests, and for Miri.

use crate::raw::RawRegion;

/// A zero-initialised region on the heap.
#[derive(Debug)]
pub struct HeapRegion {
    raw: RawRegion,
}

impl HeapRegion {
    /// A zeroed region of `len` bytes (rounded up to a multiple of 8 internally; `len()` is
    /// what was asked for).
    pub fn new(len: usize) -> Self {
        Self { raw: RawRegion::heap(len) }
    }

    pub(crate) fn raw(&self) -> &RawRegion {
        &self.raw
    }
}
