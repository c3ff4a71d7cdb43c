//! The six datagrams that silence a rustdds 0.15.1 participant (`robowire/tests/dds_flood`'s
//! `rustdds_0_15_1_trusts`), sent from a participant already discovered and matched on SEDP:
//! each is refused or handled arithmetically and counted, the participant's heap stays small,
//! and it goes on discovering and delivering afterwards.

#[allow(dead_code)] // each test binary uses a part of it
mod pair;

use std::alloc::{GlobalAlloc, Layout, System};
use std::net::SocketAddr;
use std::sync::atomic::{AtomicUsize, Ordering};

use rtps_proto::Time;
use rtps_proto::discovery::Qos;
use rtps_proto::participant::{Destination, Event, Participant};
use rtps_proto::wire::WireErrorKind;

/// Counts live heap bytes and their peak, of the whole process: each test measures with the
/// others waiting ([`one_at_a_time`]), or it would count their heap too.
struct Counting;
static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let live = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
        PEAK.fetch_max(live, Ordering::Relaxed);
        // SAFETY: the caller's layout, passed on.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        // SAFETY: `ptr` came from `alloc` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

use robowire_fixtures::rtps::hostile_datagrams as one_datagram_each;
use robowire_fixtures::wait::one_at_a_time;

#[test]
fn the_six_rustdds_datagrams_are_refused_or_bounded_and_the_participant_goes_on() {
    let _turn = one_at_a_time();
    let now = Time::from_nanos(1_000_000_000);
    let mut ours = Participant::new(pair::config(1), now);
    let mut attacker = Participant::new(pair::config(2), now);
    pair::exchange(now, &mut ours, &mut attacker);
    assert_eq!(ours.remote_participants().count(), 1, "the sender is a discovered, SEDP-matched participant");
    let source: SocketAddr = "127.0.0.1:7420".parse().unwrap();
    let before = ours.counters().clone();
    let baseline = LIVE.load(Ordering::Relaxed);
    PEAK.store(baseline, Ordering::Relaxed);
    for (what, datagram) in one_datagram_each([2; 12]) {
        ours.handle_datagram(now, source, Destination::Unicast, &datagram);
        let mut buf = vec![0u8; 65_536];
        // Whatever it answers, it answers within bounds.
        let mut answers = 0;
        while ours.poll_transmit(now, &mut buf).is_some() {
            answers += 1;
            assert!(answers < 100, "{what}: an answer without end");
        }
    }
    let peak = PEAK.load(Ordering::Relaxed) - baseline;
    assert!(peak < 512 * 1024, "the six datagrams took {peak} bytes of heap at the peak");
    let after = ours.counters();
    let wire = |k: WireErrorKind| after.wire.get(k) - before.wire.get(k);
    // Refused by the wire layer: set bounds and fragment number 0.
    assert_eq!(wire(WireErrorKind::FragmentNumberSet), 1, "NACK_FRAG fragment numbers");
    assert_eq!(wire(WireErrorKind::FragmentNumberZero), 1, "NACK_FRAG fragment number 0");
    assert_eq!(wire(WireErrorKind::SequenceNumberSet), 1, "sequence number overflow");
    // A DATA_FRAG from the SPDP writer: SPDP is never fragmented here, so nothing takes it.
    assert!(after.unmatched_source > before.unmatched_source, "DATA_FRAG sampleSize counted");
    // The HEARTBEAT of 2^40 samples and the GAP up to 2^40 reached the SEDP reader: handled by
    // arithmetic (the peak above), not by a table of their size.

    // It goes on: a newcomer is discovered and matched, and its samples arrive.
    let mut newcomer = Participant::new(pair::config(3), now);
    let w = newcomer.create_writer(now, "rt/lowstate", "T", Qos::default()).unwrap();
    ours.create_reader(now, "rt/lowstate", "T", Qos::default()).unwrap();
    pair::exchange(now, &mut ours, &mut newcomer);
    let mut buf = vec![0u8; 65_536];
    let t = newcomer.write(now, w, &[0, 1, 0, 0, 7, 7, 7, 7], &Default::default(), &mut buf).unwrap();
    ours.handle_datagram(now, source, Destination::Unicast, &buf[..t.transmit.expect("matched").len]);
    let got: Vec<_> = std::iter::from_fn(|| ours.poll_event())
        .filter_map(|e| match e {
            Event::Sample(s) => Some(s.payload),
            _ => None,
        })
        .collect();
    assert_eq!(got, vec![vec![0, 1, 0, 0, 7, 7, 7, 7]]);
}

#[test]
fn a_fragmented_sample_larger_than_the_limit_is_refused_before_any_allocation() {
    let _turn = one_at_a_time();
    let now = Time::from_nanos(1_000_000_000);
    let mut ours = Participant::new(pair::config(1), now);
    let mut peer = Participant::new(pair::config(2), now);
    let r = ours.create_reader(now, "big", "T", Qos::default()).unwrap();
    let w = peer.create_writer(now, "big", "T", Qos::default()).unwrap();
    pair::exchange(now, &mut ours, &mut peer);
    // A DATA_FRAG from the matched writer announcing a 4 GiB sample.
    let mut d = b"RTPS\x02\x04\x01\x12".to_vec();
    d.extend([2u8; 12]);
    let mut body = vec![0, 0, 28, 0];
    body.extend(r.0);
    body.extend(w.0);
    body.extend([0, 0, 0, 0, 1, 0, 0, 0]); // sn 1
    body.extend(1u32.to_le_bytes());
    body.extend(1u16.to_le_bytes());
    body.extend(1024u16.to_le_bytes());
    body.extend(0xFFFF_FFF0u32.to_le_bytes());
    body.extend([0u8; 1024]);
    d.extend([0x16, 0x01]);
    d.extend((body.len() as u16).to_le_bytes());
    d.extend(body);
    let baseline = LIVE.load(Ordering::Relaxed);
    PEAK.store(baseline, Ordering::Relaxed);
    ours.handle_datagram(now, "127.0.0.1:7420".parse().unwrap(), Destination::Unicast, &d);
    assert!(PEAK.load(Ordering::Relaxed) - baseline < 64 * 1024);
    assert_eq!(ours.reader_counters(r).unwrap().refused_fragments, 1);
}

/// A DATA_FRAG of fragment 1 from `writer` (of participant `prefix`) to `reader`, sample `sn`,
/// announcing a sample of `size` bytes in 1024-byte fragments.
fn small_frag(prefix: [u8; 12], reader: [u8; 4], writer: [u8; 4], sn: u32, size: u32) -> Vec<u8> {
    let mut d = b"RTPS\x02\x04\x01\x12".to_vec();
    d.extend(prefix);
    let mut body = vec![0, 0, 28, 0];
    body.extend(reader);
    body.extend(writer);
    body.extend(0u32.to_le_bytes());
    body.extend(sn.to_le_bytes());
    body.extend(1u32.to_le_bytes());
    body.extend(1u16.to_le_bytes());
    body.extend(1024u16.to_le_bytes());
    body.extend(size.to_le_bytes());
    body.extend([0u8; 1024]);
    d.extend([0x16, 0x01]);
    d.extend((body.len() as u16).to_le_bytes());
    d.extend(body);
    d
}

#[test]
fn small_fragments_of_many_writers_hold_no_more_than_the_reassembly_budget() {
    let _turn = one_at_a_time();
    let now = Time::from_nanos(1_000_000_000);
    let mut ours = Participant::new(pair::config(1), now);
    let mut peer = Participant::new(pair::config(2), now);
    let readers: Vec<_> =
        (0..4).map(|i| ours.create_reader(now, &format!("t{i}"), "T", Qos::default()).unwrap()).collect();
    let writers: Vec<_> =
        (0..4).map(|i| peer.create_writer(now, &format!("t{i}"), "T", Qos::default()).unwrap()).collect();
    pair::exchange(now, &mut ours, &mut peer);
    let source: SocketAddr = "127.0.0.1:7420".parse().unwrap();
    let baseline = LIVE.load(Ordering::Relaxed);
    PEAK.store(baseline, Ordering::Relaxed);
    // 4 writers × 8 samples in reassembly × 1 MiB each would be 32 MiB.
    for (r, w) in readers.iter().zip(&writers) {
        for sn in 1..=8 {
            let d = small_frag([2; 12], r.0, w.0, sn, 1024 * 1024);
            ours.handle_datagram(now, source, Destination::Unicast, &d);
        }
    }
    let peak = PEAK.load(Ordering::Relaxed) - baseline;
    let budget = rtps_proto::Limits::default().reassembly_bytes_total;
    assert!(peak <= budget + 256 * 1024, "{peak} bytes held, the budget is {budget}");
    let dropped: u64 = readers.iter().map(|r| ours.reader_counters(*r).unwrap().dropped_at_limit).sum();
    assert_eq!(dropped, 32 - 8, "what exceeds the budget is dropped and counted");
}
