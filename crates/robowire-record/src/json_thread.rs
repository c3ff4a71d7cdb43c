//! The JSON thread: decodes frames into their JSON messages off the writer's path.
//!
//! The writer hands it the frames it has written raw ([`HeldFrame`]s, their slots still out of
//! the taps' ring) through a bounded lock-free queue it never waits on: when the queue is full the
//! frame's JSON message is skipped and counted, its raw frame being in the capture already. The
//! JSON comes back to the writer through a bounded channel, in the order the frames went in.

use std::collections::HashSet;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::thread::{JoinHandle, Thread};
use std::time::Duration;

use crossbeam_queue::ArrayQueue;
use robowire_core::json::{LinkDescription, Value};
use robowire_tap::{Direction, HeldFrame, SampleOrigin};

/// How long the thread sleeps when it has nothing to decode.
const IDLE: Duration = Duration::from_millis(1);

/// A frame's JSON message, for the writer.
pub(crate) struct JsonMessage {
    /// The frame's link, direction and origin: which channels it belongs to.
    pub(crate) link: u16,
    pub(crate) direction: Direction,
    pub(crate) origin: SampleOrigin,
    /// The frame's tap stamp, monotonic ns.
    pub(crate) monotonic_ns: u64,
    /// The message's schema name.
    pub(crate) schema: &'static str,
    /// The schema, with the first message of each schema name only.
    pub(crate) schema_text: Option<Value>,
    /// The message, serialized; `None` if the frame does not decode.
    pub(crate) json: Option<Vec<u8>>,
}

/// The writer's end of the JSON thread.
pub(crate) struct JsonThread {
    frames: Arc<ArrayQueue<(HeldFrame, &'static dyn LinkDescription)>>,
    messages: Receiver<JsonMessage>,
    done: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
    waker: Thread,
}

impl JsonThread {
    /// Starts the thread; at most `queued` frames wait for it.
    pub(crate) fn spawn(queued: usize) -> std::io::Result<Self> {
        let frames = Arc::new(ArrayQueue::new(queued.max(1)));
        let (sender, messages) = sync_channel(queued.max(1));
        let done = Arc::new(AtomicBool::new(false));
        let thread = std::thread::Builder::new().name("robowire-record-json".into()).spawn({
            let (frames, done) = (frames.clone(), done.clone());
            move || decode_until_done(&frames, &sender, &done)
        })?;
        let waker = thread.thread().clone();
        Ok(Self { frames, messages, done, thread: Some(thread), waker })
    }

    /// Queues `frame` for decoding by `description`; `false` (the frame released) if the queue
    /// is full. Never waits.
    pub(crate) fn offer(&self, frame: HeldFrame, description: &'static dyn LinkDescription) -> bool {
        self.frames.push((frame, description)).is_ok()
    }

    /// Queues `frame`, waiting for room (when finishing: nothing is skipped then), handing the
    /// messages that come back meanwhile to `take`.
    pub(crate) fn push_waiting<E>(
        &self,
        mut frame: (HeldFrame, &'static dyn LinkDescription),
        mut take: impl FnMut(JsonMessage) -> Result<(), E>,
    ) -> Result<(), E> {
        loop {
            match self.frames.push(frame) {
                Ok(()) => return Ok(()),
                Err(back) => frame = back,
            }
            self.waker.unpark();
            match self.messages.recv_timeout(IDLE) {
                Ok(message) => take(message)?,
                Err(_) => continue,
            }
        }
    }

    /// Wakes the thread for what was queued.
    pub(crate) fn wake(&self) {
        self.waker.unpark();
    }

    /// The messages ready now.
    pub(crate) fn ready(&self) -> impl Iterator<Item = JsonMessage> + '_ {
        self.messages.try_iter()
    }

    /// Lets the thread decode what is queued and end, handing every message it makes to
    /// `take`, in order.
    pub(crate) fn finish<E>(mut self, mut take: impl FnMut(JsonMessage) -> Result<(), E>) -> Result<(), E> {
        self.done.store(true, Ordering::Release);
        self.waker.unpark();
        // The channel ends when the thread, done, drops its sender.
        while let Ok(message) = self.messages.recv() {
            take(message)?;
        }
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
        Ok(())
    }
}

impl Drop for JsonThread {
    fn drop(&mut self) {
        self.done.store(true, Ordering::Release);
        self.waker.unpark();
        // Unblock a send: drain what is left.
        while self.messages.try_recv().is_ok() {}
        if let Some(thread) = self.thread.take() {
            drop(std::mem::replace(&mut self.messages, sync_channel(0).1));
            let _ = thread.join();
        }
    }
}

fn decode_until_done(
    frames: &ArrayQueue<(HeldFrame, &'static dyn LinkDescription)>,
    messages: &SyncSender<JsonMessage>,
    done: &AtomicBool,
) {
    let mut schemas_sent: HashSet<&'static str> = HashSet::new();
    loop {
        let finishing = done.load(Ordering::Acquire);
        while let Some((frame, description)) = frames.pop() {
            let message = decode(&frame, description, &mut schemas_sent);
            drop(frame);
            let mut message = Some(message);
            while let Some(m) = message.take() {
                match messages.try_send(m) {
                    Ok(()) => {}
                    Err(TrySendError::Full(m)) => {
                        message = Some(m);
                        std::thread::park_timeout(IDLE);
                    }
                    Err(TrySendError::Disconnected(_)) => return,
                }
            }
        }
        if finishing {
            return;
        }
        std::thread::park_timeout(IDLE);
    }
}

fn decode(
    frame: &HeldFrame,
    description: &'static dyn LinkDescription,
    schemas_sent: &mut HashSet<&'static str>,
) -> JsonMessage {
    let mut message = JsonMessage {
        link: frame.link,
        direction: frame.direction,
        origin: frame.origin,
        monotonic_ns: frame.monotonic_ns,
        schema: "",
        schema_text: None,
        json: None,
    };
    let Ok(decoded) = description.decode(frame.direction, frame.bytes()) else { return message };
    message.schema = decoded.schema;
    if schemas_sent.insert(decoded.schema) {
        message.schema_text = Some(description.schema(&decoded));
    }
    message.json = serde_json::to_vec(&decoded.value).ok();
    message
}
