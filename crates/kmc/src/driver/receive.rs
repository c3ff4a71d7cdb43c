//! The receive thread: a small tokio runtime reading the port through the serial link,
//! queueing what the chassis sends, and reopening the port after a disconnect (then handing the
//! stream thread a new writer). A normal thread: the only one that locks the received queue
//! besides the user's.

use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::mpsc as std_mpsc;
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};

use kmc_proto::{ChassisFrame, ChassisFrameDecoder};
use robowire_serial::{LinkCounters, SerialLink};
use tokio::sync::watch;

use super::stream::StreamShared;
use super::{DriverOptions, LinkState};
use crate::KmcError;

/// What the receive thread and the user's threads share.
#[derive(Debug)]
pub(super) struct Received {
    pub(super) queue: VecDeque<ChassisFrame>,
    pub(super) link_state: LinkState,
    pub(super) frames_received: u64,
    pub(super) queue_dropped: u64,
    pub(super) disconnects: u64,
    /// The link's read side: decoder counters, bytes read, reopens.
    pub(super) link: LinkCounters,
}

#[derive(Debug)]
pub(super) struct Inbox {
    state: Mutex<Received>,
    pub(super) message_ready: Condvar,
}

impl Inbox {
    pub(super) fn new(max_queue: usize) -> Self {
        Self {
            state: Mutex::new(Received {
                queue: VecDeque::with_capacity(max_queue.min(4096)),
                link_state: LinkState::Stopped,
                frames_received: 0,
                queue_dropped: 0,
                disconnects: 0,
                link: LinkCounters::default(),
            }),
            message_ready: Condvar::new(),
        }
    }

    pub(super) fn lock(&self) -> MutexGuard<'_, Received> {
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// Opens the port, hands the stream thread its writer, reports the outcome on `started`, then
/// receives until `stop` says so.
pub(super) fn run(
    port: PathBuf,
    options: DriverOptions,
    inbox: Arc<Inbox>,
    stream: Arc<StreamShared>,
    mut stop: watch::Receiver<bool>,
    started: std_mpsc::SyncSender<Result<(), KmcError>>,
) {
    let setup = || -> Result<(tokio::runtime::Runtime, SerialLink<ChassisFrameDecoder>), KmcError> {
        let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().map_err(KmcError::Thread)?;
        let decoder = ChassisFrameDecoder::new()
            .with_max_speed_mps(options.max_speed_mps)
            .map_err(|e| KmcError::Option { name: "max_speed_mps", reason: e.to_string() })?;
        let link = {
            let _entered = runtime.enter();
            SerialLink::open(&port, &options.serial, decoder)?
        };
        *lock(&stream.writer) = Some(link.sync_writer()?);
        Ok((runtime, link))
    };
    let (runtime, mut link) = match setup() {
        Ok(ok) => ok,
        Err(e) => {
            let _ = started.send(Err(e));
            return;
        }
    };
    inbox.lock().link_state = LinkState::Connected;
    let _ = started.send(Ok(()));
    runtime.block_on(receive(&options, &inbox, &stream, &mut link, &mut stop));
    // A writer the stream thread never took would keep the port open (and, exclusive, busy).
    lock(&stream.writer).take();
}

async fn receive(
    options: &DriverOptions,
    inbox: &Inbox,
    stream: &StreamShared,
    link: &mut SerialLink<ChassisFrameDecoder>,
    stop: &mut watch::Receiver<bool>,
) {
    loop {
        if link.is_open() {
            tokio::select! {
                _ = stop.changed() => return,
                frame = link.recv() => match frame {
                    Ok(frame) => enqueue(inbox, frame, options.max_queue, link.counters()),
                    Err(_) => on_disconnect(inbox, link),
                },
            }
        } else if let Some(backoff) = options.reopen {
            tokio::select! {
                _ = stop.changed() => return,
                reopened = link.reopen(&backoff) => if reopened.is_ok() {
                    if let Ok(writer) = link.sync_writer() {
                        *lock(&stream.writer) = Some(writer);
                    }
                    let mut received = inbox.lock();
                    received.link_state = LinkState::Connected;
                    received.link = link.counters();
                },
            }
        } else {
            // No reopening: wait for stop.
            let _ = stop.changed().await;
            return;
        }
    }
}

fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    mutex.lock().unwrap_or_else(PoisonError::into_inner)
}

fn enqueue(inbox: &Inbox, frame: ChassisFrame, max_queue: usize, link: LinkCounters) {
    let mut received = inbox.lock();
    received.frames_received += 1;
    received.link = link;
    if received.queue.len() >= max_queue {
        received.queue.pop_front();
        received.queue_dropped += 1;
    }
    received.queue.push_back(frame);
    drop(received);
    inbox.message_ready.notify_one();
}

fn on_disconnect(inbox: &Inbox, link: &SerialLink<ChassisFrameDecoder>) {
    let mut received = inbox.lock();
    if received.link_state != LinkState::Disconnected {
        received.link_state = LinkState::Disconnected;
        received.disconnects += 1;
    }
    received.link = link.counters();
}
