//! Statistics out of a stream thread without blocking it: counters and a lateness ring made of
//! atomics, written by the stream thread with relaxed stores, read (copied and sorted) by any
//! other thread.

use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};

use robowire_core::timing::LatenessSummary;

/// The last `N` samples of a loop's lateness, µs, with one writer (the loop) and any number of
/// readers. Recording is two relaxed stores; [`summary`](Self::summary) copies the ring and
/// sorts the copy on the reader's thread. A summary taken while the loop records may mix a
/// sample of the next round into the window: statistics, not a log.
#[derive(Debug)]
pub struct SharedLateness<const N: usize> {
    samples: [AtomicU32; N],
    /// Samples recorded since the start.
    count: AtomicU64,
    max_us: AtomicU32,
}

impl<const N: usize> Default for SharedLateness<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> SharedLateness<N> {
    /// An empty ring.
    pub const fn new() -> Self {
        Self { samples: [const { AtomicU32::new(0) }; N], count: AtomicU64::new(0), max_us: AtomicU32::new(0) }
    }

    /// Records one sample, µs. One writer at a time (the loop's thread).
    pub fn record(&self, lateness_us: u32) {
        if N == 0 {
            return;
        }
        let count = self.count.load(Ordering::Relaxed);
        self.samples[(count % N as u64) as usize].store(lateness_us, Ordering::Relaxed);
        self.max_us.fetch_max(lateness_us, Ordering::Relaxed);
        self.count.store(count + 1, Ordering::Release);
    }

    /// Count, p50, p99 (nearest rank over the window) and max.
    pub fn summary(&self) -> LatenessSummary {
        let count = self.count.load(Ordering::Acquire);
        let len = usize::try_from(count).unwrap_or(usize::MAX).min(N);
        let mut window: Vec<u32> = self.samples[..len].iter().map(|s| s.load(Ordering::Relaxed)).collect();
        LatenessSummary::of_window(&mut window, count, self.max_us.load(Ordering::Relaxed))
    }
}

/// A counter written by one thread and read by any, relaxed.
#[derive(Debug, Default)]
pub struct Counter(AtomicU64);

impl Counter {
    /// Adds `n`.
    pub fn add(&self, n: u64) {
        self.0.fetch_add(n, Ordering::Relaxed);
    }

    /// Sets the value (for a counter mirrored from a single writer's own count).
    pub fn set(&self, value: u64) {
        self.0.store(value, Ordering::Relaxed);
    }

    /// The value now.
    pub fn get(&self) -> u64 {
        self.0.load(Ordering::Relaxed)
    }
}

/// A duration in µs, saturating at `u32::MAX` (71 minutes), for lateness samples.
pub fn micros(d: std::time::Duration) -> u32 {
    u32::try_from(d.as_micros()).unwrap_or(u32::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_over_the_window_from_another_thread() {
        let ring: std::sync::Arc<SharedLateness<100>> = std::sync::Arc::new(SharedLateness::new());
        assert_eq!(ring.summary(), LatenessSummary::default());
        let writer = {
            let ring = ring.clone();
            std::thread::spawn(move || (1..=100).rev().for_each(|v| ring.record(v)))
        };
        writer.join().unwrap();
        assert_eq!(ring.summary(), LatenessSummary { count: 100, p50_us: 50, p99_us: 99, max_us: 100 });
        (0..100).for_each(|_| ring.record(7));
        assert_eq!(ring.summary(), LatenessSummary { count: 200, p50_us: 7, p99_us: 7, max_us: 100 });
    }
}
