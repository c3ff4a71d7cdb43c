//! The blocking waits of every class: the GIL released, Ctrl-C honoured. The facades open, latch
//! and close on the caller's thread and run their own threads; what is left here is waiting for
//! a future (a state, a service's answer) with a timer, on a runtime with no thread of its own:
//! the waiting caller drives it (importing `robowire` starts nothing).

use std::future::Future;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use pyo3::prelude::*;

use crate::errors::{Kind, error};

/// How long a blocking wait runs without looking for a signal (Ctrl-C).
const SIGNAL_SLICE: Duration = Duration::from_millis(50);

static TIMER: OnceLock<tokio::runtime::Runtime> = OnceLock::new();

/// A timer-only runtime, made on first use; whichever thread waits drives it (several may at
/// once).
fn timer() -> PyResult<&'static tokio::runtime::Runtime> {
    if let Some(runtime) = TIMER.get() {
        return Ok(runtime);
    }
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_time()
        .build()
        .map_err(|e| error(Kind::Error, format!("cannot make robowire's timer: {e}")))?;
    // Two threads racing here: the loser's runtime is dropped unused.
    Ok(TIMER.get_or_init(|| runtime))
}

/// Waits for `future` up to `timeout` (`None`: for ever) with the GIL released, looking for
/// signals every 50 ms: Ctrl-C raises `KeyboardInterrupt` here. `None` when the time ran out.
pub(crate) fn wait<F>(py: Python<'_>, timeout: Option<Duration>, future: F) -> PyResult<Option<F::Output>>
where
    F: Future + Send,
    F::Output: Send,
{
    let timer = timer()?;
    let mut future = std::pin::pin!(future);
    wait_sliced(py, timeout, |slice| timer.block_on(async { tokio::time::timeout(slice, future.as_mut()).await.ok() }))
}

/// Calls `attempt(slice)` with the GIL released until it returns `Some` or `timeout` has passed
/// (`None`: no limit); each slice at most 50 ms, signals checked between slices.
pub(crate) fn wait_sliced<T: Send>(
    py: Python<'_>,
    timeout: Option<Duration>,
    mut attempt: impl FnMut(Duration) -> Option<T> + Send,
) -> PyResult<Option<T>> {
    let deadline = timeout.map(|t| Instant::now() + t);
    loop {
        let slice = match deadline {
            Some(deadline) => deadline.saturating_duration_since(Instant::now()).min(SIGNAL_SLICE),
            None => SIGNAL_SLICE,
        };
        if let Some(value) = py.detach(|| attempt(slice)) {
            return Ok(Some(value));
        }
        py.check_signals()?;
        if deadline.is_some_and(|deadline| Instant::now() >= deadline) {
            return Ok(None);
        }
    }
}

/// A duration argument in seconds: finite and not negative, else `ArgumentError`.
pub(crate) fn seconds(name: &str, value: f64) -> PyResult<Duration> {
    if (0.0..=1e9).contains(&value) {
        Ok(Duration::from_secs_f64(value))
    } else {
        Err(error(Kind::Argument, format!("{name} = {value} s: a duration must be finite and between 0 and 1e9 s")))
    }
}

/// An optional timeout in seconds (`None`: no limit).
pub(crate) fn timeout(name: &str, value: Option<f64>) -> PyResult<Option<Duration>> {
    value.map(|v| seconds(name, v)).transpose()
}
