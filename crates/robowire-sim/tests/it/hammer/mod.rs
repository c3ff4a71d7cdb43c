//! A simulator's public API called in a loop from another thread while the test watches its
//! stream: what the handle does must never hold the stream up.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc;
use std::time::Duration;

/// Runs `watch` on this thread while another thread calls `api` in a loop: `watch` starts once
/// `api` has returned from a first call (so the two overlap however the threads are scheduled),
/// and `api` is called until `watch` returns. `watch`'s result.
pub(crate) fn while_hammering<T>(api: impl Fn() + Sync, watch: impl FnOnce() -> T) -> T {
    let (stop, calls) = (AtomicBool::new(false), AtomicU64::new(0));
    let (first_call, first_call_done) = mpsc::channel();
    std::thread::scope(|scope| {
        scope.spawn(|| {
            while !stop.load(Ordering::Relaxed) {
                api();
                if calls.fetch_add(1, Ordering::Relaxed) == 0 {
                    let _ = first_call.send(());
                }
            }
        });
        // A failure bound only: the first call returns at once when the handle works.
        let started = first_call_done.recv_timeout(Duration::from_secs(10));
        if started.is_err() {
            stop.store(true, Ordering::Relaxed);
            panic!("the simulator's API did not return from a first call within 10 s");
        }
        let watched = watch();
        stop.store(true, Ordering::Relaxed);
        watched
    })
}
