//! Timing helpers shared by the latency benches of several crates (included with
//! `#[path = "../../../benches/timing.rs"] mod timing;`).
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

/// p50 and p99 of `samples` (nearest rank), ns.
pub(crate) fn percentiles(mut samples: Vec<u64>) -> (u64, u64) {
    samples.sort_unstable();
    let n = samples.len();
    (samples[n / 2], samples[(n * 99).div_ceil(100) - 1])
}

/// Pins the calling thread to `cpu`; threads it spawns afterwards inherit the pinning.
///
/// Latency benches put the client side on one CPU and the peer (echo thread, simulator) on
/// the other, as between a computer and its robot: unpinned, whether two threads happen to
/// share a vCPU decides a loopback round trip on a VM and a comparison would measure the
/// scheduler's luck.
pub(crate) fn pin(cpu: usize) {
    robowire_rt::pin_current_thread(cpu).expect("pinning a bench thread (needs 2 CPUs)");
}

/// Runs `f` on a new thread pinned to `cpu` and returns its result; threads `f` spawns (a
/// simulator's) stay on `cpu`.
pub(crate) fn on_cpu<T: Send>(cpu: usize, f: impl FnOnce() -> T + Send) -> T {
    std::thread::scope(|scope| {
        scope
            .spawn(|| {
                pin(cpu);
                f()
            })
            .join()
            .expect("the pinned thread panicked")
    })
}
