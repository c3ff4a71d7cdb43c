//! In steady state, `Writer::try_write` allocates nothing on the real socket path: a LowCmd
//! encoded, handed to the RTPS core and sent with `sendto` to a matched reliable reader of
//! another participant (where loopback carries multicast: `netns`). Counted on the writing thread
//! only (the participants' background threads and the harness allocate when they like).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use robowire_dds::netns::with_loopback_multicast;
use robowire_dds::qos::Qos;
use robowire_dds::{Participant, ParticipantOptions};
use unitree_proto::{LowCmd, Message};

struct Counting;
static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    /// Counting on this thread only.
    static COUNTING: Cell<bool> = const { Cell::new(false) };
}

fn counting() -> bool {
    COUNTING.try_with(Cell::get).unwrap_or(false)
}

// SAFETY: forwards to the system allocator; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if counting() {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        // SAFETY: the caller's layout, passed on.
        unsafe { System.alloc(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if counting() {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        // SAFETY: as the caller's contract.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `alloc` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Writes counted after the warm-up.
const COUNTED: u32 = 2000;

#[test]
fn try_write_to_a_matched_reader_allocates_nothing_in_steady_state() {
    with_loopback_multicast(|| {
        let options = ParticipantOptions::new(0, Some("lo"));
        let client = Participant::new(options.clone()).unwrap();
        let robot = Participant::new(options).unwrap();
        let writer = client.writer::<LowCmd>(LowCmd::TOPIC, Qos::STREAM_WRITER).unwrap();
        // Reliable: heartbeats and acknowledgements run around the samples too.
        let reader = robot.reader::<LowCmd>(LowCmd::TOPIC, Qos { reliable: true, ..Qos::READER }).unwrap();
        let arrived = Arc::new(AtomicU64::new(0));
        let _listener = reader.listen({
            let arrived = arrived.clone();
            move |_| {
                arrived.fetch_add(1, Ordering::Relaxed);
            }
        });
        let mut cmd = LowCmd::default();
        let end = Instant::now() + Duration::from_secs(20);
        while arrived.load(Ordering::Relaxed) == 0 {
            assert!(Instant::now() < end, "no LowCmd arrived (discovery)");
            writer.try_write(cmd).unwrap();
            std::thread::sleep(Duration::from_millis(10));
        }
        // Warm-up: the thread's payload buffer grows, the history takes its buffers.
        for i in 0..200u32 {
            cmd.reserve = i.into();
            writer.try_write(cmd).unwrap();
            std::thread::sleep(Duration::from_micros(500));
        }
        let before = arrived.load(Ordering::Relaxed);
        COUNTING.with(|c| c.set(true));
        for i in 0..COUNTED {
            cmd.reserve = i.into();
            writer.try_write(cmd).unwrap();
            std::thread::sleep(Duration::from_micros(500));
        }
        COUNTING.with(|c| c.set(false));
        let allocations = ALLOCATIONS.load(Ordering::Relaxed);
        std::thread::sleep(Duration::from_millis(100));
        let delivered = arrived.load(Ordering::Relaxed) - before;
        assert!(delivered > u64::from(COUNTED) / 2, "{delivered} of {COUNTED} arrived: the path was not exercised");
        assert_eq!(allocations, 0, "{allocations} allocations in {COUNTED} writes ({delivered} arrived)");
        assert_eq!(writer.stats().dropped, 0);
    });
}
