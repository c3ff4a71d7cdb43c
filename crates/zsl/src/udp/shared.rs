//! What a session's stream thread, receive thread and caller share: the [`Wire`] bound on an
//! interface's datagrams and the lock-free [`Shared`] block.

use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, AtomicU64};

use robowire_rt::Latest;
use robowire_rt::runner::Waker;
use robowire_rt::stats::{Counter, SharedLateness};
use zsl_proto::codec::ClientCodec;
use zsl_proto::stream::Interface;
use zsl_proto::zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout};

/// An [`Interface`] whose datagrams can cross threads through a seqlock.
pub(super) trait Wire:
    Interface<
        Command: FromBytes + IntoBytes + KnownLayout + Immutable + std::fmt::Debug + Send,
        State: FromBytes + IntoBytes + KnownLayout + Immutable + std::fmt::Debug + Send + Sync,
        Memory: Send,
        Observed: Send,
    > + Send
    + Sync
    + 'static
{
}

impl<I> Wire for I where
    I: Interface<
            Command: FromBytes + IntoBytes + KnownLayout + Immutable + std::fmt::Debug + Send,
            State: FromBytes + IntoBytes + KnownLayout + Immutable + std::fmt::Debug + Send + Sync,
            Memory: Send,
            Observed: Send,
        > + Send
        + Sync
        + 'static
{
}

pub(super) type Codec<I> = ClientCodec<<I as Interface>::Command, <I as Interface>::State>;

/// What the stream thread, the receive thread and the caller share; every field lock-free.
pub(super) struct Shared<I: Interface> {
    /// The latest call's command (calls write, the stream takes).
    pub(super) calls: Latest<I::Command>,
    /// The latest state, for the per-datagram rules (the receive thread writes).
    pub(super) states: Latest<I::State>,
    /// When the watchdog last expired, ns on the monotonic clock (0: never).
    pub(super) disconnected_at: AtomicU64,
    /// The last datagram sent, stamped with when the stream took its inputs.
    pub(super) streamed: Latest<I::Command>,
    /// The robot's SDK-mismatch flag stopped the stream for good.
    pub(super) halted: AtomicBool,
    /// Wakes the stream thread when a call or a disconnect arrives (set once the thread runs).
    pub(super) waker: OnceLock<Waker>,
    pub(super) lateness: SharedLateness<4096>,
    pub(super) calls_sent: Counter,
    pub(super) refreshes_sent: Counter,
    pub(super) missed_ticks: Counter,
    pub(super) accepted: Counter,
    pub(super) short_states: Counter,
    pub(super) header_anomalies: Counter,
}

impl<I: Wire> Shared<I> {
    pub(super) fn new() -> Self {
        Self {
            calls: Latest::new(),
            states: Latest::new(),
            disconnected_at: AtomicU64::new(0),
            streamed: Latest::new(),
            halted: AtomicBool::new(false),
            waker: OnceLock::new(),
            lateness: SharedLateness::new(),
            calls_sent: Counter::default(),
            refreshes_sent: Counter::default(),
            missed_ticks: Counter::default(),
            accepted: Counter::default(),
            short_states: Counter::default(),
            header_anomalies: Counter::default(),
        }
    }

    pub(super) fn wake(&self) {
        if let Some(waker) = self.waker.get() {
            waker.wake();
        }
    }
}
