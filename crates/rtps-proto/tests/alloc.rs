//! In steady state, writing a LowCmd-sized sample, carrying it, receiving it (and the reliable
//! protocol's heartbeats and acknowledgements around it) allocates nothing.

#[allow(dead_code)] // each test binary uses a part of it
mod pair;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

use rtps_proto::Time;
use rtps_proto::discovery::{History, Qos, Reliability};
use rtps_proto::participant::{Destination, Event, Participant};
use rtps_proto::types::DdsDuration;

struct Counting;
static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    /// Counting on this thread only (the test harness's own threads allocate when they like).
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

fn steady_state_allocations(reliable: bool) -> usize {
    let mut now = Time::from_nanos(1_000_000_000);
    let mut a = Participant::new(pair::config(1), now);
    let mut b = Participant::new(pair::config(2), now);
    let reliability =
        if reliable { Reliability::Reliable { max_blocking_time: DdsDuration::ZERO } } else { Reliability::BestEffort };
    let qos = Qos { history: History::KeepLast { depth: 1 }, reliability, ..Qos::default() };
    let w = a.create_writer(now, "rt/lowcmd", "unitree_go::msg::dds_::LowCmd_", qos.clone()).unwrap();
    b.create_reader(now, "rt/lowcmd", "unitree_go::msg::dds_::LowCmd_", qos).unwrap();
    let mut buf = vec![0u8; 65_536];
    let source: SocketAddr = "127.0.0.1:7410".parse().unwrap();
    let mut sample = vec![0u8; 816]; // LowCmd's 812 bytes of XCDR1 and the encapsulation header
    sample[1] = 1;
    let mut step = |now: Time, a: &mut Participant, b: &mut Participant, i: u32| {
        sample[4..8].copy_from_slice(&i.to_le_bytes());
        let t = a.write(now, w, &sample, &Default::default(), &mut buf).unwrap();
        if let Some(t) = t.transmit {
            b.handle_datagram(now, source, Destination::Unicast, &buf[..t.len]);
        }
        for _ in 0..4 {
            a.handle_timeout(now);
            b.handle_timeout(now);
            while let Some(t) = a.poll_transmit(now, &mut buf) {
                b.handle_datagram(now, source, Destination::Unicast, &buf[..t.len]);
            }
            while let Some(t) = b.poll_transmit(now, &mut buf) {
                a.handle_datagram(now, source, Destination::Unicast, &buf[..t.len]);
            }
        }
        let mut got = 0;
        while let Some(e) = b.poll_event() {
            if let Event::Sample(s) = e {
                got += 1;
                b.recycle(s.payload);
            }
        }
        got
    };
    // Discovery and warm-up (buffers reach their sizes).
    for i in 0..200 {
        step(now, &mut a, &mut b, i);
        now = now + Duration::from_millis(2);
    }
    // The next samples, 2 ms apart (heartbeats every 100 ms), counted; SPDP announcements are
    // not the sample path: the window stays inside one announcement period.
    ALLOCATIONS.store(0, Ordering::Relaxed);
    COUNTING.with(|c| c.set(true));
    let mut received = 0;
    for i in 200..1200 {
        received += step(now, &mut a, &mut b, i);
        now = now + Duration::from_micros(2000);
    }
    COUNTING.with(|c| c.set(false));
    assert_eq!(received, 1000, "every sample arrived");
    ALLOCATIONS.load(Ordering::Relaxed)
}

#[test]
fn steady_writes_and_receives_allocate_nothing() {
    assert_eq!(steady_state_allocations(false), 0, "best effort");
    assert_eq!(steady_state_allocations(true), 0, "reliable");
}
