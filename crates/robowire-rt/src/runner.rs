//! The one runner: a thread that turns a sans-IO schedule into actions on time.
//!
//! A [`Job`] says when it wants to run next (a deadline on the monotonic clock) and does what is
//! due when run; the [`Runner`] thread sleeps until the deadline and runs it. The wait is coarse
//! then precise: the thread parks (a futex wait, wakeable by a [`Waker`]) until [`RunnerOptions::spin`]
//! before the deadline, then spins on the clock. The thread's timer slack is set to 1 ns, so the
//! coarse phase ends within the kernel's wake-up latency instead of the default 50 µs slack;
//! the spin absorbs that latency. Optional `SCHED_FIFO` priority, CPU pinning and `mlockall`.
//!
//! A runner started with [`Runner::spawn_polling`] also runs its job as soon as one of the job's
//! file descriptors (a socket) has something to read: it waits in `poll(2)` instead of parking,
//! so that a datagram is handled on the runner's thread without a hand-over to it.
//!
//! ```
//! use std::time::Duration;
//! use robowire_core::schedule::{Periodic, Time};
//! use robowire_rt::runner::{Job, Runner, RunnerOptions};
//!
//! /// Ten ticks at 1 kHz, then done.
//! struct Ten { grid: Periodic, late_us: Vec<u128> }
//! impl Job for Ten {
//!     fn next_run(&mut self) -> Option<Time> {
//!         (self.grid.ticks() < 10).then(|| self.grid.deadline())
//!     }
//!     fn run(&mut self, now: Time) {
//!         if let Some(tick) = self.grid.poll(now) {
//!             self.late_us.push(tick.lateness.as_micros());
//!         }
//!     }
//! }
//!
//! let job = Ten { grid: Periodic::new(robowire_rt::now(), Duration::from_millis(1)), late_us: Vec::new() };
//! let done = Runner::spawn(RunnerOptions::named("ten"), job)?.join().expect("the job");
//! assert_eq!(done.late_us.len(), 10);
//! # Ok::<(), robowire_rt::RtError>(())
//! ```

mod poll;
#[cfg(test)]
mod tests;

use std::os::fd::OwnedFd;
use std::os::unix::net::UnixDatagram;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::{JoinHandle, Thread};
use std::time::Duration;

use robowire_core::schedule::Time;

use crate::{Placement, RtError, now};
use poll::Readable;

/// Periodic work for a [`Runner`].
pub trait Job: Send + 'static {
    /// When to run next: a deadline on the monotonic clock ([`now`]); one in the past means at
    /// once; `None` ends the thread (the job is done).
    fn next_run(&mut self) -> Option<Time>;

    /// Does what is due at `now`. Called at (just after) the deadline, or earlier when a
    /// [`Waker`] woke the thread or, on a [`Runner::spawn_polling`] runner, when one of its file
    /// descriptors has something to read.
    fn run(&mut self, now: Time);
}

/// How a runner's thread is set up.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RunnerOptions {
    /// The thread's name.
    pub name: String,
    /// Priority, CPU and memory lock.
    pub placement: Placement,
    /// The last part of every wait, spent spinning on the clock. Default [`DEFAULT_SPIN`].
    pub spin: Duration,
}

/// The spin at the end of each wait: long enough to absorb the wake-up latency of a parked
/// thread on a VM (measured by `cargo xtask bench` at 0–150 µs: below ~60 µs the p99 lateness
/// follows the wake-up latency, at 100 µs it is a few tens of µs), short enough to cost little
/// CPU (5 % of a core at 500 Hz).
pub const DEFAULT_SPIN: Duration = Duration::from_micros(100);

impl RunnerOptions {
    /// Normal scheduling, no pinning, the default spin.
    pub fn named(name: impl Into<String>) -> Self {
        Self::placed(name, Placement::default())
    }

    /// `placement`, the default spin.
    pub fn placed(name: impl Into<String>, placement: Placement) -> Self {
        Self { name: name.into(), placement, spin: DEFAULT_SPIN }
    }
}

#[derive(Debug, Default)]
struct Control {
    stop: AtomicBool,
    woken: AtomicBool,
    /// A polling runner's end of its wake socket pair: a datagram sent on it ends the thread's
    /// `poll(2)`.
    wake: Option<UnixDatagram>,
}

impl Control {
    /// What is left of a wait until `deadline`; `None` once it is over (woken, stopping, due).
    fn left_until(&self, deadline: Time) -> Option<Duration> {
        if self.woken.swap(false, Ordering::AcqRel) || self.stop.load(Ordering::Acquire) {
            return None;
        }
        Some(deadline.saturating_duration_since(now())).filter(|left| !left.is_zero())
    }

    /// Ends the thread's wait, parked or polling.
    fn notify(&self, thread: &Thread) {
        thread.unpark();
        if let Some(wake) = &self.wake {
            // Non-blocking: a full socket already holds a wake-up.
            let _ = wake.send(&[1]);
        }
    }
}

/// Wakes a runner's thread early: its job runs at once (to send a stop, say). Cheap to clone,
/// usable from any thread; never blocks.
#[derive(Debug, Clone)]
pub struct Waker {
    control: Arc<Control>,
    thread: Thread,
}

impl Waker {
    /// The job runs as soon as the thread is scheduled.
    pub fn wake(&self) {
        self.control.woken.store(true, Ordering::Release);
        self.control.notify(&self.thread);
    }
}

/// A thread running a [`Job`] on time; see the [module](self).
pub struct Runner<J: Job> {
    thread: Option<JoinHandle<J>>,
    waker: Waker,
}

impl<J: Job> std::fmt::Debug for Runner<J> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Runner").field("thread", &self.waker.thread.name()).finish_non_exhaustive()
    }
}

impl<J: Job> Runner<J> {
    /// Starts the thread: placement first (an error there is returned, and the thread ends),
    /// then the loop.
    pub fn spawn(options: RunnerOptions, job: J) -> Result<Self, RtError> {
        Self::start(options, job, Control::default(), None)
    }

    /// Starts the thread as [`spawn`](Self::spawn) does; the job also runs as soon as one of
    /// `readable` has something to read (or an error to report). The thread waits in `poll(2)`
    /// on them until [`RunnerOptions::spin`] before the deadline, then spins with a non-blocking
    /// look at them. The job reads them without blocking; what it leaves unread runs it again at
    /// once.
    pub fn spawn_polling(options: RunnerOptions, job: J, readable: Vec<OwnedFd>) -> Result<Self, RtError> {
        let wake_error = |source| RtError::Wake { name: options.name.clone(), source };
        let (wake, woken) = UnixDatagram::pair().map_err(wake_error)?;
        wake.set_nonblocking(true).map_err(wake_error)?;
        woken.set_nonblocking(true).map_err(wake_error)?;
        let control = Control { wake: Some(wake), ..Control::default() };
        Self::start(options, job, control, Some(Readable::new(woken, readable)))
    }

    fn start(
        options: RunnerOptions,
        mut job: J,
        control: Control,
        readable: Option<Readable>,
    ) -> Result<Self, RtError> {
        let control = Arc::new(control);
        let (placed_tx, placed) = std::sync::mpsc::sync_channel(1);
        let name = options.name.clone();
        let thread = std::thread::Builder::new()
            .name(name.clone())
            .spawn({
                let control = control.clone();
                move || {
                    let placement = options.placement.apply();
                    let ok = placement.is_ok();
                    let _ = placed_tx.send(placement);
                    if ok {
                        match readable {
                            None => run(&mut job, &control, |deadline| wait_until(deadline, options.spin, &control)),
                            Some(readable) => readable.run(&mut job, &control, options.spin),
                        }
                    }
                    job
                }
            })
            .map_err(|source| RtError::Thread { name, source })?;
        let waker = Waker { control, thread: thread.thread().clone() };
        let placement = placed.recv().unwrap_or_else(|_| {
            Err(RtError::Thread { name: options_name(&thread), source: std::io::Error::other("died while starting") })
        });
        let runner = Self { thread: Some(thread), waker };
        placement.map(|()| runner)
    }

    /// A waker for the thread.
    pub fn waker(&self) -> Waker {
        self.waker.clone()
    }

    /// Whether the job ended by itself (its `next_run` said `None`).
    pub fn is_finished(&self) -> bool {
        self.thread.as_ref().is_none_or(JoinHandle::is_finished)
    }

    /// Waits for the job to end by itself and returns it (`None` if it panicked).
    pub fn join(mut self) -> Option<J> {
        self.thread.take().and_then(|t| t.join().ok())
    }

    /// Ends the loop after the current run, without running the job again, and returns it.
    pub fn stop(mut self) -> Option<J> {
        self.request_stop();
        self.thread.take().and_then(|t| t.join().ok())
    }

    fn request_stop(&self) {
        self.waker.control.stop.store(true, Ordering::Release);
        self.waker.control.notify(&self.waker.thread);
    }
}

impl<J: Job> Drop for Runner<J> {
    fn drop(&mut self) {
        if let Some(thread) = self.thread.take() {
            self.request_stop();
            let _ = thread.join();
        }
    }
}

fn options_name<T>(thread: &JoinHandle<T>) -> String {
    thread.thread().name().unwrap_or_default().to_string()
}

/// The loop: `wait` until each deadline (or less), then the job.
fn run<J: Job>(job: &mut J, control: &Control, mut wait: impl FnMut(Time)) {
    while !control.stop.load(Ordering::Acquire) {
        let Some(deadline) = job.next_run() else { return };
        wait(deadline);
        if control.stop.load(Ordering::Acquire) {
            return;
        }
        job.run(now());
    }
}

/// Parks until `spin` before `deadline` (or a wake), then spins until it.
fn wait_until(deadline: Time, spin: Duration, control: &Control) {
    loop {
        let Some(left) = control.left_until(deadline) else { return };
        if left > spin {
            std::thread::park_timeout(left - spin);
        } else {
            spin_until(deadline, || control.woken.load(Ordering::Acquire));
            return;
        }
    }
}

fn spin_until(deadline: Time, interrupted: impl Fn() -> bool) {
    while now() < deadline && !interrupted() {
        std::hint::spin_loop();
    }
}

/// Sleeps until `deadline` the runner's way (coarse sleep, then `spin` of spinning on the
/// clock), for loops that are not a [`Job`]. Set the timer slack first
/// ([`set_fine_timer_slack`](crate::set_fine_timer_slack)) for the coarse phase to be tight.
pub fn sleep_until(deadline: Time, spin: Duration) {
    let left = deadline.saturating_duration_since(now());
    if left > spin {
        std::thread::sleep(left - spin);
    }
    spin_until(deadline, || false);
}
