//! What a simulator's stream thread shares with its other threads, none of it a lock the stream
//! thread takes: every simulator owns its model on its stream thread and
//!
//! - takes requests from the public API (faults, settings) through [`Requests`], a bounded
//!   lock-free queue it drains each run, in order; the caller waits (on its own thread) until
//!   the stream thread applied its request and published the result;
//! - publishes what the API shows through [`Published`] (any `Clone` value: copies move by
//!   pointer between preallocated boxes, the writer never waits or allocates) or a
//!   [`robowire_rt::Latest`] seqlock (fixed layouts);
//! - counts its cycles, missed deadlines and lateness in [`StreamStats`] (atomics).
//!
//! Locks remain only among the other threads (API callers among themselves).

use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use crossbeam_queue::ArrayQueue;
#[cfg(any(feature = "zsl", feature = "go2", feature = "g1"))]
use robowire_core::{schedule::Tick, timing::LatenessSummary};
use robowire_rt::lock;
#[cfg(any(feature = "zsl", feature = "go2", feature = "g1"))]
use robowire_rt::stats::{Counter, SharedLateness, micros};

/// How long an API call waits for a stalled stream thread before it returns anyway (its request
/// stays queued, or is dropped if the queue stayed full).
const CALL_BOUND: Duration = Duration::from_secs(2);
/// How long a caller yields before it sleeps between looks: a running stream thread answers
/// within a wake-up.
const YIELD_FOR: Duration = Duration::from_micros(500);
/// A caller's sleep between looks after that.
const SLEEP_STEP: Duration = Duration::from_micros(50);

/// Requests from the public API to a stream thread: pushed in order (callers take turns), drained
/// by the stream thread without waiting, confirmed once their effect is published.
#[derive(Debug)]
pub(crate) struct Requests<R> {
    queue: ArrayQueue<R>,
    /// Requests pushed so far; callers hold it while they push, the stream thread never.
    submitted: Mutex<u64>,
    /// Requests the stream thread applied and published; written by the stream thread only.
    applied: AtomicU64,
}

/// Requests a stream thread took, to [`Requests::confirm`] once it published their effect.
#[derive(Debug)]
#[must_use = "confirm the requests once their effect is published"]
pub(crate) struct Taken(u64);

impl<R> Requests<R> {
    /// Room for `capacity` requests not yet taken.
    pub(crate) fn new(capacity: usize) -> Self {
        Self { queue: ArrayQueue::new(capacity), submitted: Mutex::new(0), applied: AtomicU64::new(0) }
    }

    /// Hands `request` over, calls `wake` (to run the stream thread at once) and waits until the
    /// stream thread has applied it and published the result. Never waits longer than
    /// [`CALL_BOUND`] (a stalled thread): then returns `false`.
    pub(crate) fn call(&self, request: R, wake: impl Fn()) -> bool {
        let start = Instant::now();
        let ticket = {
            let mut submitted = lock(&self.submitted);
            let mut request = request;
            loop {
                match self.queue.push(request) {
                    Ok(()) => break,
                    Err(back) if start.elapsed() < CALL_BOUND => {
                        request = back;
                        wake();
                        pause(start);
                    }
                    Err(_) => return false,
                }
            }
            *submitted += 1;
            *submitted
        };
        wake();
        while self.applied.load(Ordering::Acquire) < ticket {
            if start.elapsed() >= CALL_BOUND {
                return false;
            }
            pause(start);
        }
        true
    }

    /// The stream thread: applies every queued request, oldest first. Never waits.
    pub(crate) fn take(&self, mut apply: impl FnMut(R)) -> Taken {
        let mut taken = 0;
        while let Some(request) = self.queue.pop() {
            apply(request);
            taken += 1;
        }
        Taken(taken)
    }

    /// The stream thread: the requests of `taken` are applied and their effect published.
    pub(crate) fn confirm(&self, taken: Taken) {
        if taken.0 > 0 {
            self.applied.fetch_add(taken.0, Ordering::Release);
        }
    }
}

/// A caller's wait between looks: yield first, then short sleeps.
fn pause(start: Instant) {
    if start.elapsed() < YIELD_FOR {
        std::thread::yield_now();
    } else {
        std::thread::sleep(SLEEP_STEP);
    }
}

#[cfg(any(feature = "kmc", feature = "zsl"))]
/// Copies of a value a stream thread owns, published by it and read by any thread. The writer
/// takes a preallocated box from a free queue, copies into it and puts it in the one-place
/// "latest" queue, returning the box it displaced: no wait, no allocation (for values whose
/// `clone_from` allocates nothing). Readers take turns (a lock among readers only), take the
/// latest box, copy it and put it back, or free it if a newer one arrived meanwhile.
#[derive(Debug)]
pub(crate) struct Published<T> {
    /// Boxes not in use: at most one is the writer's, one a reader's, one the latest.
    free: ArrayQueue<Box<T>>,
    latest: ArrayQueue<Box<T>>,
    /// The copy readers make; readers hold it while they read, the writer never.
    read: Mutex<T>,
}

/// Boxes a [`Published`] needs: the latest, the one the writer fills, the one a reader copies.
#[cfg(any(feature = "kmc", feature = "zsl"))]
const PUBLISHED_BOXES: usize = 3;

#[cfg(any(feature = "kmc", feature = "zsl"))]
impl<T: Clone> Published<T> {
    /// `initial` published.
    pub(crate) fn new(initial: &T) -> Self {
        let free = ArrayQueue::new(PUBLISHED_BOXES);
        for _ in 1..PUBLISHED_BOXES {
            let _ = free.push(Box::new(initial.clone()));
        }
        let latest = ArrayQueue::new(1);
        let _ = latest.push(Box::new(initial.clone()));
        Self { free, latest, read: Mutex::new(initial.clone()) }
    }

    /// The writer (one thread): publishes a copy of `value`. Never waits.
    pub(crate) fn publish(&self, value: &T) {
        // Three boxes: with the latest and a reader's taken, one is free.
        let Some(mut spare) = self.free.pop() else { return };
        spare.as_mut().clone_from(value);
        if let Some(displaced) = self.latest.force_push(spare) {
            let _ = self.free.push(displaced);
        }
    }

    /// The latest value published.
    pub(crate) fn read(&self) -> T {
        let mut read = lock(&self.read);
        if let Some(latest) = self.latest.pop() {
            read.clone_from(&latest);
            if let Err(latest) = self.latest.push(latest) {
                // The writer published a newer one meanwhile.
                let _ = self.free.push(latest);
            }
        }
        read.clone()
    }
}

/// A periodic stream's own statistics, written by its thread with relaxed stores.
#[cfg(any(feature = "zsl", feature = "go2", feature = "g1"))]
#[derive(Debug, Default)]
pub(crate) struct StreamStats<const N: usize> {
    cycles: Counter,
    missed: Counter,
    lateness: SharedLateness<N>,
}

/// What a [`StreamStats`] counted.
#[cfg(any(feature = "zsl", feature = "go2", feature = "g1"))]
#[derive(Debug, Clone, Copy)]
#[cfg_attr(not(feature = "zsl"), expect(dead_code, reason = "the Go2's snapshot shows the lateness only"))]
pub(crate) struct StreamSummary {
    /// Cycles run.
    pub(crate) cycles: u64,
    /// Deadlines skipped because a cycle ran more than a period late.
    pub(crate) missed: u64,
    /// Lateness of the cycles run against their deadlines, µs.
    pub(crate) lateness: LatenessSummary,
}

#[cfg(any(feature = "zsl", feature = "go2", feature = "g1"))]
impl<const N: usize> StreamStats<N> {
    /// A tick of the grid: the slots it skipped, and if the stream `served` it (ran its cycle),
    /// its lateness.
    pub(crate) fn record(&self, tick: &Tick, served: bool) {
        self.missed.add(tick.skipped);
        if served {
            self.lateness.record(micros(tick.lateness));
            self.cycles.add(1);
        }
    }

    /// The counts now.
    pub(crate) fn summary(&self) -> StreamSummary {
        StreamSummary { cycles: self.cycles.get(), missed: self.missed.get(), lateness: self.lateness.summary() }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;
    use std::sync::atomic::AtomicBool;

    use super::*;

    #[test]
    fn a_call_returns_once_its_request_is_applied_in_order() {
        let requests: Arc<Requests<u32>> = Arc::new(Requests::new(2));
        let applied = Arc::new(Mutex::new(Vec::new()));
        let stop = Arc::new(AtomicBool::new(false));
        let stream = std::thread::spawn({
            let (requests, applied, stop) = (requests.clone(), applied.clone(), stop.clone());
            move || {
                while !stop.load(Ordering::Relaxed) {
                    let mut seen = Vec::new();
                    let taken = requests.take(|r| seen.push(r));
                    lock(&applied).extend(seen);
                    requests.confirm(taken);
                    std::thread::yield_now();
                }
            }
        });
        for r in 0..100 {
            assert!(requests.call(r, || {}));
            assert_eq!(lock(&applied).last(), Some(&r), "applied when the call returns");
        }
        stop.store(true, Ordering::Relaxed);
        stream.join().unwrap();
        assert_eq!(*lock(&applied), (0..100).collect::<Vec<_>>());
    }

    #[test]
    fn a_call_to_a_stalled_stream_gives_up() {
        let requests: Requests<u32> = Requests::new(1);
        assert!(!requests.call(1, || {}), "queued, never applied");
        assert!(!requests.call(2, || {}), "the queue stayed full");
        let mut seen = Vec::new();
        let taken = requests.take(|r| seen.push(r));
        requests.confirm(taken);
        assert_eq!(seen, [1]);
    }

    #[test]
    #[cfg(any(feature = "kmc", feature = "zsl"))]
    fn readers_see_the_latest_while_the_writer_never_waits() {
        let published = Arc::new(Published::new(&vec![0u64; 4]));
        let done = Arc::new(AtomicBool::new(false));
        let readers: Vec<_> = (0..2)
            .map(|_| {
                let (published, done) = (published.clone(), done.clone());
                std::thread::spawn(move || {
                    let mut last = 0;
                    while !done.load(Ordering::Relaxed) {
                        let value = published.read();
                        assert!(value.iter().all(|v| *v == value[0]), "a whole copy: {value:?}");
                        assert!(value[0] >= last, "never older than what was read before");
                        last = value[0];
                    }
                })
            })
            .collect();
        let mut value = vec![0u64; 4];
        for n in 1..=20_000 {
            value.fill(n);
            published.publish(&value);
        }
        done.store(true, Ordering::Relaxed);
        readers.into_iter().for_each(|r| r.join().unwrap());
        assert_eq!(published.read(), vec![20_000; 4]);
    }
}
