//! The access trait, [`SharedRegion`], and the two protocols written once against it: the
//! consumer-flag handshake of a [`FlaggedBlock`] and the versioned read of a
//! [`VersionedRecord`].

use std::sync::atomic::{Ordering, fence};

use robowire_core::shm::{FlaggedBlock, VersionedRecord};

use crate::raw::RawRegion;

/// Why an access to a region was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum RegionError {
    /// `[offset, offset + len)` does not fit the region.
    #[error("access of {len} bytes at offset {offset} is outside the {region_len}-byte region")]
    OutOfBounds {
        /// Start of the access.
        offset: usize,
        /// Length of the access.
        len: usize,
        /// Length of the region.
        region_len: usize,
    },
    /// Offset or length not a multiple of the access width.
    #[error("access of {len} bytes at offset {offset} is not {align}-byte aligned")]
    Misaligned {
        /// Start of the access.
        offset: usize,
        /// Length of the access.
        len: usize,
        /// Required alignment.
        align: usize,
    },
    /// A buffer does not have the length of the block or record it is for.
    #[error("a {expected}-byte block was given a {found}-byte buffer")]
    Length {
        /// The block's length.
        expected: usize,
        /// The buffer's length.
        found: usize,
    },
    /// A record version of 0 was given; 0 means "no record" to readers.
    #[error("a versioned record cannot be published with version 0")]
    ZeroVersion,
}

/// A record [`SharedRegion::read_versioned`] accepted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct VersionedRead {
    /// The record's version.
    pub version: u64,
    /// Attempts it took (1: the first copy was consistent).
    pub attempts: u32,
}

/// Why [`SharedRegion::read_versioned`] returned no record.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum VersionedReadError {
    /// The version is 0: nothing was ever published (or the writer is stuck mid-update).
    #[error("no record published")]
    Empty,
    /// The version changed during every attempt: the writer kept updating the record.
    #[error("the record changed during each of {attempts} read attempts")]
    Torn {
        /// Attempts made.
        attempts: u32,
    },
    /// The access itself was refused.
    #[error(transparent)]
    Region(#[from] RegionError),
}

/// Memory shared with other threads or processes, accessed only by copies and atomics.
///
/// Block copies go word by word (4 bytes, relaxed atomic loads and stores: the same machine
/// instructions as a volatile copy, but free of data races under the Rust memory model, so that
/// Miri can check the heap implementation). Bytes are copied as they are in memory (native
/// endianness). Offsets and lengths are multiples of 4; the u64 accessors need multiples of 8.
/// A location must always be accessed with the same width. Publication follows release/acquire:
/// write the data, then store a flag with [`Ordering::Release`]; load the flag with
/// [`Ordering::Acquire`], then read the data.
///
/// The provided methods are the two protocols robowire uses on shared memory, written once:
/// [`publish`](Self::publish) / [`take`](Self::take) (a [`FlaggedBlock`]'s consumer-flag
/// handshake) and [`write_versioned`](Self::write_versioned) /
/// [`read_versioned`](Self::read_versioned) (a [`VersionedRecord`]). They never sleep and never
/// read a clock.
pub trait SharedRegion {
    /// Length in bytes.
    fn len(&self) -> usize;
    /// `true` for an empty region.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Copies `dst.len()` bytes starting at `offset` out of the region.
    fn read(&self, offset: usize, dst: &mut [u8]) -> Result<(), RegionError>;
    /// Copies `src` into the region at `offset`.
    fn write(&self, offset: usize, src: &[u8]) -> Result<(), RegionError>;
    /// Atomic load of the u32 at `offset`.
    fn load_u32(&self, offset: usize, order: Ordering) -> Result<u32, RegionError>;
    /// Atomic store of the u32 at `offset`.
    fn store_u32(&self, offset: usize, value: u32, order: Ordering) -> Result<(), RegionError>;
    /// Atomic load of the u64 at `offset`.
    fn load_u64(&self, offset: usize, order: Ordering) -> Result<u64, RegionError>;
    /// Atomic store of the u64 at `offset`.
    fn store_u64(&self, offset: usize, value: u64, order: Ordering) -> Result<(), RegionError>;
    /// A memory fence of `order` (a model checker substitutes its own).
    fn fence(&self, order: Ordering) {
        fence(order);
    }

    /// Checks that a layout fits this region (call once, after attaching).
    fn check_fits(&self, end: usize) -> Result<(), RegionError> {
        if end <= self.len() {
            Ok(())
        } else {
            Err(RegionError::OutOfBounds { offset: 0, len: end, region_len: self.len() })
        }
    }

    /// Producer side of a flagged block: writes `data` into the block, then raises the flag of
    /// every consumer in `consumers` (release). All of `consumers` describe the same block.
    fn publish(&self, consumers: &[FlaggedBlock], data: &[u8]) -> Result<(), RegionError> {
        let Some(block) = consumers.first() else { return Ok(()) };
        if data.len() != block.len {
            return Err(RegionError::Length { expected: block.len, found: data.len() });
        }
        self.write(block.offset, data)?;
        for consumer in consumers {
            self.store_u32(consumer.flag, 1, Ordering::Release)?;
        }
        Ok(())
    }

    /// Whether `block`'s consumer flag is raised (a fresh block waits), without taking it.
    fn is_raised(&self, block: &FlaggedBlock) -> Result<bool, RegionError> {
        Ok(self.load_u32(block.flag, Ordering::Acquire)? != 0)
    }

    /// Consumer side of a flagged block: if the flag is raised (acquire), copies the block into
    /// `dst`, lowers the flag (release) and returns `true`; else leaves `dst` alone and returns
    /// `false`.
    fn take(&self, block: &FlaggedBlock, dst: &mut [u8]) -> Result<bool, RegionError> {
        if dst.len() != block.len {
            return Err(RegionError::Length { expected: block.len, found: dst.len() });
        }
        if self.load_u32(block.flag, Ordering::Acquire)? == 0 {
            return Ok(false);
        }
        self.read(block.offset, dst)?;
        self.store_u32(block.flag, 0, Ordering::Release)?;
        Ok(true)
    }

    /// Writer side of a versioned record: the version becomes 0 while `data` is written, then
    /// `version` (release). A reader never accepts the half-written record.
    fn write_versioned(&self, record: &VersionedRecord, version: u64, data: &[u8]) -> Result<(), RegionError> {
        if version == 0 {
            return Err(RegionError::ZeroVersion);
        }
        if data.len() != record.data_len() {
            return Err(RegionError::Length { expected: record.data_len(), found: data.len() });
        }
        self.store_u64(record.offset, 0, Ordering::Relaxed)?;
        self.fence(Ordering::Release);
        self.write(record.data_offset(), data)?;
        self.store_u64(record.offset, version, Ordering::Release)
    }

    /// Reader side of a versioned record: reads the version (acquire), copies the data into
    /// `dst`, reads the version again; accepts the copy if the version was non-zero and did not
    /// change, else retries, up to `max_attempts` times. Returns the version and the attempts.
    ///
    /// Against a writer that follows [`write_versioned`](Self::write_versioned) this never
    /// yields a torn record. Against one that writes version and data in another order, a tear
    /// that leaves the version unchanged cannot be seen.
    fn read_versioned(
        &self,
        record: &VersionedRecord,
        dst: &mut [u8],
        max_attempts: u32,
    ) -> Result<VersionedRead, VersionedReadError> {
        if dst.len() != record.data_len() {
            return Err(RegionError::Length { expected: record.data_len(), found: dst.len() }.into());
        }
        let mut saw_record = false;
        for attempt in 1..=max_attempts.max(1) {
            let before = self.load_u64(record.offset, Ordering::Acquire)?;
            if before != 0 {
                saw_record = true;
                self.read(record.data_offset(), dst)?;
                self.fence(Ordering::Acquire);
                if self.load_u64(record.offset, Ordering::Relaxed)? == before {
                    return Ok(VersionedRead { version: before, attempts: attempt });
                }
            }
            std::hint::spin_loop();
        }
        Err(if saw_record {
            VersionedReadError::Torn { attempts: max_attempts.max(1) }
        } else {
            VersionedReadError::Empty
        })
    }
}

impl SharedRegion for RawRegion {
    fn len(&self) -> usize {
        RawRegion::len(self)
    }

    fn read(&self, offset: usize, dst: &mut [u8]) -> Result<(), RegionError> {
        let words = self.words(offset, dst.len())?;
        let (chunks, _) = dst.as_chunks_mut::<4>();
        for (i, chunk) in chunks.iter_mut().enumerate() {
            if let Some(word) = words.get(i) {
                *chunk = word.load(Ordering::Relaxed).to_ne_bytes();
            }
        }
        Ok(())
    }

    fn write(&self, offset: usize, src: &[u8]) -> Result<(), RegionError> {
        let words = self.words(offset, src.len())?;
        let (chunks, _) = src.as_chunks::<4>();
        for (i, chunk) in chunks.iter().enumerate() {
            if let Some(word) = words.get(i) {
                word.store(u32::from_ne_bytes(*chunk), Ordering::Relaxed);
            }
        }
        Ok(())
    }

    fn load_u32(&self, offset: usize, order: Ordering) -> Result<u32, RegionError> {
        let words = self.words(offset, 4)?;
        Ok(words.get(0).map_or(0, |w| w.load(order)))
    }

    fn store_u32(&self, offset: usize, value: u32, order: Ordering) -> Result<(), RegionError> {
        if let Some(word) = self.words(offset, 4)?.get(0) {
            word.store(value, order);
        }
        Ok(())
    }

    fn load_u64(&self, offset: usize, order: Ordering) -> Result<u64, RegionError> {
        Ok(self.dword(offset)?.get().load(order))
    }

    fn store_u64(&self, offset: usize, value: u64, order: Ordering) -> Result<(), RegionError> {
        self.dword(offset)?.get().store(value, order);
        Ok(())
    }
}

/// Shares a region between owners (a client thread and a daemon thread, say).
macro_rules! delegate {
    ($(impl$(<$($g:ident),*>)? for $ty:ty => |$s:ident| $inner:expr;)*) => {$(
        impl$(<$($g: SharedRegion + ?Sized),*>)? SharedRegion for $ty {
            fn len(&self) -> usize {
                let $s = self;
                $inner.len()
            }
            fn read(&self, offset: usize, dst: &mut [u8]) -> Result<(), RegionError> {
                let $s = self;
                $inner.read(offset, dst)
            }
            fn write(&self, offset: usize, src: &[u8]) -> Result<(), RegionError> {
                let $s = self;
                $inner.write(offset, src)
            }
            fn load_u32(&self, offset: usize, order: Ordering) -> Result<u32, RegionError> {
                let $s = self;
                $inner.load_u32(offset, order)
            }
            fn store_u32(&self, offset: usize, value: u32, order: Ordering) -> Result<(), RegionError> {
                let $s = self;
                $inner.store_u32(offset, value, order)
            }
            fn load_u64(&self, offset: usize, order: Ordering) -> Result<u64, RegionError> {
                let $s = self;
                $inner.load_u64(offset, order)
            }
            fn store_u64(&self, offset: usize, value: u64, order: Ordering) -> Result<(), RegionError> {
                let $s = self;
                $inner.store_u64(offset, value, order)
            }
            fn fence(&self, order: Ordering) {
                let $s = self;
                $inner.fence(order)
            }
        }
    )*};
}

delegate! {
    impl<R> for std::sync::Arc<R> => |s| (**s);
    impl<R> for &R => |s| (**s);
    impl for crate::HeapRegion => |s| s.raw();
    impl for crate::MappedRegion => |s| s.raw();
}
