#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod links;

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use crossbeam_queue::ArrayQueue;
pub use links::{LinkRegistry, RecordLinks};
pub use robowire_core::Direction;

/// Bytes one slot holds: the largest frame robowire records, a Unitree HG `LowState_` DDS
/// payload (2100 bytes in XCDR2, 2092 in XCDR1), with room to spare. A Go2 `LowState_` is 1188,
/// a ZSL-1 HighLevel state 560, a KMC frame at most 84. A longer frame is counted
/// ([`TapCounters::oversize`]), never recorded in part.
pub const SLOT_BYTES: usize = 2304;

/// A slot's bytes.
type Slot = Box<[u8; SLOT_BYTES]>;

/// What a middleware says of a sample besides its bytes (DDS: the writer's GUID, the source
/// timestamp); nothing for links that say nothing (serial, UDP, shared memory).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SampleOrigin {
    /// The GUID of the writer that published it (RTPS: 12-byte prefix, 4-byte entity id).
    pub writer: Option<[u8; 16]>,
    /// When its writer published it by the writer's clock (DDS source timestamp): Unix time, ns.
    pub source_unix_ns: Option<u64>,
}

impl SampleOrigin {
    /// Nothing known besides the bytes.
    pub const NONE: Self = Self { writer: None, source_unix_ns: None };
}

/// One frame as it was on the wire, in its slot.
pub struct TappedFrame {
    /// The link, as the recorder numbered it.
    pub link: u16,
    /// Sent or received.
    pub direction: Direction,
    /// When the tap took it: `CLOCK_MONOTONIC`, ns ([`robowire_rt::monotonic_ns`]).
    pub monotonic_ns: u64,
    /// What the middleware said of it.
    pub origin: SampleOrigin,
    len: u16,
    slot: Slot,
}

impl TappedFrame {
    /// The bytes, exactly.
    pub fn bytes(&self) -> &[u8] {
        &self.slot[..usize::from(self.len)]
    }
}

impl std::fmt::Debug for TappedFrame {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TappedFrame")
            .field("link", &self.link)
            .field("direction", &self.direction)
            .field("monotonic_ns", &self.monotonic_ns)
            .field("origin", &self.origin)
            .field("len", &self.len)
            .finish_non_exhaustive()
    }
}

/// What the taps of one ring did.
#[derive(Debug, Default)]
pub struct TapCounters {
    recorded: AtomicU64,
    dropped: AtomicU64,
    oversize: AtomicU64,
}

impl TapCounters {
    /// Frames put into the ring.
    pub fn recorded(&self) -> u64 {
        self.recorded.load(Ordering::Relaxed)
    }

    /// Frames dropped because the ring was full (the recorder fell behind) or closed.
    pub fn dropped(&self) -> u64 {
        self.dropped.load(Ordering::Relaxed)
    }

    /// Frames dropped because they are longer than a slot ([`SLOT_BYTES`]).
    pub fn oversize(&self) -> u64 {
        self.oversize.load(Ordering::Relaxed)
    }
}

/// The slots, each either free or holding a frame for the recorder: a frame moves between the
/// two queues by its slot's pointer, and only its own bytes are copied.
#[derive(Debug)]
struct Ring {
    free: ArrayQueue<Slot>,
    filled: ArrayQueue<TappedFrame>,
    counters: TapCounters,
    closed: AtomicBool,
}

/// A recorder's ring: preallocated slots of [`SLOT_BYTES`], filled by any number of [`Tap`]s
/// and emptied by the recorder, lock-free both ways (two of crossbeam's `ArrayQueue`s: the free
/// slots and the filled ones).
#[derive(Debug, Clone)]
pub struct TapRing {
    ring: Arc<Ring>,
}

impl TapRing {
    /// A ring of `slots` slots (at least one), every one allocated now: about
    /// `slots × (SLOT_BYTES + 48)` bytes.
    pub fn with_slots(slots: usize) -> Self {
        let slots = slots.max(1);
        let free = ArrayQueue::new(slots);
        for _ in 0..slots {
            let _ = free.push(Box::new([0; SLOT_BYTES]));
        }
        let ring =
            Ring { free, filled: ArrayQueue::new(slots), counters: TapCounters::default(), closed: false.into() };
        Self { ring: Arc::new(ring) }
    }

    /// A tap for link number `link`.
    pub fn tap(&self, link: u16) -> Tap {
        Tap { link, ring: self.ring.clone(), also: None }
    }

    /// Hands the oldest frame in the ring to `read`, then frees its slot; `None` if the ring
    /// is empty. Frames of one tap come out in the order it took them.
    pub fn pop<R>(&self, read: impl FnOnce(&TappedFrame) -> R) -> Option<R> {
        let frame = self.ring.filled.pop()?;
        let result = read(&frame);
        // Never full: there are as many places as slots.
        let _ = self.ring.free.push(frame.slot);
        Some(result)
    }

    /// The oldest frame in the ring, to keep as long as needed (another thread may decode it):
    /// its slot goes back to the ring when the [`HeldFrame`] is dropped. `None` if the ring is
    /// empty.
    pub fn take(&self) -> Option<HeldFrame> {
        let frame = self.ring.filled.pop()?;
        Some(HeldFrame { frame: Some(frame), ring: self.ring.clone() })
    }

    /// Frames in the ring now, waiting for the recorder.
    pub fn waiting(&self) -> usize {
        self.ring.filled.len()
    }

    /// Refuses frames from now on (each tap drops and counts them); those in the ring stay.
    pub fn close(&self) {
        self.ring.closed.store(true, Ordering::Release);
    }

    /// The counters of every tap of this ring.
    pub fn counters(&self) -> &TapCounters {
        &self.ring.counters
    }

    /// How many frames the ring holds at most.
    pub fn slots(&self) -> usize {
        self.ring.filled.capacity()
    }
}

/// A frame taken out of its ring ([`TapRing::take`]); its slot returns to the ring on drop.
pub struct HeldFrame {
    /// Always `Some` until dropped.
    frame: Option<TappedFrame>,
    ring: Arc<Ring>,
}

impl std::ops::Deref for HeldFrame {
    type Target = TappedFrame;
    fn deref(&self) -> &TappedFrame {
        // Only `drop` takes it out.
        self.frame.as_ref().unwrap_or_else(|| unreachable!("a held frame is taken only on drop"))
    }
}

impl std::fmt::Debug for HeldFrame {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.frame.fmt(f)
    }
}

impl Drop for HeldFrame {
    fn drop(&mut self) {
        if let Some(frame) = self.frame.take() {
            // Never full: there are as many places as slots.
            let _ = self.ring.free.push(frame.slot);
        }
    }
}

/// A link's tap: [`record`](Self::record) never blocks, allocates or reads the wall clock.
#[derive(Clone)]
pub struct Tap {
    link: u16,
    ring: Arc<Ring>,
    /// A tap of another ring that gets every frame too ([`and`](Self::and)).
    also: Option<Box<Tap>>,
}

impl std::fmt::Debug for Tap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Tap").field("link", &self.link).finish_non_exhaustive()
    }
}

/// Two taps are equal when they feed the same ring as the same link.
impl PartialEq for Tap {
    fn eq(&self, other: &Self) -> bool {
        self.link == other.link && Arc::ptr_eq(&self.ring, &other.ring) && self.also == other.also
    }
}

impl Eq for Tap {}

impl Tap {
    /// The link number.
    pub fn link(&self) -> u16 {
        self.link
    }

    /// Copies `bytes` into a slot of the ring, stamped now on the monotonic clock. A frame
    /// longer than [`SLOT_BYTES`] is counted as oversize; one that finds the ring full or closed
    /// is counted as dropped.
    pub fn record(&self, direction: Direction, bytes: &[u8]) {
        self.record_parts(direction, &[bytes], SampleOrigin::NONE);
    }

    /// This tap and `other` as one: every frame goes into both rings (a capture's and a live
    /// view's), each counting its own.
    pub fn and(self, other: Tap) -> Tap {
        let also = match self.also {
            Some(also) => also.and(other),
            None => other,
        };
        Tap { also: Some(Box::new(also)), ..self }
    }

    /// Counts a frame that was too long to record ([`TapCounters::oversize`]), for a caller that
    /// found so before copying it.
    pub fn count_oversize(&self) {
        self.ring.counters.oversize.fetch_add(1, Ordering::Relaxed);
        if let Some(also) = &self.also {
            also.count_oversize();
        }
    }

    /// As [`record`](Self::record), for a frame in `parts` (a DDS payload's encapsulation header
    /// and body, say) that the middleware says `origin` of.
    pub fn record_parts(&self, direction: Direction, parts: &[&[u8]], origin: SampleOrigin) {
        self.record_into_ring(direction, parts, origin);
        if let Some(also) = &self.also {
            also.record_parts(direction, parts, origin);
        }
    }

    fn record_into_ring(&self, direction: Direction, parts: &[&[u8]], origin: SampleOrigin) {
        let counters = &self.ring.counters;
        let total = parts.iter().map(|p| p.len()).fold(0usize, usize::saturating_add);
        let Some(len) = u16::try_from(total).ok().filter(|_| total <= SLOT_BYTES) else {
            counters.oversize.fetch_add(1, Ordering::Relaxed);
            return;
        };
        if self.ring.closed.load(Ordering::Acquire) {
            counters.dropped.fetch_add(1, Ordering::Relaxed);
            return;
        }
        let monotonic_ns = robowire_rt::monotonic_ns();
        let Some(mut slot) = self.ring.free.pop() else {
            counters.dropped.fetch_add(1, Ordering::Relaxed);
            return;
        };
        let mut at = 0;
        for part in parts {
            slot[at..at + part.len()].copy_from_slice(part);
            at += part.len();
        }
        let frame = TappedFrame { link: self.link, direction, monotonic_ns, origin, len, slot };
        match self.ring.filled.push(frame) {
            Ok(()) => counters.recorded.fetch_add(1, Ordering::Relaxed),
            // Never full: a filled frame holds one of the slots. Should it be, the slot goes back.
            Err(frame) => {
                let _ = self.ring.free.push(frame.slot);
                counters.dropped.fetch_add(1, Ordering::Relaxed)
            }
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_keep_their_link_direction_bytes_and_order() {
        let ring = TapRing::with_slots(8);
        let (a, b) = (ring.tap(1), ring.tap(2));
        a.record(Direction::Sent, &[1]);
        b.record(Direction::Received, &[2, 2]);
        let read = |f: &TappedFrame| (f.link, f.direction, f.bytes().to_vec(), f.monotonic_ns);
        let first = ring.pop(read).unwrap();
        let second = ring.pop(read).unwrap();
        assert!(ring.pop(read).is_none());
        assert_eq!(
            [&first, &second].map(|f| (f.0, f.1, f.2.clone())),
            [(1, Direction::Sent, vec![1]), (2, Direction::Received, vec![2, 2])]
        );
        assert!(first.3 <= second.3);
        assert_ne!(a, b);
        assert_eq!(a, a.clone());
    }

    #[test]
    fn a_full_ring_drops_and_an_oversize_frame_is_its_own_count() {
        let ring = TapRing::with_slots(2);
        let tap = ring.tap(0);
        for n in 0..5u8 {
            tap.record(Direction::Sent, &[n]);
        }
        tap.record(Direction::Sent, &[0; SLOT_BYTES + 1]);
        tap.record(Direction::Sent, &vec![0; usize::from(u16::MAX) + 1]);
        let c = ring.counters();
        assert_eq!((c.recorded(), c.dropped(), c.oversize()), (2, 3, 2));
        // The ring kept the first two: nothing is overwritten.
        let bytes = |f: &TappedFrame| f.bytes().to_vec();
        assert_eq!([ring.pop(bytes), ring.pop(bytes)], [Some(vec![0]), Some(vec![1])]);
        // Their slots are free again; a whole slot is not oversize, and a shorter frame in a
        // used slot is its own bytes only.
        tap.record(Direction::Sent, &[9; SLOT_BYTES]);
        tap.record(Direction::Sent, &[7; 3]);
        assert_eq!(ring.pop(bytes), Some(vec![9; SLOT_BYTES]));
        assert_eq!(ring.pop(bytes), Some(vec![7; 3]));
        assert_eq!(ring.counters().recorded(), 4);
    }

    #[test]
    fn a_tap_and_another_fill_both_rings_each_counting_its_own() {
        let (capture, live) = (TapRing::with_slots(4), TapRing::with_slots(1));
        let tap = capture.tap(3).and(live.tap(0));
        tap.record(Direction::Sent, &[1]);
        tap.record(Direction::Received, &[2]);
        tap.record(Direction::Sent, &[0; SLOT_BYTES + 1]);
        let read = |f: &TappedFrame| (f.link, f.direction, f.bytes().to_vec());
        assert_eq!(capture.pop(read), Some((3, Direction::Sent, vec![1])));
        assert_eq!(capture.pop(read), Some((3, Direction::Received, vec![2])));
        assert_eq!(live.pop(read), Some((0, Direction::Sent, vec![1])));
        assert!(live.pop(read).is_none());
        let counts = |r: &TapRing| (r.counters().recorded(), r.counters().dropped(), r.counters().oversize());
        assert_eq!((counts(&capture), counts(&live)), ((2, 0, 1), (1, 1, 1)));
    }

    #[test]
    fn a_closed_ring_drops_and_counts_but_keeps_what_it_holds() {
        let ring = TapRing::with_slots(4);
        let tap = ring.tap(1);
        tap.record(Direction::Received, &[1]);
        ring.close();
        tap.record(Direction::Received, &[2]);
        assert_eq!((ring.counters().recorded(), ring.counters().dropped()), (1, 1));
        assert_eq!(ring.pop(|f| f.bytes().to_vec()), Some(vec![1]));
        assert!(ring.pop(|_| ()).is_none());
    }

    #[test]
    fn several_threads_record_at_once_and_every_frame_is_counted_once() {
        const PER_THREAD: u32 = 20_000;
        let ring = TapRing::with_slots(64);
        let taps: Vec<Tap> = (0..3).map(|link| ring.tap(link)).collect();
        let stop = AtomicBool::new(false);
        let popped = std::thread::scope(|s| {
            let reader = s.spawn(|| {
                // Per link, what came out must be in the order it went in.
                let mut last = [None::<u32>; 3];
                let mut popped = 0u64;
                loop {
                    let done = stop.load(Ordering::Acquire);
                    while let Some((link, n)) =
                        ring.pop(|f| (f.link, u32::from_le_bytes(f.bytes().try_into().unwrap())))
                    {
                        let last = &mut last[usize::from(link)];
                        assert!(last.is_none_or(|l| l < n), "link {link}: {n} after {last:?}");
                        *last = Some(n);
                        popped += 1;
                    }
                    if done {
                        return popped;
                    }
                    std::thread::yield_now();
                }
            });
            let writers: Vec<_> = taps
                .iter()
                .map(|tap| s.spawn(move || (0..PER_THREAD).for_each(|n| tap.record(Direction::Sent, &n.to_le_bytes()))))
                .collect();
            writers.into_iter().for_each(|w| w.join().unwrap());
            stop.store(true, Ordering::Release);
            reader.join().unwrap()
        });
        let c = ring.counters();
        assert_eq!(c.recorded() + c.dropped(), 3 * u64::from(PER_THREAD));
        assert_eq!(popped, c.recorded());
        assert_eq!(c.oversize(), 0);
    }
}
