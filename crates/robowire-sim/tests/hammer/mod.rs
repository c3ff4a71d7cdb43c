//! A simulator's public API called in a loop from another thread while the test watches its
//! stream: what the handle does must never hold the stream up.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// Runs `watch` on this thread while another thread calls `api` in a loop; `watch`'s result
/// and how many times `api` ran meanwhile.
pub(crate) fn while_hammering<T>(api: impl Fn() + Sync, watch: impl FnOnce() -> T) -> (T, u64) {
    let (stop, calls) = (AtomicBool::new(false), AtomicU64::new(0));
    std::thread::scope(|scope| {
        scope.spawn(|| {
            while !stop.load(Ordering::Relaxed) {
                api();
                calls.fetch_add(1, Ordering::Relaxed);
            }
        });
        let watched = watch();
        stop.store(true, Ordering::Relaxed);
        (watched, calls.load(Ordering::Relaxed))
    })
}
