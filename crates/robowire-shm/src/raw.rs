//! The one place with `unsafe`: word-wise access to memory that another thread or process may
//! change at any time, and the two ways such memory comes to exist (a heap allocation, a
//! mapping). Everything goes through raw pointers; no Rust reference to the memory is ever
//! created except the momentary `&Atomic*` of an atomic operation.
//!
//! Soundness rests on one type: a [`Words`] or [`DWord`] can only be made by
//! [`RawRegion::words`] / [`RawRegion::dword`] after the range was checked against the region
//! (in bounds, aligned), and it borrows the region, so it cannot outlive the memory.

use std::marker::PhantomData;
use std::ptr::NonNull;
use std::sync::Arc;
use std::sync::atomic::{AtomicU32, AtomicU64};

use memmap2::MmapRaw;

use crate::RegionError;

/// What keeps the memory alive.
#[derive(Debug)]
enum Backing {
    /// Atomics on the heap. An `Arc`, not a `Box`: moving a `Box` asserts unique access and
    /// would invalidate the base pointer (Miri's Stacked Borrows says so); the `Arc`'s
    /// allocation stays put when the `RawRegion` moves.
    Heap(#[allow(dead_code)] Arc<[AtomicU64]>),
    /// A shared mapping.
    Mapped(#[allow(dead_code)] MmapRaw),
}

/// A base pointer, a length and what owns the memory: memory shared with other threads or
/// processes.
///
/// Invariants, established by the two constructors and relied on by every access: `base` is
/// 8-byte aligned; `len` bytes from `base` are valid for reads and writes for as long as the
/// `RawRegion` lives (the backing is owned here and never replaced); every access to them from
/// robowire is an atomic access of one fixed size per location (u32 words for data and flags,
/// u64 for designated u64 fields). Other processes sharing a mapping are expected to follow the
/// same rule (the protocols robowire speaks use aligned 4- and 8-byte fields).
#[derive(Debug)]
pub(crate) struct RawRegion {
    base: NonNull<u8>,
    len: usize,
    _backing: Backing,
}

// SAFETY: the region is only accessed through atomic operations (see the invariants above), which
// are safe to perform from any thread; the backing (an `Arc` of atomics, a mapping) may be moved
// to and dropped on any thread.
unsafe impl Send for RawRegion {}
// SAFETY: as for Send: shared access is all atomic.
unsafe impl Sync for RawRegion {}

impl RawRegion {
    /// A zeroed region of `len` bytes on the heap (rounded up to whole u64s internally).
    pub(crate) fn heap(len: usize) -> Self {
        let storage: Arc<[AtomicU64]> = (0..len.div_ceil(8)).map(|_| AtomicU64::new(0)).collect();
        // The slice is 8-byte aligned and at least `len` bytes long. It is made of atomics, so
        // writing through a pointer derived from a shared reference to it is allowed.
        let base = NonNull::new(storage.as_ptr().cast::<u8>().cast_mut()).unwrap_or(NonNull::dangling());
        Self { base, len, _backing: Backing::Heap(storage) }
    }

    /// The whole of a shared mapping.
    pub(crate) fn mapped(map: MmapRaw) -> Self {
        // A mapping is page-aligned, `map.len()` bytes long, readable and writable.
        let base = NonNull::new(map.as_mut_ptr()).unwrap_or(NonNull::dangling());
        Self { base, len: map.len(), _backing: Backing::Mapped(map) }
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

    /// The u32 words of `[offset, offset + len)`, checked once.
    pub(crate) fn words(&self, offset: usize, len: usize) -> Result<Words<'_>, RegionError> {
        self.check(offset, len, 4)?;
        // In bounds (checked), so the offset pointer stays inside the allocation; base is
        // 8-aligned and offset a multiple of 4, so it is 4-aligned.
        let first = self.base.as_ptr().wrapping_add(offset).cast::<AtomicU32>();
        Ok(Words { first: NonNull::new(first).unwrap_or(NonNull::dangling()), count: len / 4, _region: PhantomData })
    }

    /// The u64 at `offset`, checked.
    pub(crate) fn dword(&self, offset: usize) -> Result<DWord<'_>, RegionError> {
        self.check(offset, 8, 8)?;
        let at = self.base.as_ptr().wrapping_add(offset).cast::<AtomicU64>();
        Ok(DWord { at: NonNull::new(at).unwrap_or(NonNull::dangling()), _region: PhantomData })
    }
}

/// `count` u32 words starting at `first`, proven in bounds and 4-aligned in a region that lives
/// for `'r`. Only [`RawRegion::words`] makes one.
pub(crate) struct Words<'r> {
    first: NonNull<AtomicU32>,
    count: usize,
    _region: PhantomData<&'r RawRegion>,
}

impl<'r> Words<'r> {
    /// Word `i`, or `None` past the end.
    pub(crate) fn get(&self, i: usize) -> Option<&'r AtomicU32> {
        if i >= self.count {
            return None;
        }
        // SAFETY: `i < count` and the whole range of `count` words was checked to lie inside the
        // region, 4-aligned (the type's invariant), so the pointer is in bounds and aligned; the
        // region outlives `'r`, which bounds the reference. Every access to this word is a
        // 4-byte atomic (RawRegion's invariant), as `AtomicU32::from_ptr` requires.
        Some(unsafe { AtomicU32::from_ptr(self.first.as_ptr().add(i).cast::<u32>()) })
    }
}

/// A u64 proven in bounds and 8-aligned in a region that lives for `'r`. Only
/// [`RawRegion::dword`] makes one.
pub(crate) struct DWord<'r> {
    at: NonNull<AtomicU64>,
    _region: PhantomData<&'r RawRegion>,
}

impl<'r> DWord<'r> {
    /// The atomic.
    pub(crate) fn get(&self) -> &'r AtomicU64 {
        // SAFETY: checked in bounds and 8-aligned when made (the type's invariant); the region
        // outlives `'r`; every access to this location is an 8-byte atomic (RawRegion's
        // invariant), as `AtomicU64::from_ptr` requires.
        unsafe { AtomicU64::from_ptr(self.at.as_ptr().cast::<u64>()) }
    }
}
