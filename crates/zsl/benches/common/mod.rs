//! Timing helpers shared by the zsl benches.
// Each bench uses what it needs of this module.
#![allow(dead_code)]

use std::time::Instant;

/// Appends `n` individually timed calls of `f` to `samples` (after a short warm-up), ns.
pub(crate) fn time_each(samples: &mut Vec<u64>, n: usize, mut f: impl FnMut()) {
    for _ in 0..200 {
        f();
    }
    samples.extend((0..n).map(|_| {
        let start = Instant::now();
        f();
        start.elapsed().as_nanos() as u64
    }));
}

/// p50 and p99 of `samples`, ns.
pub(crate) fn percentiles(mut samples: Vec<u64>) -> (u64, u64) {
    samples.sort_unstable();
    let n = samples.len();
    (samples[n / 2], samples[(n * 99).div_ceil(100) - 1])
}
