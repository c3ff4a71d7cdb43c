//! The one tokio runtime behind every client and simulator, started on first use (importing
//! `robowire` starts nothing), and the blocking waits: the GIL released, Ctrl-C honoured.

use std::future::Future;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use pyo3::prelude::*;

use crate::errors::{Kind, error};

/// How long a blocking wait runs without looking for a signal (Ctrl-C).
const SIGNAL_SLICE: Duration = Duration::from_millis(50);

static RUNTIME: OnceLock<tokio::runtime::Runtime> = OnceLock::new();

/// The runtime (one I/O thread, `robowire-io`), started on first use.
pub(crate) fn runtime() -> PyResult<&'static tokio::runtime::Runtime> {
    if let Some(runtime) = RUNTIME.get() {
        return Ok(runtime);
    }
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .thread_name("robowire-io")
        .enable_all()
        .build()
        .map_err(|e| error(Kind::Error, format!("cannot start robowire's I/O thread: {e}")))?;
    // Two threads racing here: the loser's runtime is dropped unused.
    Ok(RUNTIME.get_or_init(|| runtime))
}

/// Runs a future that does not wait on anything slow (binding a socket, starting a thread) to
/// completion on the runtime, with the GIL released.
pub(crate) fn block_on<F>(py: Python<'_>, future: F) -> PyResult<F::Output>
where
    F: Future + Send,
    F::Output: Send,
{
    let runtime = runtime()?;
    Ok(py.detach(|| runtime.block_on(future)))
}

/// Waits for `future` up to `timeout` (`None`: for ever) with the GIL released, looking for
/// signals every 50 ms: Ctrl-C raises `KeyboardInterrupt` here. `None` when the time ran out.
pub(crate) fn wait<F>(py: Python<'_>, timeout: Option<Duration>, future: F) -> PyResult<Option<F::Output>>
where
    F: Future + Send,
    F::Output: Send,
{
    let runtime = runtime()?;
    let mut future = std::pin::pin!(future);
    wait_sliced(py, timeout, |slice| {
        runtime.block_on(async { tokio::time::timeout(slice, future.as_mut()).await.ok() })
    })
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

/// Runs a future that normally completes at once (the facades' calls that only latch a
/// command) here, without a thread switch; on the runtime if it ever has to wait.
pub(crate) fn now<F>(py: Python<'_>, future: F) -> PyResult<F::Output>
where
    F: Future + Send,
    F::Output: Send,
{
    let mut future = std::pin::pin!(future);
    let mut context = std::task::Context::from_waker(std::task::Waker::noop());
    match future.as_mut().poll(&mut context) {
        std::task::Poll::Ready(output) => Ok(output),
        std::task::Poll::Pending => block_on(py, future),
    }
}
