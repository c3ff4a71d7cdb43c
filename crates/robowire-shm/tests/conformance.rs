//! One conformance suite over every `SharedRegion`: the heap region (also under Miri) and a real
//! POSIX mapping.

use std::sync::Arc;
use std::sync::atomic::Ordering;

use robowire_shm::{FlaggedBlock, HeapRegion, RegionError, SharedRegion, VersionedReadError, VersionedRecord};

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
    assert_eq!(u32::from_ne_bytes(word), 0xDEAD_BEEF, "bytes copied as they are in memory");
}

/// The two protocols, single-threaded: lengths, flags, versions.
fn protocols<R: SharedRegion>(region: &R) {
    let block = FlaggedBlock::new(0, 32, 32);
    let other = block.for_consumer(36);
    let mut got = [0u8; 32];
    assert_eq!(region.take(&block, &mut got), Ok(false));
    assert_eq!(region.take(&block, &mut [0; 8]), Err(RegionError::Length { expected: 32, found: 8 }));
    assert_eq!(region.publish(&[block, other], &[3; 8]), Err(RegionError::Length { expected: 32, found: 8 }));
    region.publish(&[block, other], &[3; 32]).unwrap();
    assert_eq!((region.is_raised(&block), region.is_raised(&other)), (Ok(true), Ok(true)));
    assert_eq!(region.take(&block, &mut got), Ok(true));
    assert_eq!(got, [3; 32]);
    assert_eq!((region.is_raised(&block), region.is_raised(&other)), (Ok(false), Ok(true)), "one consumer's flag");
    assert_eq!(region.take(&other, &mut got), Ok(true));

    let record = VersionedRecord::new(64, 48);
    let mut data = [0u8; 40];
    assert_eq!(region.read_versioned(&record, &mut data, 4), Err(VersionedReadError::Empty));
    assert_eq!(region.write_versioned(&record, 0, &[0; 40]), Err(RegionError::ZeroVersion));
    region.write_versioned(&record, 42, &[9; 40]).unwrap();
    assert_eq!(region.read_versioned(&record, &mut data, 4).map(|r| r.version), Ok(42));
    assert_eq!(data, [9; 40]);
    // A writer stuck mid-update (version 0) reads as no record, never as data.
    region.store_u64(64, 0, Ordering::Relaxed).unwrap();
    assert_eq!(region.read_versioned(&record, &mut data, 4), Err(VersionedReadError::Empty));
    assert!(region.check_fits(1024).is_ok() && region.check_fits(1025).is_err());
}

/// A producer publishes blocks through the handshake; a consumer that takes one sees the whole
/// block of that round, every round, in order.
fn flag_handshake<R: SharedRegion + Send + Sync + 'static>(region: Arc<R>, rounds: u32) {
    const BLOCK: FlaggedBlock = FlaggedBlock::new(0, 256, 512);
    let producer = {
        let region = region.clone();
        std::thread::spawn(move || {
            for round in 1..=rounds {
                while region.is_raised(&BLOCK).unwrap() {
                    std::hint::spin_loop();
                    std::thread::yield_now();
                }
                let block: Vec<u8> = (0..64u32).flat_map(|i| (round * 1000 + i).to_ne_bytes()).collect();
                region.publish(&[BLOCK], &block).unwrap();
            }
        })
    };
    let mut round = 1;
    let mut block = [0u8; 256];
    while round <= rounds {
        if !region.take(&BLOCK, &mut block).unwrap() {
            std::hint::spin_loop();
            std::thread::yield_now();
            continue;
        }
        for (i, word) in block.chunks_exact(4).enumerate() {
            assert_eq!(u32::from_ne_bytes(word.try_into().unwrap()), round * 1000 + i as u32, "round {round} word {i}");
        }
        round += 1;
    }
    producer.join().unwrap();
}

/// A writer updates a record as fast as it can; every record a reader accepts is whole.
fn versioned_record<R: SharedRegion + Send + Sync + 'static>(region: Arc<R>, versions: u64) {
    const RECORD: VersionedRecord = VersionedRecord::new(600, 40);
    let writer = {
        let region = region.clone();
        std::thread::spawn(move || {
            for version in 1..=versions {
                let data: Vec<u8> = (0..8u32).flat_map(|_| (version as u32).to_ne_bytes()).collect();
                region.write_versioned(&RECORD, version, &data).unwrap();
            }
        })
    };
    let mut data = [0u8; 32];
    let mut accepted = 0;
    while !writer.is_finished() || accepted == 0 {
        match region.read_versioned(&RECORD, &mut data, 8) {
            Ok(read) => {
                let version = read.version;
                accepted += 1;
                assert!(data.chunks_exact(4).all(|w| u32::from_ne_bytes(w.try_into().unwrap()) == version as u32));
            }
            Err(VersionedReadError::Empty | VersionedReadError::Torn { .. }) => std::thread::yield_now(),
            Err(e) => panic!("{e}"),
        }
    }
    writer.join().unwrap();
}

#[test]
fn heap_region_conforms() {
    basic_access(&HeapRegion::new(1024));
    protocols(&HeapRegion::new(1024));
    let rounds = if cfg!(miri) { 20 } else { 2000 };
    flag_handshake(Arc::new(HeapRegion::new(1024)), rounds);
    versioned_record(Arc::new(HeapRegion::new(1024)), u64::from(rounds));
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
        protocols(&MappedRegion::create(&name, 1024, &CreateOptions::default()).unwrap());
        let creator = Arc::new(MappedRegion::create(&name, 1024, &CreateOptions::default()).unwrap());
        flag_handshake(creator.clone(), 2000);
        versioned_record(creator, 2000);
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

    /// The name of the object the permission test's child process opens.
    const DENIED_ENV: &str = "ROBOWIRE_SHM_DENIED_OBJECT";

    /// A process that may not open an object gets the object's mode and owner and what to do,
    /// not a bare I/O error. Root may open anything, so as root the open runs in a child
    /// process as `nobody`; otherwise the object is made unreadable to its own owner.
    #[test]
    fn permission_denied_names_mode_and_owner() {
        if let Ok(object) = std::env::var(DENIED_ENV) {
            // The child: report what opening gives.
            match MappedRegion::open(&object, 8) {
                Err(e @ ShmError::PermissionDenied { .. }) => println!("DENIED {e}"),
                other => println!("UNEXPECTED {other:?}"),
            }
            return;
        }
        let name = name("denied");
        let root = rustix::process::geteuid().is_root();
        let mode = if root { 0o600 } else { 0o000 };
        let _creator = MappedRegion::create(&name, 64, &CreateOptions { mode, unlink_on_drop: true }).unwrap();
        let text = if root {
            use std::os::unix::process::CommandExt;
            let output = std::process::Command::new(std::env::current_exe().unwrap())
                .args(["--exact", "mapped::permission_denied_names_mode_and_owner", "--nocapture", "--test-threads=1"])
                .env(DENIED_ENV, &name)
                .uid(65534)
                .gid(65534)
                .output()
                .unwrap();
            String::from_utf8_lossy(&output.stdout).into_owned()
        } else {
            match MappedRegion::open(&name, 8) {
                Err(e @ ShmError::PermissionDenied { .. }) => format!("DENIED {e}"),
                other => format!("UNEXPECTED {other:?}"),
            }
        };
        assert!(text.contains("DENIED"), "{text}");
        assert!(text.contains(&format!("mode {mode:04o}")), "{text}");
        let owner = rustix::process::geteuid().as_raw();
        assert!(text.contains(&format!("owner uid {owner}")), "{text}");
        assert!(text.contains("0660"), "says what to do: {text}");
    }
}
