//! Loom models of the two shared-memory protocols, running robowire-shm's own code
//! ([`SharedRegion::publish`] / [`take`](SharedRegion::take), [`write_versioned`] /
//! [`read_versioned`]) over a region made of loom atomics. Loom explores every interleaving and
//! checks that a consumer never reads a torn or stale block and that no access races.
//!
//! [`write_versioned`]: SharedRegion::write_versioned
//! [`read_versioned`]: SharedRegion::read_versioned

use std::sync::atomic::Ordering;

use loom::sync::Arc;
use loom::sync::atomic::{AtomicU32, AtomicU64};
use robowire_shm::{FlaggedBlock, RegionError, SharedRegion, VersionedReadError, VersionedRecord};

/// A region of loom atomics. The trait's contract (one access width per location) lets u32
/// words and u64 fields live in separate arrays: `u64` offsets map to `dwords`, all others to
/// `words`.
struct LoomRegion {
    words: Vec<AtomicU32>,
    dwords: Vec<AtomicU64>,
}

impl LoomRegion {
    fn new(len: usize) -> Self {
        Self {
            words: (0..len / 4).map(|_| AtomicU32::new(0)).collect(),
            dwords: (0..len / 8).map(|_| AtomicU64::new(0)).collect(),
        }
    }

    fn word(&self, offset: usize) -> Result<&AtomicU32, RegionError> {
        self.words.get(offset / 4).ok_or(RegionError::OutOfBounds { offset, len: 4, region_len: self.len() })
    }
}

impl SharedRegion for LoomRegion {
    fn len(&self) -> usize {
        self.words.len() * 4
    }
    fn read(&self, offset: usize, dst: &mut [u8]) -> Result<(), RegionError> {
        for (i, chunk) in dst.chunks_exact_mut(4).enumerate() {
            chunk.copy_from_slice(&self.word(offset + 4 * i)?.load(Ordering::Relaxed).to_ne_bytes());
        }
        Ok(())
    }
    fn write(&self, offset: usize, src: &[u8]) -> Result<(), RegionError> {
        for (i, chunk) in src.chunks_exact(4).enumerate() {
            self.word(offset + 4 * i)?.store(u32::from_ne_bytes(chunk.try_into().unwrap()), Ordering::Relaxed);
        }
        Ok(())
    }
    fn load_u32(&self, offset: usize, order: Ordering) -> Result<u32, RegionError> {
        Ok(self.word(offset)?.load(order))
    }
    fn store_u32(&self, offset: usize, value: u32, order: Ordering) -> Result<(), RegionError> {
        self.word(offset)?.store(value, order);
        Ok(())
    }
    fn load_u64(&self, offset: usize, order: Ordering) -> Result<u64, RegionError> {
        Ok(self.dwords[offset / 8].load(order))
    }
    fn store_u64(&self, offset: usize, value: u64, order: Ordering) -> Result<(), RegionError> {
        self.dwords[offset / 8].store(value, order);
        Ok(())
    }
    fn fence(&self, order: Ordering) {
        loom::sync::atomic::fence(order);
    }
}

/// Two words of block at 0, the consumer's flag at 8.
const BLOCK: FlaggedBlock = FlaggedBlock::new(0, 8, 8);

fn block_of(round: u32) -> [u8; 8] {
    let mut bytes = [0u8; 8];
    bytes[..4].copy_from_slice(&round.to_ne_bytes());
    bytes[4..].copy_from_slice(&round.to_ne_bytes());
    bytes
}

#[test]
fn the_handshake_delivers_whole_fresh_blocks() {
    loom::model(|| {
        let region = Arc::new(LoomRegion::new(16));
        let producer = {
            let region = region.clone();
            loom::thread::spawn(move || {
                for round in 1..=2u32 {
                    // The producer waits for the consumer to take the previous block.
                    while region.is_raised(&BLOCK).unwrap() {
                        loom::thread::yield_now();
                    }
                    region.publish(&[BLOCK], &block_of(round)).unwrap();
                }
            })
        };
        let mut seen = 0;
        let mut got = [0u8; 8];
        while seen < 2 {
            if !region.take(&BLOCK, &mut got).unwrap() {
                loom::thread::yield_now();
                continue;
            }
            seen += 1;
            assert_eq!(got, block_of(seen), "torn, stale or skipped block");
        }
        producer.join().unwrap();
    });
}

/// Version at 0, two words of data at 8..16.
const RECORD: VersionedRecord = VersionedRecord::new(0, 16);

#[test]
fn a_versioned_read_never_accepts_a_torn_record() {
    loom::model(|| {
        let region = Arc::new(LoomRegion::new(16));
        let writer = {
            let region = region.clone();
            loom::thread::spawn(move || {
                for version in 1..=2u64 {
                    region.write_versioned(&RECORD, version, &block_of(version as u32)).unwrap();
                }
            })
        };
        let mut data = [0u8; 8];
        match region.read_versioned(&RECORD, &mut data, 2) {
            Ok(read) => assert_eq!(data, block_of(read.version as u32), "accepted a torn record"),
            Err(VersionedReadError::Empty | VersionedReadError::Torn { .. }) => {}
            Err(e) => panic!("{e}"),
        }
        writer.join().unwrap();
    });
}
