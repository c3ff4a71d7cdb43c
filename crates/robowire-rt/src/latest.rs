//! [`Latest`]: the latest value of something (a command, a state), written by any thread and
//! read by a stream thread without ever waiting, with the time it was written.
//!
//! A versioned record on a heap region (`robowire-shm`): the write time is the version, so a
//! reader either gets a value and its time that belong together, or retries. Writers take a
//! lock among themselves; the reader takes none. Versions strictly increase: two writes in the
//! same nanosecond are stamped a nanosecond apart, so a reader never mistakes a new value for
//! the one it has.

use std::sync::Mutex;
use std::sync::atomic::Ordering;

use robowire_core::schedule::Time;
use robowire_core::shm::VersionedRecord;
use robowire_shm::{HeapRegion, SharedRegion};
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout};

/// Read attempts before a reader gives up on a record a writer keeps rewriting.
const READ_ATTEMPTS: u32 = 64;

/// The latest `T` and when it was written: a seqlock whose version is the write time. A
/// reader either gets a value and its time that belong together or retries; writers take a
/// lock among themselves, the reader none. Stamps strictly increase. `T`'s size must be a
/// multiple of 4 bytes.
#[derive(Debug)]
pub struct Latest<T> {
    region: HeapRegion,
    record: VersionedRecord,
    /// The last version written; held by a writer while it writes.
    writers: Mutex<u64>,
    value: std::marker::PhantomData<fn(T) -> T>,
}

impl<T: FromBytes + IntoBytes + KnownLayout + Immutable> Default for Latest<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: FromBytes + IntoBytes + KnownLayout + Immutable> Latest<T> {
    const RECORD: VersionedRecord = VersionedRecord::new(0, 8 + size_of::<T>());

    /// Nothing written yet.
    pub fn new() -> Self {
        const { assert!(size_of::<T>().is_multiple_of(4), "Latest<T> needs a size that is a multiple of 4") };
        Self {
            region: HeapRegion::new(Self::RECORD.len),
            record: Self::RECORD,
            writers: Mutex::new(0),
            value: std::marker::PhantomData,
        }
    }

    /// Replaces the value, written at `at`; returns the time it is stamped with (`at`, or just
    /// after the previous write's stamp if that is not earlier).
    pub fn write(&self, at: Time, value: &T) -> Time {
        let mut last = crate::lock(&self.writers);
        let version = at.as_nanos().max(*last + 1);
        *last = version;
        // The region is ours and sized for the record: this cannot fail.
        let _ = self.region.write_versioned(&self.record, version, value.as_bytes());
        Time::from_nanos(version)
    }

    /// The latest value and when it was written, or `None` if nothing was (or a write was under
    /// way during every attempt, which a bounded number of retries makes rare).
    pub fn read(&self) -> Option<(Time, T)> {
        let mut value = T::new_zeroed();
        let read = self.region.read_versioned(&self.record, value.as_mut_bytes(), READ_ATTEMPTS).ok()?;
        Some((Time::from_nanos(read.version), value))
    }

    /// Like [`read`](Self::read), but `None` without copying when the stamp is still `seen`
    /// (the value the reader already has). For a loop that polls for a new value.
    pub fn read_newer(&self, seen: Option<Time>) -> Option<(Time, T)> {
        let version = self.region.load_u64(self.record.offset, Ordering::Acquire).ok()?;
        if version == 0 || Some(Time::from_nanos(version)) == seen {
            return None;
        }
        self.read()
    }

    /// When the latest value was written (`None` if never, or while a write is under way).
    pub fn written_at(&self) -> Option<Time> {
        let version = self.region.load_u64(self.record.offset, Ordering::Acquire).ok()?;
        (version != 0).then_some(Time::from_nanos(version))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_latest_value_with_its_time() {
        let latest: Latest<[u32; 2]> = Latest::new();
        assert_eq!(latest.read(), None);
        assert_eq!(latest.write(Time::from_nanos(5), &[1, 2]), Time::from_nanos(5));
        latest.write(Time::from_nanos(9), &[3, 4]);
        assert_eq!(latest.read(), Some((Time::from_nanos(9), [3, 4])));
        assert_eq!(latest.written_at(), Some(Time::from_nanos(9)));
        // Not later than the last stamp: stamped just after it.
        assert_eq!(latest.write(Time::from_nanos(9), &[5, 6]), Time::from_nanos(10));
        assert_eq!(latest.write(Time::ZERO, &[7, 8]), Time::from_nanos(11));
        assert_eq!(latest.read(), Some((Time::from_nanos(11), [7, 8])));
    }

    #[test]
    fn read_newer_skips_the_value_already_seen() {
        let latest: Latest<u32> = Latest::new();
        assert_eq!(latest.read_newer(None), None);
        let at = latest.write(Time::from_nanos(100), &7);
        assert_eq!(latest.read_newer(None), Some((at, 7)));
        assert_eq!(latest.read_newer(Some(at)), None);
        let next = latest.write(Time::from_nanos(100), &8);
        assert_eq!(latest.read_newer(Some(at)), Some((next, 8)));
    }
}
