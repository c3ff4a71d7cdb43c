//! The one place with `unsafe`: word-wise access to memory that another thread or process may
//! change at any time. Everything goes through raw pointers; no Rust reference to the memory is
//! ever created except the momentary `&Atomic*` of an atomic operation.

use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};

use crate::RegionError;

/// A base pointer and a length: memory shared with other threads or processes.
///
/// Invariants (upheld by the constructors' callers, [`crate::MappedRegion`] and
/// [`crate::HeapRegion`]): `base` is 8-byte aligned, `len` bytes from `base` stay valid and
/// writable for the lifetime of the `RawRegion`, and every access to them, by anyone, is an
/// atomic access of one fixed size per location (u32 words for data and flags, u64 for
/// designated u64 fields).
#[derive(Debug)]
pub(crate) struct RawRegion {
    base: *mut u8,
    len: usize,
}

// SAFETY: the region is only accessed through atomic operations (see the invariants above), which
// are safe to perform from any thread.
unsafe impl Send for RawRegion {}
// SAFETY: as for Send: shared access is all atomic.
unsafe impl Sync for RawRegion {}

impl RawRegion {
    /// # Safety
    ///
    /// `base` must be 8-byte aligned and valid for reads and writes of `len` bytes for as long
    /// as the returned value lives, and the memory must only ever be accessed atomically.
    pub(crate) unsafe fn new(base: *mut u8, len: usize) -> Self {
        Self { base, len }
    }

    pub(crate) fn len(&self) -> usize {
        self.len
    }

    /// Checks that `[offset, offset + len)` is inside the region and `align`-aligned.
    fn check(&self, offset: usize, len: usize, align: usize) -> Result<(), RegionError> {
        let end = offset.checked_add(len).ok_or(RegionError::OutOfBounds { offset, len, region_len: self.len })?;
        if end > self.len {
            return Err(RegionError::OutOfBounds { offset, len, region_len: self.len });
        }
        if !offset.is_multiple_of(align) || !len.is_multiple_of(align) {
            return Err(RegionError::Misaligned { offset, len, align });
        }
        Ok(())
    }

    fn word(&self, offset: usize) -> &AtomicU32 {
        // SAFETY: callers checked `offset + 4 <= len` and 4-byte alignment (base is 8-aligned), so
        // the pointer is in bounds, aligned, and valid for the region's lifetime, which bounds the
        // returned reference. All accesses to this word are 4-byte atomics (type invariant), as
        // `AtomicU32::from_ptr` requires.
        unsafe { AtomicU32::from_ptr(self.base.add(offset).cast::<u32>()) }
    }

    fn dword(&self, offset: usize) -> &AtomicU64 {
        // SAFETY: callers checked `offset + 8 <= len` and 8-byte alignment (base is 8-aligned);
        // all accesses to this location are 8-byte atomics (type invariant).
        unsafe { AtomicU64::from_ptr(self.base.add(offset).cast::<u64>()) }
    }

    /// Copies `dst.len()` bytes from `offset`, word by word with relaxed loads.
    pub(crate) fn read(&self, offset: usize, dst: &mut [u8]) -> Result<(), RegionError> {
        self.check(offset, dst.len(), 4)?;
        let (words, _) = dst.as_chunks_mut::<4>();
        for (i, chunk) in words.iter_mut().enumerate() {
            *chunk = self.word(offset + 4 * i).load(Ordering::Relaxed).to_le_bytes();
        }
        Ok(())
    }

    /// Copies `src` to `offset`, word by word with relaxed stores.
    pub(crate) fn write(&self, offset: usize, src: &[u8]) -> Result<(), RegionError> {
        self.check(offset, src.len(), 4)?;
        let (words, _) = src.as_chunks::<4>();
        for (i, chunk) in words.iter().enumerate() {
            self.word(offset + 4 * i).store(u32::from_le_bytes(*chunk), Ordering::Relaxed);
        }
        Ok(())
    }

    pub(crate) fn load_u32(&self, offset: usize, order: Ordering) -> Result<u32, RegionError> {
        self.check(offset, 4, 4)?;
        Ok(self.word(offset).load(order))
    }

    pub(crate) fn store_u32(&self, offset: usize, value: u32, order: Ordering) -> Result<(), RegionError> {
        self.check(offset, 4, 4)?;
        self.word(offset).store(value, order);
        Ok(())
    }

    pub(crate) fn load_u64(&self, offset: usize, order: Ordering) -> Result<u64, RegionError> {
        self.check(offset, 8, 8)?;
        Ok(self.dword(offset).load(order))
    }

    pub(crate) fn store_u64(&self, offset: usize, value: u64, order: Ordering) -> Result<(), RegionError> {
        self.check(offset, 8, 8)?;
        self.dword(offset).store(value, order);
        Ok(())
    }
}
