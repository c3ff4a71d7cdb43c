//! Loop-timing statistics: how late periodic work ran against its absolute deadlines.
//!
//! Every robowire loop (100 Hz chassis stream, 500 Hz UDP heartbeat, 1 kHz shared-memory
//! handshake) records its lateness here; demos and benches print the summaries.

/// The last `N` lateness samples, in µs, with exact percentiles over them.
///
/// Recording is O(1) and never allocates; [`summary`](Self::summary) sorts a stack copy, so call
/// it from a reporting path, not from the loop.
#[derive(Debug, Clone)]
pub struct LatenessRing<const N: usize> {
    samples: [u32; N],
    next: usize,
    len: usize,
    total: u64,
    max_us: u32,
}

/// Percentiles of the recorded lateness, µs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LatenessSummary {
    /// Samples recorded since the start (not only those in the ring).
    pub count: u64,
    /// Median over the ring.
    pub p50_us: u32,
    /// 99th percentile over the ring.
    pub p99_us: u32,
    /// Largest sample since the start.
    pub max_us: u32,
}

impl<const N: usize> Default for LatenessRing<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> LatenessRing<N> {
    /// An empty ring.
    pub const fn new() -> Self {
        Self { samples: [0; N], next: 0, len: 0, total: 0, max_us: 0 }
    }

    /// Records one sample, µs.
    pub fn record(&mut self, lateness_us: u32) {
        if N == 0 {
            return;
        }
        self.samples[self.next] = lateness_us;
        self.next = (self.next + 1) % N;
        self.len = (self.len + 1).min(N);
        self.total += 1;
        self.max_us = self.max_us.max(lateness_us);
    }

    /// Count, p50, p99 (nearest rank) and max.
    pub fn summary(&self) -> LatenessSummary {
        let mut sorted = self.samples;
        LatenessSummary::of_window(&mut sorted[..self.len], self.total, self.max_us)
    }
}

impl LatenessSummary {
    /// The summary of a window of samples (sorted in place), with the total count and the
    /// maximum since the start. For rings kept elsewhere (a lock-free one, say).
    pub fn of_window(window: &mut [u32], count: u64, max_us: u32) -> Self {
        window.sort_unstable();
        let rank = |p: usize| -> u32 {
            if window.is_empty() {
                0
            } else {
                // Nearest-rank percentile: the smallest sample with at least p % at or below it.
                let index = (p * window.len()).div_ceil(100).saturating_sub(1);
                window[index.min(window.len() - 1)]
            }
        };
        Self { count, p50_us: rank(50), p99_us: rank(99), max_us }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_over_the_window() {
        let mut ring: LatenessRing<100> = LatenessRing::new();
        assert_eq!(ring.summary(), LatenessSummary::default());
        for v in (1..=100).rev() {
            ring.record(v);
        }
        assert_eq!(ring.summary(), LatenessSummary { count: 100, p50_us: 50, p99_us: 99, max_us: 100 });
        // The window slides; max and count cover everything.
        for _ in 0..100 {
            ring.record(7);
        }
        assert_eq!(ring.summary(), LatenessSummary { count: 200, p50_us: 7, p99_us: 7, max_us: 100 });
    }
}
