//! A loom model of the consumer-flag handshake (spec §6): the producer writes the block and
//! sets the flag with Release; the consumer tests it with Acquire, copies the block and clears
//! it with Release; the producer waits for the clear before the next block. Loom explores every
//! interleaving and checks that the consumer never reads a torn or stale block and that no
//! access races.

use loom::cell::UnsafeCell;
use loom::sync::Arc;
use loom::sync::atomic::{AtomicU32, Ordering};

struct Shared {
    block: UnsafeCell<[u32; 2]>,
    flag: AtomicU32,
}

#[test]
fn handshake_delivers_whole_blocks() {
    loom::model(|| {
        let shared = Arc::new(Shared { block: UnsafeCell::new([0, 0]), flag: AtomicU32::new(0) });
        let producer = {
            let shared = shared.clone();
            loom::thread::spawn(move || {
                for round in 1..=2u32 {
                    while shared.flag.load(Ordering::Acquire) != 0 {
                        loom::thread::yield_now();
                    }
                    shared.block.with_mut(|b| {
                        // SAFETY: the consumer cleared the flag (acquired above), so it no longer
                        // reads the block; loom reports the access if that reasoning is wrong.
                        let b = unsafe { &mut *b };
                        b[0] = round;
                        b[1] = round;
                    });
                    shared.flag.store(1, Ordering::Release);
                }
            })
        };
        let mut seen = 0;
        while seen < 2 {
            if shared.flag.load(Ordering::Acquire) == 0 {
                loom::thread::yield_now();
                continue;
            }
            // SAFETY: the flag was acquired non-zero, so the producer finished writing and waits
            // for the clear; loom reports the access if that reasoning is wrong.
            let block = shared.block.with(|b| unsafe { *b });
            assert_eq!(block[0], block[1], "torn block");
            assert_eq!(block[0], seen + 1, "stale or skipped block");
            seen += 1;
            shared.flag.store(0, Ordering::Release);
        }
        producer.join().unwrap();
    });
}
