//! The participant's one background thread and the state it shares with writers and readers.
//!
//! The core (`rtps_proto::participant::Participant`) sits behind one mutex, held only while it
//! computes and while its datagrams go out with non-blocking `sendto`s (microseconds; no I/O
//! that can wait). The background thread waits in `poll(2)` on the sockets and an eventfd until
//! a datagram arrives or the core's next deadline (announcements, heartbeats, acknowledgements,
//! leases): it never spins. It hands each received sample to its reader's slot and wakes the
//! reader's task once. A writer's sample is sent on the writer's own thread.

use std::collections::HashMap;
use std::io;
use std::net::{SocketAddr, UdpSocket};
use std::os::fd::{AsFd, OwnedFd};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

use crossbeam_queue::ArrayQueue;
use rtps_proto::participant::{Destination, Event, Participant as Core};
use rtps_proto::{EntityId, Time};
use rustix::event::{EventfdFlags, PollFd, PollFlags};

use crate::slot::ReaderSlot;
use crate::sockets::{MAX_DATAGRAM, Sockets};

/// Incompatible remote endpoints remembered per local endpoint (the first ones).
const INCOMPATIBLE_KEPT: usize = 32;

/// A remote endpoint on a local endpoint's topic that cannot match it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Incompatible {
    /// The remote writer's or reader's GUID in wire order.
    pub remote: [u8; 16],
    /// Why: the type names differ, or the QoS policy that does not match and both sides' values.
    pub reason: String,
}

/// Payload buffers handed back by readers, kept for the core to reuse.
const RECYCLED: usize = 64;

/// What the core, the background thread, writers and readers share.
#[derive(Debug)]
pub(crate) struct Shared {
    state: Mutex<State>,
    pub(crate) sockets: Sockets,
    wake: OwnedFd,
    /// The background thread's next deadline in monotonic ns (`u64::MAX`: none), written and
    /// read under the state's lock.
    armed_ns: AtomicU64,
    stop: AtomicBool,
    /// Payload buffers readers are done with.
    pub(crate) recycled: ArrayQueue<Vec<u8>>,
    /// Woken after each datagram while a writer waits for acknowledgements.
    pub(crate) acknowledgements: tokio::sync::Notify,
    pub(crate) ack_waiters: AtomicUsize,
    /// Datagrams whose `sendto` failed (full buffer, unreachable network).
    pub(crate) send_failures: AtomicU64,
}

/// The core and the readers' slots, under the lock.
#[derive(Debug)]
pub(crate) struct State {
    pub(crate) core: Core,
    pub(crate) readers: HashMap<EntityId, Arc<ReaderSlot>>,
    /// Remote endpoints on a local endpoint's topic that cannot match it, and why.
    pub(crate) incompatible: HashMap<EntityId, Vec<Incompatible>>,
    /// Room for one datagram to send.
    pub(crate) buf: Vec<u8>,
    /// Listened readers with samples, for the background thread to run once the lock is let go.
    pub(crate) listeners_due: Vec<Arc<ReaderSlot>>,
}

impl Shared {
    pub(crate) fn new(core: Core, sockets: Sockets) -> io::Result<Arc<Self>> {
        let wake = rustix::event::eventfd(0, EventfdFlags::CLOEXEC | EventfdFlags::NONBLOCK)?;
        Ok(Arc::new(Self {
            state: Mutex::new(State {
                core,
                readers: HashMap::new(),
                incompatible: HashMap::new(),
                buf: vec![0; MAX_DATAGRAM],
                listeners_due: Vec::new(),
            }),
            sockets,
            wake,
            armed_ns: AtomicU64::new(u64::MAX),
            stop: AtomicBool::new(false),
            recycled: ArrayQueue::new(RECYCLED),
            acknowledgements: tokio::sync::Notify::new(),
            ack_waiters: AtomicUsize::new(0),
            send_failures: AtomicU64::new(0),
        }))
    }

    /// The state (a poisoned lock's state is still consistent: see `robowire_rt::sync`).
    pub(crate) fn lock(&self) -> MutexGuard<'_, State> {
        robowire_rt::lock(&self.state)
    }

    /// Sends what the core has due, hands samples to readers; then, if the core's next deadline
    /// is earlier than the one the background thread sleeps towards, wakes it.
    pub(crate) fn settle(&self, st: &mut State, now: Time) {
        self.dispatch(st);
        self.flush(st, now);
        let next = st.core.poll_timeout().map_or(u64::MAX, Time::as_nanos);
        if next < self.armed_ns.load(Ordering::Relaxed) {
            self.armed_ns.store(next, Ordering::Relaxed);
            self.wake();
        }
    }

    /// Sends every datagram the core has due.
    pub(crate) fn flush(&self, st: &mut State, now: Time) {
        let State { core, buf, .. } = st;
        while let Some(t) = core.poll_transmit(now, buf) {
            let failed = self.sockets.send(&buf[..t.len], t.destinations());
            if failed > 0 {
                self.send_failures.fetch_add(failed, Ordering::Relaxed);
            }
        }
    }

    /// Hands received samples to their readers (the oldest kept sample replaced when a reader's
    /// slot is full, its buffer reused) and gives readers' spent buffers back to the core.
    fn dispatch(&self, st: &mut State) {
        while let Some(b) = self.recycled.pop() {
            st.core.recycle(b);
        }
        while let Some(e) = st.core.poll_event() {
            match e {
                Event::Sample(sample) => match st.readers.get(&sample.info.reader) {
                    Some(slot) => {
                        let (replaced, listen) = slot.push(sample);
                        if let Some(replaced) = replaced {
                            st.core.recycle(replaced);
                        }
                        if listen {
                            st.listeners_due.push(slot.clone());
                        }
                    }
                    None => st.core.recycle(sample.payload),
                },
                Event::Incompatible { local, remote, reason } => {
                    let list = st.incompatible.entry(local).or_default();
                    let remote = remote.to_bytes();
                    list.retain(|i| i.remote != remote);
                    if list.len() < INCOMPATIBLE_KEPT {
                        list.push(Incompatible { remote, reason: reason.to_string() });
                    }
                }
                Event::Matched { remote, .. } | Event::EndpointLost { guid: remote } => {
                    let remote = remote.to_bytes();
                    st.incompatible.values_mut().for_each(|l| l.retain(|i| i.remote != remote));
                }
                _ => {}
            }
        }
    }

    fn wake(&self) {
        let _ = rustix::io::write(&self.wake, &1u64.to_ne_bytes());
    }

    /// Ends the background thread.
    pub(crate) fn stop(&self) {
        self.stop.store(true, Ordering::Relaxed);
        self.wake();
    }
}

/// The background thread's buffers: a datagram received, the listeners to run.
struct Scratch {
    rx: Vec<u8>,
    listeners: Vec<Arc<ReaderSlot>>,
}

/// Lets the lock go, then runs the listeners of the readers that got samples.
fn run_listeners(mut st: MutexGuard<'_, State>, spare: &mut Vec<Arc<ReaderSlot>>) {
    if st.listeners_due.is_empty() {
        return;
    }
    std::mem::swap(&mut st.listeners_due, spare);
    drop(st);
    for slot in spare.drain(..) {
        slot.run_listener();
    }
}

fn recv_all(shared: &Shared, socket: &UdpSocket, destination: Destination, scratch: &mut Scratch) {
    loop {
        match socket.recv_from(&mut scratch.rx) {
            Ok((n, from)) => handle(shared, from, destination, &scratch.rx[..n], &mut scratch.listeners),
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(_) => return, // WouldBlock: drained (other errors: ICMP reports, ignored)
        }
    }
}

fn handle(
    shared: &Shared,
    from: SocketAddr,
    destination: Destination,
    datagram: &[u8],
    listeners: &mut Vec<Arc<ReaderSlot>>,
) {
    let now = robowire_rt::now();
    let mut st = shared.lock();
    st.core.handle_datagram(now, from, destination, datagram);
    // A listened sample first: what else the datagram made due (an acknowledgement, a new
    // deadline) goes out after the listener, which often writes its answer (and settles) itself.
    shared.dispatch(&mut st);
    if !st.listeners_due.is_empty() {
        run_listeners(st, listeners);
        st = shared.lock();
    }
    shared.settle(&mut st, now);
    drop(st);
    if shared.ack_waiters.load(Ordering::Relaxed) > 0 {
        shared.acknowledgements.notify_waiters();
    }
}

/// The background thread: receives, and runs the core's timers.
pub(crate) fn run(shared: Arc<Shared>) {
    let mut scratch = Scratch { rx: vec![0u8; MAX_DATAGRAM], listeners: Vec::new() };
    while !shared.stop.load(Ordering::Relaxed) {
        let deadline = {
            let st = shared.lock();
            let next = st.core.poll_timeout().map_or(u64::MAX, Time::as_nanos);
            shared.armed_ns.store(next, Ordering::Relaxed);
            next
        };
        let now = robowire_rt::monotonic_ns();
        let timeout = (deadline != u64::MAX).then(|| {
            let ns = deadline.saturating_sub(now);
            rustix::time::Timespec { tv_sec: (ns / 1_000_000_000) as i64, tv_nsec: (ns % 1_000_000_000) as i64 }
        });
        let s = &shared.sockets;
        let mut fds = [
            PollFd::new(&s.user, PollFlags::IN),
            PollFd::new(&s.meta, PollFlags::IN),
            PollFd::new(&s.spdp, PollFlags::IN),
            PollFd::from_borrowed_fd(shared.wake.as_fd(), PollFlags::IN),
        ];
        if rustix::event::poll(&mut fds, timeout.as_ref()).is_err() {
            continue; // EINTR
        }
        let ready: [bool; 4] = std::array::from_fn(|i| !fds[i].revents().is_empty());
        if ready[3] {
            let mut b = [0u8; 8];
            let _ = rustix::io::read(&shared.wake, &mut b);
        }
        if ready[0] {
            recv_all(&shared, &s.user, Destination::Unicast, &mut scratch);
        }
        if ready[1] {
            recv_all(&shared, &s.meta, Destination::Unicast, &mut scratch);
        }
        if ready[2] {
            recv_all(&shared, &s.spdp, Destination::Multicast, &mut scratch);
        }
        let now = robowire_rt::now();
        let mut st = shared.lock();
        if st.core.poll_timeout().is_some_and(|t| t <= now) {
            st.core.handle_timeout(now);
        }
        shared.settle(&mut st, now);
        run_listeners(st, &mut scratch.listeners);
    }
    // Leaving: tell the others at once rather than letting the lease run out.
    let mut st = shared.lock();
    let State { core, buf, .. } = &mut *st;
    if let Some(t) = core.leave(buf) {
        shared.sockets.send(&buf[..t.len], t.destinations());
    }
}
