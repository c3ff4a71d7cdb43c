//! Descriptors of shared-memory layouts: what a codec declares about a region, for the
//! shared-memory transport (`robowire-shm`) to implement. Plain data, no access.
//!
//! Two patterns cover the robots robowire speaks to:
//! - [`FlaggedBlock`]: a block with consumer flags. The producer writes the block, then raises
//!   every consumer's flag (release); a consumer that finds its flag raised (acquire) copies
//!   the block and lowers the flag (release). A raised flag means "fresh since you last took it".
//! - [`VersionedRecord`]: a record that starts with a non-zero 64-bit version (a timestamp, a
//!   counter). The writer stores 0 while it updates the record and the new version after it; a
//!   reader accepts a copy only if the version was non-zero and unchanged around the copy.

/// A block of `len` bytes at `offset`, with the u32 flag of each consumer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FlaggedBlock {
    /// Offset of the block in the region, bytes (a multiple of 4).
    pub offset: usize,
    /// Length of the block, bytes (a multiple of 4).
    pub len: usize,
    /// Offset of the flag (a u32, 4-byte aligned) of the consumer this descriptor is for.
    pub flag: usize,
}

impl FlaggedBlock {
    /// The block at `offset..offset + len` read by the consumer whose flag is at `flag`.
    pub const fn new(offset: usize, len: usize, flag: usize) -> Self {
        Self { offset, len, flag }
    }

    /// The same block, seen by the consumer whose flag is at `flag`.
    pub const fn for_consumer(self, flag: usize) -> Self {
        Self { flag, ..self }
    }

    /// One past the last byte the block and its flag use.
    pub const fn end(&self) -> usize {
        let block_end = self.offset + self.len;
        let flag_end = self.flag + 4;
        if block_end > flag_end { block_end } else { flag_end }
    }
}

/// A record of `len` bytes at `offset` whose first 8 bytes are its version (a u64, 8-byte
/// aligned; 0 = no record, or being written).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct VersionedRecord {
    /// Offset of the version word, bytes (a multiple of 8).
    pub offset: usize,
    /// Length of the record, version included, bytes (8 plus a multiple of 4).
    pub len: usize,
}

impl VersionedRecord {
    /// The record at `offset..offset + len`, version first.
    pub const fn new(offset: usize, len: usize) -> Self {
        Self { offset, len }
    }

    /// Offset of the data after the version.
    pub const fn data_offset(&self) -> usize {
        self.offset + 8
    }

    /// Length of the data after the version.
    pub const fn data_len(&self) -> usize {
        self.len.saturating_sub(8)
    }

    /// One past the last byte.
    pub const fn end(&self) -> usize {
        self.offset + self.len
    }
}
