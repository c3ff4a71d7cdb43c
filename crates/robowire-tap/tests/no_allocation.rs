//! `Tap::record` allocates nothing, whatever becomes of the frame: recorded, dropped on a full
//! ring, oversize, or refused by a closed ring. One test in this binary, so that no other test
//! allocates while it counts.

use std::alloc::System;

use robowire_tap::{Direction, SLOT_BYTES, TapRing};
use stats_alloc::{INSTRUMENTED_SYSTEM, Region, StatsAlloc};

#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

#[test]
fn record_never_allocates() {
    let ring = TapRing::with_slots(8);
    let tap = ring.tap(3);
    let state = [0x5a; 560];
    let oversize = vec![0; SLOT_BYTES + 1];
    // The first read of the monotonic clock may set up the vDSO lookup.
    tap.record(Direction::Received, &state);
    let _ = ring.pop(|_| ());

    let region = Region::new(GLOBAL);
    for _ in 0..20 {
        tap.record(Direction::Received, &state);
    }
    tap.record(Direction::Sent, &oversize);
    ring.close();
    tap.record(Direction::Sent, &state);
    let change = region.change();

    let c = ring.counters();
    assert_eq!((c.recorded(), c.dropped(), c.oversize()), (1 + 8, 12 + 1, 1), "every outcome was taken");
    assert_eq!((change.allocations, change.reallocations, change.bytes_allocated), (0, 0, 0), "{change:?}");
}
