#![doc = include_str!("../README.md")]
#![deny(unsafe_code)]

#[allow(unsafe_code)]
mod raw;

use std::io;
use std::os::fd::OwnedFd;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use memmap2::{MmapOptions, MmapRaw};
use rustix::fs::Mode;
use rustix::shm;

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
}

/// Memory shared with other threads or processes, accessed only by copies and atomics.
///
/// Block copies go word by word (4 bytes, relaxed atomic loads and stores: the same machine
/// instructions as a volatile copy, but free of data races under the Rust memory model, so that
/// Miri can check the heap implementation). Offsets and lengths are multiples of 4; the u64
/// accessors need multiples of 8. A location must always be accessed with the same width.
/// Publication follows release/acquire: write the data, then store a flag with
/// [`Ordering::Release`]; load the flag with [`Ordering::Acquire`], then read the data.
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
}

/// Shares a region between owners (a client thread and a daemon thread, say).
macro_rules! delegate_to_deref {
    ($($ty:ty),*) => {$(
        impl<R: SharedRegion + ?Sized> SharedRegion for $ty {
            fn len(&self) -> usize {
                (**self).len()
            }
            fn read(&self, offset: usize, dst: &mut [u8]) -> Result<(), RegionError> {
                (**self).read(offset, dst)
            }
            fn write(&self, offset: usize, src: &[u8]) -> Result<(), RegionError> {
                (**self).write(offset, src)
            }
            fn load_u32(&self, offset: usize, order: Ordering) -> Result<u32, RegionError> {
                (**self).load_u32(offset, order)
            }
            fn store_u32(&self, offset: usize, value: u32, order: Ordering) -> Result<(), RegionError> {
                (**self).store_u32(offset, value, order)
            }
            fn load_u64(&self, offset: usize, order: Ordering) -> Result<u64, RegionError> {
                (**self).load_u64(offset, order)
            }
            fn store_u64(&self, offset: usize, value: u64, order: Ordering) -> Result<(), RegionError> {
                (**self).store_u64(offset, value, order)
            }
        }
    )*};
}

delegate_to_deref!(Arc<R>, &R);

macro_rules! delegate_to_raw {
    ($ty:ty) => {
        impl SharedRegion for $ty {
            fn len(&self) -> usize {
                self.raw.len()
            }
            fn read(&self, offset: usize, dst: &mut [u8]) -> Result<(), RegionError> {
                self.raw.read(offset, dst)
            }
            fn write(&self, offset: usize, src: &[u8]) -> Result<(), RegionError> {
                self.raw.write(offset, src)
            }
            fn load_u32(&self, offset: usize, order: Ordering) -> Result<u32, RegionError> {
                self.raw.load_u32(offset, order)
            }
            fn store_u32(&self, offset: usize, value: u32, order: Ordering) -> Result<(), RegionError> {
                self.raw.store_u32(offset, value, order)
            }
            fn load_u64(&self, offset: usize, order: Ordering) -> Result<u64, RegionError> {
                self.raw.load_u64(offset, order)
            }
            fn store_u64(&self, offset: usize, value: u64, order: Ordering) -> Result<(), RegionError> {
                self.raw.store_u64(offset, value, order)
            }
        }
    };
}

/// A region on the heap, zero-initialised: the same behaviour as a mapping, for threads of one
/// process, for tests, and for Miri.
#[derive(Debug)]
pub struct HeapRegion {
    raw: RawRegion,
    /// Owns the memory `raw` points into; atomics give it interior mutability. An `Arc`, not a
    /// `Box`: moving a `Box` asserts unique access and would invalidate `raw`'s pointer (Miri's
    /// Stacked Borrows says so).
    _storage: Arc<[AtomicU64]>,
}

impl HeapRegion {
    /// A zeroed region of `len` bytes (rounded up to a multiple of 8 internally; `len()` is
    /// what was asked for).
    pub fn new(len: usize) -> Self {
        let storage: Arc<[AtomicU64]> = (0..len.div_ceil(8)).map(|_| AtomicU64::new(0)).collect();
        #[allow(unsafe_code)]
        // SAFETY: the slice is 8-byte aligned, at least `len` bytes long, and never freed before
        // `raw` (both live in `self`; the allocation stays put when the `Arc` moves). It is made
        // of atomics, so writing through a pointer derived from a shared reference to it is
        // allowed. The region is only accessed through `RawRegion`'s atomic operations.
        let raw = unsafe { RawRegion::new(storage.as_ptr().cast::<u8>().cast_mut(), len) };
        Self { raw, _storage: storage }
    }
}

delegate_to_raw!(HeapRegion);

/// How a creator makes a shared-memory object.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CreateOptions {
    /// Permission bits, applied with `fchmod` after creation so the umask cannot narrow them.
    /// Default `0o660`.
    pub mode: u32,
    /// Remove the object's name when the region is dropped. Default true.
    pub unlink_on_drop: bool,
}

impl Default for CreateOptions {
    fn default() -> Self {
        Self { mode: 0o660, unlink_on_drop: true }
    }
}

/// Why a shared-memory object could not be opened or created.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ShmError {
    /// No object of that name exists (its creator is not running).
    #[error("no shared-memory object {name}")]
    NotFound {
        /// The object's name.
        name: String,
    },
    /// The object is smaller than the layout it must hold.
    #[error("shared-memory object {name} is {size} bytes, {required} needed")]
    TooSmall {
        /// The object's name.
        name: String,
        /// Its size.
        size: u64,
        /// What the layout needs.
        required: usize,
    },
    /// Not a POSIX shared-memory name (`/name`, no further `/`).
    #[error("invalid shared-memory name {name:?}: it must be '/' followed by a name without '/'")]
    InvalidName {
        /// The name given.
        name: String,
    },
    /// A system call failed.
    #[error("{operation} of shared-memory object {name} failed: {source}")]
    Io {
        /// The object's name.
        name: String,
        /// What was being done.
        operation: &'static str,
        /// The error.
        #[source]
        source: io::Error,
    },
}

/// A POSIX shared-memory object (`shm_open`) mapped read-write and shared.
#[derive(Debug)]
pub struct MappedRegion {
    raw: RawRegion,
    /// Owns the mapping `raw` points into.
    _map: MmapRaw,
    name: String,
    unlink_on_drop: bool,
}

fn check_name(name: &str) -> Result<(), ShmError> {
    let valid = name.len() > 1 && name.starts_with('/') && !name[1..].contains('/') && name.len() < 256;
    if valid { Ok(()) } else { Err(ShmError::InvalidName { name: name.to_string() }) }
}

impl MappedRegion {
    /// Opens an existing object, read-write, never creating or resizing it. A missing object
    /// is [`ShmError::NotFound`]; one smaller than `min_len` is [`ShmError::TooSmall`]. The
    /// whole object is mapped.
    pub fn open(name: &str, min_len: usize) -> Result<Self, ShmError> {
        check_name(name)?;
        let io = |operation, source: rustix::io::Errno| ShmError::Io {
            name: name.to_string(),
            operation,
            source: source.into(),
        };
        let fd = match shm::open(name, shm::OFlags::RDWR, Mode::empty()) {
            Ok(fd) => fd,
            Err(rustix::io::Errno::NOENT) => return Err(ShmError::NotFound { name: name.to_string() }),
            Err(e) => return Err(io("shm_open", e)),
        };
        let size = rustix::fs::fstat(&fd).map_err(|e| io("fstat", e))?.st_size;
        let size = u64::try_from(size).unwrap_or(0);
        if size < min_len as u64 {
            return Err(ShmError::TooSmall { name: name.to_string(), size, required: min_len });
        }
        Self::map(name, fd, size as usize, false)
    }

    /// Creates (or takes over) the object with exactly `len` bytes, permissions from `options`
    /// applied explicitly, and maps it. Only a device's side (a daemon, a simulator) creates.
    pub fn create(name: &str, len: usize, options: &CreateOptions) -> Result<Self, ShmError> {
        check_name(name)?;
        let io = |operation, source: rustix::io::Errno| ShmError::Io {
            name: name.to_string(),
            operation,
            source: source.into(),
        };
        let fd = shm::open(name, shm::OFlags::CREATE | shm::OFlags::RDWR, Mode::from_bits_truncate(options.mode))
            .map_err(|e| io("shm_open", e))?;
        rustix::fs::fchmod(&fd, Mode::from_bits_truncate(options.mode)).map_err(|e| io("fchmod", e))?;
        rustix::fs::ftruncate(&fd, len as u64).map_err(|e| io("ftruncate", e))?;
        Self::map(name, fd, len, options.unlink_on_drop)
    }

    fn map(name: &str, fd: OwnedFd, len: usize, unlink_on_drop: bool) -> Result<Self, ShmError> {
        let file = std::fs::File::from(fd);
        let map = MmapOptions::new().len(len).map_raw(&file).map_err(|source| ShmError::Io {
            name: name.to_string(),
            operation: "mmap",
            source,
        })?;
        #[allow(unsafe_code)]
        // SAFETY: the mapping is page-aligned, `len` bytes long, readable and writable, and lives
        // in `_map` beside `raw` (declared after it, so dropped after it). Processes sharing the
        // object may write to it at any time; all our accesses are atomic (RawRegion's
        // invariant), which is the only sound way to touch memory that changes underneath.
        let raw = unsafe { RawRegion::new(map.as_mut_ptr(), len) };
        Ok(Self { raw, _map: map, name: name.to_string(), unlink_on_drop })
    }

    /// The object's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Removes an object's name (`shm_unlink`); `Ok` if it did not exist.
    pub fn unlink(name: &str) -> Result<(), ShmError> {
        check_name(name)?;
        match shm::unlink(name) {
            Ok(()) | Err(rustix::io::Errno::NOENT) => Ok(()),
            Err(e) => Err(ShmError::Io { name: name.to_string(), operation: "shm_unlink", source: e.into() }),
        }
    }
}

impl Drop for MappedRegion {
    fn drop(&mut self) {
        if self.unlink_on_drop {
            let _ = Self::unlink(&self.name);
        }
    }
}

delegate_to_raw!(MappedRegion);
