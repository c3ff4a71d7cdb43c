//! One conformance suite over every `SharedRegion`: the heap region (also under Miri) and a real
//! POSIX mapping.

use std::sync::Arc;
use std::sync::atomic::Ordering;

use robowire_shm::{HeapRegion, RegionError, SharedRegion};

/// Bounds, alignment, copies and atomics.
fn basic_access<R: SharedRegion>(region: &R) {
    assert_eq!(region.len(), 1024);
    let mut buf = [0u8; 16];
    region.read(0, &mut buf).unwrap();
    assert_eq!(buf, [0; 16], "a new region is zeroed");
    region.write(16, &[9; 16]).unwrap();
    region.read(12, &mut buf).unwrap();
    assert_eq!(buf, [0, 0, 0, 0, 9, 9, 9, 9, 9, 9, 9, 9, 9, 9, 9, 9]);
    assert_eq!(
        region.read(1020, &mut [0; 8]),
        Err(RegionError::OutOfBounds { offset: 1020, len: 8, region_len: 1024 })
    );
    assert_eq!(
        region.write(usize::MAX - 2, &[0; 4]),
        Err(RegionError::OutOfBounds { offset: usize::MAX - 2, len: 4, region_len: 1024 })
    );
    assert_eq!(region.read(2, &mut [0; 4]), Err(RegionError::Misaligned { offset: 2, len: 4, align: 4 }));
    assert_eq!(region.write(4, &[0; 3]), Err(RegionError::Misaligned { offset: 4, len: 3, align: 4 }));
    assert_eq!(region.load_u64(4, Ordering::Acquire), Err(RegionError::Misaligned { offset: 4, len: 8, align: 8 }));
    region.store_u32(100, 0xDEAD_BEEF, Ordering::Release).unwrap();
    assert_eq!(region.load_u32(100, Ordering::Acquire), Ok(0xDEAD_BEEF));
    region.store_u64(200, u64::MAX - 1, Ordering::Release).unwrap();
    assert_eq!(region.load_u64(200, Ordering::Acquire), Ok(u64::MAX - 1));
    let mut word = [0u8; 4];
    region.read(100, &mut word).unwrap();
    assert_eq!(u32::from_le_bytes(word), 0xDEAD_BEEF, "little-endian words");
}

/// A producer publishes blocks with release; a consumer that acquires the flag sees the whole
/// block of that round.
fn flag_handshake<R: SharedRegion + Send + Sync + 'static>(region: Arc<R>, rounds: u32) {
    const FLAG: usize = 512;
    let producer = {
        let region = region.clone();
        std::thread::spawn(move || {
            for round in 1..=rounds {
                while region.load_u32(FLAG, Ordering::Acquire).unwrap() != 0 {
                    std::hint::spin_loop();
                    std::thread::yield_now();
                }
                let block: Vec<u8> = (0..64u32).flat_map(|i| (round * 1000 + i).to_le_bytes()).collect();
                region.write(0, &block).unwrap();
                region.store_u32(FLAG, round, Ordering::Release).unwrap();
            }
        })
    };
    let mut expected = 1;
    while expected <= rounds {
        let round = region.load_u32(FLAG, Ordering::Acquire).unwrap();
        if round == 0 {
            std::hint::spin_loop();
            std::thread::yield_now();
            continue;
        }
        assert_eq!(round, expected);
        let mut block = [0u8; 256];
        region.read(0, &mut block).unwrap();
        for (i, word) in block.chunks_exact(4).enumerate() {
            assert_eq!(u32::from_le_bytes(word.try_into().unwrap()), round * 1000 + i as u32, "round {round} word {i}");
        }
        region.store_u32(FLAG, 0, Ordering::Release).unwrap();
        expected += 1;
    }
    producer.join().unwrap();
}

#[test]
fn heap_region_conforms() {
    basic_access(&HeapRegion::new(1024));
    let rounds = if cfg!(miri) { 20 } else { 2000 };
    flag_handshake(Arc::new(HeapRegion::new(1024)), rounds);
}

#[test]
fn heap_region_rounds_odd_lengths() {
    let region = HeapRegion::new(6);
    assert_eq!(region.len(), 6);
    region.write(0, &[1, 2, 3, 4]).unwrap();
    assert!(region.write(4, &[0; 4]).is_err());
}

#[cfg(not(miri))]
mod mapped {
    use super::*;
    use robowire_shm::{CreateOptions, MappedRegion, ShmError};

    fn name(tag: &str) -> String {
        format!("/robowire-test-{tag}-{}", std::process::id())
    }

    #[test]
    fn mapped_region_conforms() {
        let name = name("conform");
        let creator = MappedRegion::create(&name, 1024, &CreateOptions::default()).unwrap();
        basic_access(&creator);
        drop(creator);
        let creator = Arc::new(MappedRegion::create(&name, 1024, &CreateOptions::default()).unwrap());
        flag_handshake(creator, 2000);
    }

    #[test]
    fn two_mappings_of_one_object_share_memory() {
        let name = name("share");
        let creator = MappedRegion::create(&name, 4096, &CreateOptions::default()).unwrap();
        let client = MappedRegion::open(&name, 608).unwrap();
        assert_eq!(client.len(), 4096, "the whole object is mapped");
        client.write(336, &[7; 8]).unwrap();
        client.store_u32(600, 1, Ordering::Release).unwrap();
        assert_eq!(creator.load_u32(600, Ordering::Acquire), Ok(1));
        let mut got = [0u8; 8];
        creator.read(336, &mut got).unwrap();
        assert_eq!(got, [7; 8]);
    }

    #[test]
    fn clients_never_create_or_grow_objects() {
        let missing = name("missing");
        assert!(matches!(MappedRegion::open(&missing, 8), Err(ShmError::NotFound { name }) if name == missing));
        let small = name("small");
        let _creator = MappedRegion::create(&small, 100, &CreateOptions::default()).unwrap();
        match MappedRegion::open(&small, 608) {
            Err(ShmError::TooSmall { size: 100, required: 608, .. }) => {}
            other => panic!("{other:?}"),
        }
        assert!(matches!(MappedRegion::open("no-slash", 8), Err(ShmError::InvalidName { .. })));
        assert!(matches!(MappedRegion::open("/a/b", 8), Err(ShmError::InvalidName { .. })));
    }

    #[test]
    fn creator_mode_is_not_narrowed_by_the_umask() {
        let name = name("mode");
        // The process umask applies to shm_open's mode; the creator must override it.
        let old = rustix::process::umask(rustix::fs::Mode::from_bits_truncate(0o077));
        let creator = MappedRegion::create(&name, 64, &CreateOptions { mode: 0o660, unlink_on_drop: true });
        rustix::process::umask(old);
        let _creator = creator.unwrap();
        let meta = std::fs::metadata(format!("/dev/shm/{}", &name[1..])).unwrap();
        use std::os::unix::fs::PermissionsExt;
        assert_eq!(meta.permissions().mode() & 0o777, 0o660);
    }

    #[test]
    fn unlink_on_drop_removes_the_name() {
        let name = name("unlink");
        drop(MappedRegion::create(&name, 64, &CreateOptions::default()).unwrap());
        assert!(matches!(MappedRegion::open(&name, 8), Err(ShmError::NotFound { .. })));
        let kept =
            MappedRegion::create(&name, 64, &CreateOptions { unlink_on_drop: false, ..Default::default() }).unwrap();
        drop(kept);
        assert!(MappedRegion::open(&name, 8).is_ok());
        MappedRegion::unlink(&name).unwrap();
        MappedRegion::unlink(&name).unwrap(); // idempotent
    }
}
