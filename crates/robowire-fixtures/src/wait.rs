//! What tests wait with: polling until a condition holds within a bound (a failure names what
//! never happened), one test at a time where tests would share the two cores, and a runtime.

use std::sync::{Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};

/// How often [`until`] and [`until_async`] look.
const POLL: Duration = Duration::from_millis(1);

/// Polls `done` every millisecond until it holds; fails the test naming `what` after `within`.
#[track_caller]
pub fn until(within: Duration, what: &str, mut done: impl FnMut() -> bool) {
    let start = Instant::now();
    while !done() {
        assert!(start.elapsed() < within, "not within {within:?}: {what}");
        std::thread::sleep(POLL);
    }
}

/// As [`until`], in a task: sleeps on tokio's timer between looks.
pub async fn until_async(within: Duration, what: &str, mut done: impl FnMut() -> bool) {
    some_async(within, what, || done().then_some(())).await;
}

/// Polls `f` in a task until it gives a value; fails the test naming `what` after `within`.
pub async fn some_async<T>(within: Duration, what: &str, mut f: impl FnMut() -> Option<T>) -> T {
    let start = Instant::now();
    loop {
        if let Some(value) = f() {
            return value;
        }
        assert!(start.elapsed() < within, "not within {within:?}: {what}");
        tokio::time::sleep(POLL).await;
    }
}

/// One test of this binary at a time while the guard lives (two robots and their streams on two
/// cores would make each other late). A test that failed holding it does not fail the next.
pub fn one_at_a_time() -> MutexGuard<'static, ()> {
    static TURN: Mutex<()> = Mutex::new(());
    TURN.lock().unwrap_or_else(PoisonError::into_inner)
}

/// A current-thread runtime with timers and I/O, for a test body that awaits.
pub fn runtime() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_current_thread().enable_all().build().expect("a tokio runtime")
}

/// A runtime of two worker threads (one per core of the test machine).
pub fn runtime_two_workers() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().expect("a tokio runtime")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn until_returns_once_the_condition_holds() {
        let mut looks = 0;
        until(Duration::from_secs(5), "the third look", || {
            looks += 1;
            looks == 3
        });
        assert_eq!(looks, 3);
    }

    #[test]
    #[should_panic(expected = "not within 5ms: never")]
    fn until_fails_naming_what_never_happened() {
        until(Duration::from_millis(5), "never", || false);
    }

    #[test]
    fn some_async_gives_the_value() {
        let mut n = 0;
        let got = runtime().block_on(some_async(Duration::from_secs(5), "a value", || {
            n += 1;
            (n == 2).then_some(n)
        }));
        assert_eq!(got, 2);
    }

    #[test]
    fn a_failed_turn_does_not_fail_the_next() {
        let _ = std::thread::spawn(|| {
            let _turn = one_at_a_time();
            panic!("a test fails holding its turn");
        })
        .join();
        drop(one_at_a_time());
    }
}
