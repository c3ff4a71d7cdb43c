//! A whole RTPS `Participant` (one reliable writer and one reader on a topic, a peer whose SPDP
//! and SEDP it has taken) driven by a sequence of steps: datagrams (any bytes, or templates of
//! DATA, DATA_FRAG, HEARTBEAT, HEARTBEAT_FRAG, ACKNACK, GAP, NACK_FRAG and the peer's discovery
//! data with their numbers chosen by the fuzzer), clock steps with `handle_timeout`, local
//! writes, and polls of transmits and events (`rtps_proto::fuzzing::participant_steps`, which
//! documents the input format). No panic, and the live heap stays under a bound.
#![no_main]

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicUsize, Ordering};

use libfuzzer_sys::fuzz_target;
use rtps_proto::fuzzing::{ParticipantSetup, participant_steps};

/// The live heap allowed: 64 MiB. From `Limits::default()`: what one input can make the
/// participant hold is dominated by reassembly buffers, which are allocated at `sampleSize` up
/// front (`reassembly_bytes` = 1 MiB each, `reassemblies` = 8 per matched writer: 8 MiB for the
/// peer's writer); the history (`history_depth` samples) and the event queue (`events`) hold
/// only bytes the input itself carried (at most `-max_len`). 64 MiB is eight such writers'
/// reassembly tables, and leaves room for the setup kept across runs (a few KiB) and the run's
/// scratch buffers (about 150 KiB). An allocation past it fails, which aborts the process
/// ("memory allocation of N bytes failed"): libFuzzer reports a crash and keeps the input.
const HEAP_LIMIT: usize = 64 << 20;

/// Counts live heap bytes; refuses an allocation that would pass [`HEAP_LIMIT`].
struct Bounded;

static LIVE: AtomicUsize = AtomicUsize::new(0);

impl Bounded {
    fn reserve(size: usize) -> bool {
        let live = LIVE.fetch_add(size, Ordering::Relaxed) + size;
        if live > HEAP_LIMIT {
            LIVE.fetch_sub(size, Ordering::Relaxed);
            return false;
        }
        true
    }
}

// SAFETY: forwards to the system allocator; only counts, and refuses past the bound (returning
// null, which `GlobalAlloc` allows).
unsafe impl GlobalAlloc for Bounded {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if !Self::reserve(layout.size()) {
            return std::ptr::null_mut();
        }
        // SAFETY: the caller's layout, passed on.
        let p = unsafe { System.alloc(layout) };
        if p.is_null() {
            LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        }
        p
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if !Self::reserve(layout.size()) {
            return std::ptr::null_mut();
        }
        // SAFETY: the caller's layout, passed on.
        let p = unsafe { System.alloc_zeroed(layout) };
        if p.is_null() {
            LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        // SAFETY: `ptr` came from this allocator with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let grow = new_size.saturating_sub(layout.size());
        if !Self::reserve(grow) {
            return std::ptr::null_mut();
        }
        // SAFETY: `ptr` came from this allocator with `layout`; the caller's new size.
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if p.is_null() {
            LIVE.fetch_sub(grow, Ordering::Relaxed);
        } else {
            LIVE.fetch_sub(layout.size().saturating_sub(new_size), Ordering::Relaxed);
        }
        p
    }
}

#[global_allocator]
static ALLOCATOR: Bounded = Bounded;

/// The peer's discovery datagrams, captured once from two real participants.
static SETUP: OnceLock<ParticipantSetup> = OnceLock::new();

fuzz_target!(|data: &[u8]| participant_steps(SETUP.get_or_init(ParticipantSetup::new), data));
