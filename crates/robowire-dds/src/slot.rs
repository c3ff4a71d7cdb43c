//! A reader's slot: where the participant's background thread puts the reader's samples and
//! wakes its task or runs its listener.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use crossbeam_queue::ArrayQueue;
use futures::task::AtomicWaker;
use rtps_proto::participant::Sample as Arrived;

use crate::sample::Counters;

/// What a listened reader runs on the background thread: takes its slot's samples.
pub(crate) type Listen = Box<dyn FnMut() + Send>;

/// Where the background thread puts a reader's samples: the newest `depth` (keep last), and the
/// waker of the task that waits for them, or the listener that takes them on the background
/// thread.
pub(crate) struct ReaderSlot {
    queue: ArrayQueue<Arrived>,
    waker: AtomicWaker,
    counters: Arc<Counters>,
    /// A listener is installed: the background thread runs it instead of waking a task.
    listened: AtomicBool,
    /// Samples arrived that the listener has not been run for (the slot is in the background
    /// thread's list to run).
    due: AtomicBool,
    /// The listener; taken only by the background thread and by the [`Listener`](crate::reader::Listener)'s drop.
    listener: Mutex<Option<Listen>>,
}

impl std::fmt::Debug for ReaderSlot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ReaderSlot").field("kept", &self.queue.len()).finish_non_exhaustive()
    }
}

impl ReaderSlot {
    pub(crate) fn new(depth: usize, counters: Arc<Counters>) -> Self {
        Self {
            queue: ArrayQueue::new(depth.max(1)),
            waker: AtomicWaker::new(),
            counters,
            listened: AtomicBool::new(false),
            due: AtomicBool::new(false),
            listener: Mutex::new(None),
        }
    }

    /// Keeps `sample` (replacing the oldest when full: its buffer is returned) and wakes the
    /// reader's task; with a listener, whether the listener is to be run (the first sample since
    /// it last ran).
    pub(crate) fn push(&self, sample: Arrived) -> (Option<Vec<u8>>, bool) {
        let replaced = self.queue.force_push(sample).map(|old| {
            Counters::bump(&self.counters.dropped);
            old.payload
        });
        if self.listened.load(Ordering::Acquire) {
            return (replaced, !self.due.swap(true, Ordering::AcqRel));
        }
        self.waker.wake();
        (replaced, false)
    }

    /// The background thread, without the core's lock: runs the listener on what arrived.
    pub(crate) fn run_listener(&self) {
        self.due.store(false, Ordering::Release);
        if let Some(listen) = robowire_rt::lock(&self.listener).as_mut() {
            listen();
        }
    }

    /// The oldest sample kept.
    pub(crate) fn pop(&self) -> Option<Arrived> {
        self.queue.pop()
    }

    /// Wakes `waker` at the next sample; `false` if one arrived meanwhile (look again).
    pub(crate) fn register(&self, waker: &std::task::Waker) -> bool {
        self.waker.register(waker);
        self.queue.is_empty()
    }

    /// From now on the background thread runs `listen` instead of waking a task.
    pub(crate) fn install(&self, listen: Listen) {
        *robowire_rt::lock(&self.listener) = Some(listen);
        self.listened.store(true, Ordering::Release);
    }

    /// Takes the listener out (the background thread no longer runs it).
    pub(crate) fn uninstall(&self) -> Option<Listen> {
        self.listened.store(false, Ordering::Release);
        robowire_rt::lock(&self.listener).take()
    }
}
