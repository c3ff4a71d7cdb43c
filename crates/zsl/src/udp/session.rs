//! The session with the robot that HighLevel and LowLevel share, on two threads of control.
//!
//! - The **stream thread** (robowire's runner) owns `zsl-proto`'s sans-IO [`CommandStream`]:
//!   it sends the latched command the moment a call changes it and every 2 ms on absolute
//!   deadlines ([`stream`](super::stream)).
//! - The **receive task** (tokio) decodes state, feeds `zsl-proto`'s [`Watchdog`], publishes
//!   state and connection events to the user, and tells the stream about states and
//!   disconnects.
//!
//! Nothing the stream thread reads is behind a lock another thread holds: calls and states
//! reach it through seqlocks ([`Latest`]), disconnects through an atomic, and what it sent
//! and how late comes back as a seqlock and atomics.

use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::Duration;

use robowire_core::timing::LatenessSummary;
use robowire_rt::runner::{Runner, Waker};
use robowire_rt::stats::{Counter, SharedLateness, micros};
use robowire_rt::{Latest, Time};
use robowire_udp::{LinkStats, Peer, StatsHandle, UdpError, UdpLink, UdpReceiver};
use tokio::sync::watch;
use tokio::task::JoinHandle;
use zsl_proto::codec::{ClientCodec, StateReceived};
use zsl_proto::stream::{CommandStream, Connection, Event, Interface, Watchdog};
use zsl_proto::zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout};

use super::stream::{Input, StreamJob, in_order};
use super::{CallError, ClientOptions, ConnectError};

/// An [`Interface`] whose datagrams can cross threads through a seqlock.
pub(super) trait Wire:
    Interface<
        Command: FromBytes + IntoBytes + KnownLayout + Immutable + std::fmt::Debug,
        State: FromBytes + IntoBytes + KnownLayout + Immutable + std::fmt::Debug,
        Memory: Send,
        Observed: Send,
    > + Send
    + 'static
{
}

impl<I> Wire for I where
    I: Interface<
            Command: FromBytes + IntoBytes + KnownLayout + Immutable + std::fmt::Debug,
            State: FromBytes + IntoBytes + KnownLayout + Immutable + std::fmt::Debug,
            Memory: Send,
            Observed: Send,
            Observed: Send,
        > + Send
        + 'static
{
}

pub(super) type Codec<I> = ClientCodec<<I as Interface>::Command, <I as Interface>::State>;

/// Statistics of one client.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ClientStats {
    /// The socket's counters: commands sent, state datagrams received, decode errors, datagrams
    /// dropped from foreign sources, send errors.
    pub link: LinkStats,
    /// Datagrams sent at once because a call changed the command.
    pub calls_sent: u64,
    /// Periodic refreshes sent.
    pub refreshes_sent: u64,
    /// Refresh slots skipped because the stream thread was more than a period late.
    pub missed_ticks: u64,
    /// State datagrams accepted.
    pub states: u64,
    /// Accepted state datagrams shorter than the full state (lenient mode).
    pub short_states: u64,
    /// Accepted state datagrams with an unexpected header (HighLevel) or without the magic
    /// (LowLevel `haveMotorData() == false`).
    pub header_anomalies: u64,
    /// Watchdog timeouts.
    pub disconnects: u64,
    /// Returns to `Connected` after a timeout.
    pub reconnects: u64,
    /// Lateness of the refreshes against their absolute deadlines, µs.
    pub stream_lateness: LatenessSummary,
    /// Time between consecutive accepted state datagrams, µs (the robot sends every 2 ms; the
    /// maximum shows how close the link came to the watchdog).
    pub state_gap: LatenessSummary,
}

/// What the stream thread reads and writes; every field lock-free for it.
pub(super) struct StreamShared<I: Interface> {
    /// The latest call's command (calls write, the stream takes).
    pub(super) calls: Latest<I::Command>,
    /// The latest state, for the per-datagram rules (the receive task writes).
    pub(super) states: Latest<I::State>,
    /// When the watchdog last expired, ns on the monotonic clock (0: never).
    pub(super) disconnected_at: AtomicU64,
    /// The last datagram sent, stamped with when the stream took its inputs.
    pub(super) streamed: Latest<I::Command>,
    /// The robot's SDK-mismatch flag stopped the stream for good.
    pub(super) halted: AtomicBool,
    pub(super) lateness: SharedLateness<4096>,
    pub(super) calls_sent: Counter,
    pub(super) refreshes_sent: Counter,
    pub(super) missed_ticks: Counter,
}

/// What the receive task counts.
#[derive(Debug, Default)]
struct StateCounters {
    states: Counter,
    short_states: Counter,
    header_anomalies: Counter,
    disconnects: Counter,
    reconnects: Counter,
    gaps: SharedLateness<1024>,
}

pub(super) struct Session<I: Interface> {
    pub(super) stream: StreamShared<I>,
    /// Wakes the stream thread when a call arrives (set once the thread runs).
    waker: OnceLock<Waker>,
    state: watch::Sender<Option<I::State>>,
    connection: watch::Sender<Connection>,
    counters: StateCounters,
    link: StatsHandle,
    local: SocketAddr,
    pub(super) options: ClientOptions,
}

/// A running session: the shared state, the stream thread and the receive task, both stopped
/// on drop.
pub(super) struct Running<I: Wire> {
    pub(super) session: Arc<Session<I>>,
    stream: Option<Runner<StreamJob<I>>>,
    receive: JoinHandle<()>,
}

impl<I: Wire> Drop for Running<I> {
    fn drop(&mut self) {
        self.receive.abort();
        if let Some(stream) = self.stream.take() {
            stream.stop();
        }
    }
}

impl<I: Wire> Running<I> {
    /// Stops the receive task and the stream and waits until both have let go of the socket.
    pub(super) async fn shut_down(mut self) {
        self.receive.abort();
        let _ = (&mut self.receive).await;
        if let Some(stream) = self.stream.take() {
            drop(stream.stop());
        }
    }

    /// Binds, starts the stream (idle command at once, like the vendor) and the receive task.
    pub(super) async fn start(options: ClientOptions) -> Result<Self, ConnectError> {
        options.validate()?;
        let codec = Codec::<I>::new(options.model, options.state_decoding);
        // The robot's sending port is not documented (spec §2): accept state from any port of its
        // IP, nothing from anyone else.
        let mut link = UdpLink::bind(options.local, Peer::AnyPortOf(options.dog), codec).await?;
        link.set_tap(options.tap.clone());
        let local = link.local_addr().map_err(UdpError::from)?;
        let stats = link.stats_handle();
        let (sender, receiver) = link.into_split();
        let session = Arc::new(Session {
            stream: StreamShared {
                calls: Latest::new(),
                states: Latest::new(),
                disconnected_at: AtomicU64::new(0),
                streamed: Latest::new(),
                halted: AtomicBool::new(false),
                lateness: SharedLateness::new(),
                calls_sent: Counter::default(),
                refreshes_sent: Counter::default(),
                missed_ticks: Counter::default(),
            },
            waker: OnceLock::new(),
            state: watch::Sender::new(None),
            connection: watch::Sender::new(Connection::Waiting),
            counters: StateCounters::default(),
            link: stats,
            local,
            options,
        });
        let now = robowire_rt::now();
        let watchdog = Watchdog::new(now, session.options.watchdog);
        let job = StreamJob::new(CommandStream::new(now, session.options.period), sender, session.clone());
        let stream = Runner::spawn(session.options.runner_options(), job)?;
        let _ = session.waker.set(stream.waker());
        let receive = tokio::spawn(receive(session.clone(), receiver, watchdog));
        Ok(Self { session, stream: Some(stream), receive })
    }
}

impl<I: Wire> Session<I> {
    /// Latches `command`; the stream thread sends it at once. `Ok` means queued (the vendor's
    /// 0); a failed send is counted in the link's statistics and retried by the refresh.
    pub(super) fn submit(&self, command: I::Command) -> Result<(), CallError> {
        if self.halted() {
            return Err(CallError::SdkMismatch);
        }
        self.stream.calls.write(robowire_rt::now(), &command);
        if let Some(waker) = self.waker.get() {
            waker.wake();
        }
        Ok(())
    }

    /// The command being streamed: the last one sent, with what the stream thread has not
    /// taken yet applied (a call latches, a disconnect stops the motion): what goes out next,
    /// the per-datagram rules aside.
    pub(super) fn latched(&self) -> I::Command {
        let shared = &self.stream;
        let (sent_at, mut latched) = shared.streamed.read().unwrap_or((Time::ZERO, I::Command::default()));
        let call = shared.calls.read().filter(|(at, _)| *at > sent_at);
        let disconnected_at = Time::from_nanos(shared.disconnected_at.load(Ordering::Acquire));
        let disconnect = (disconnected_at > sent_at).then_some(disconnected_at);
        for input in in_order(call, disconnect) {
            match input {
                Input::Call(command) => latched = command,
                Input::Disconnect => I::stop_motion(&mut latched),
            }
        }
        latched
    }

    /// Whether the stream halted on the robot's SDK-mismatch flag.
    pub(super) fn halted(&self) -> bool {
        self.stream.halted.load(Ordering::Acquire)
    }

    pub(super) fn connection(&self) -> Connection {
        *self.connection.borrow()
    }

    pub(super) fn connection_events(&self) -> watch::Receiver<Connection> {
        self.connection.subscribe()
    }

    pub(super) fn local_addr(&self) -> SocketAddr {
        self.local
    }

    pub(super) fn stats(&self) -> ClientStats {
        let (c, s) = (&self.counters, &self.stream);
        ClientStats {
            link: self.link.get(),
            calls_sent: s.calls_sent.get(),
            refreshes_sent: s.refreshes_sent.get(),
            missed_ticks: s.missed_ticks.get(),
            states: c.states.get(),
            short_states: c.short_states.get(),
            header_anomalies: c.header_anomalies.get(),
            disconnects: c.disconnects.get(),
            reconnects: c.reconnects.get(),
            stream_lateness: s.lateness.summary(),
            state_gap: c.gaps.summary(),
        }
    }

    /// The state, or `None` before the first state and after a timeout.
    pub(super) fn read<T>(&self, f: impl FnOnce(&I::State) -> T) -> Option<T> {
        self.state.borrow().as_ref().map(f)
    }

    /// Waits until a state satisfies `accept`, up to `timeout`.
    pub(super) fn state_updates(&self) -> watch::Receiver<Option<I::State>> {
        self.state.subscribe()
    }

    pub(super) async fn wait_for(&self, timeout: Duration, accept: impl Fn(&I::State) -> bool) -> Option<I::State> {
        let mut rx = self.state.subscribe();
        let wait = rx.wait_for(|s| s.as_ref().is_some_and(&accept));
        match tokio::time::timeout(timeout, wait).await {
            Ok(Ok(state)) => *state,
            _ => None,
        }
    }
}

/// The tokio instant of a monotonic-clock time.
fn tokio_instant(at: Time) -> tokio::time::Instant {
    tokio::time::Instant::now() + at.saturating_duration_since(robowire_rt::now())
}

/// Receives state and runs the watchdog (spec decisions 2, 3, 6).
async fn receive<I: Wire>(session: Arc<Session<I>>, mut receiver: UdpReceiver<Codec<I>>, mut watchdog: Watchdog) {
    let mut last_state: Option<Time> = None;
    loop {
        let expires = watchdog.poll_timeout();
        let timeout = async {
            match expires {
                Some(at) => tokio::time::sleep_until(tokio_instant(at)).await,
                None => std::future::pending().await,
            }
        };
        tokio::select! {
            received = receiver.recv() => match received {
                Ok(received) => {
                    let now = robowire_rt::now();
                    let event = watchdog.feed(now);
                    if let Some(last) = last_state.replace(now) {
                        session.counters.gaps.record(micros(now.saturating_duration_since(last)));
                    }
                    // The connection first: whoever wakes on the state sees it connected.
                    if event.is_some() {
                        on_connected(&session, &watchdog);
                    }
                    on_state(&session, &received, now);
                }
                // Counted by the link; a datagram that does not decode does not feed the watchdog.
                Err(UdpError::Decode(_)) => {}
                // A socket error (counted by the link as a receive error): back off briefly
                // instead of spinning on a broken socket.
                Err(_) => tokio::time::sleep(RECEIVE_ERROR_BACKOFF).await,
            },
            () = timeout => {
                let now = robowire_rt::now();
                if watchdog.poll_event(now) == Some(Event::Disconnected) {
                    receiver.codec_mut().reset();
                    on_disconnected(&session, &watchdog, now);
                }
            }
        }
    }
}

fn on_state<I: Wire>(session: &Session<I>, received: &StateReceived<I::State>, now: Time) {
    let c = &session.counters;
    c.states.add(1);
    if received.update.short {
        c.short_states.add(1);
    }
    if received.update.len > 0 {
        if !received.update.header_ok {
            c.header_anomalies.add(1);
        }
        // A 0-byte datagram only feeds the watchdog: zeros never pose as a state.
        session.stream.states.write(now, &received.state);
        session.state.send_replace(Some(received.state));
    }
}

fn on_connected<I: Wire>(session: &Session<I>, watchdog: &Watchdog) {
    session.counters.reconnects.set(watchdog.counters().reconnects);
    session.connection.send_replace(watchdog.connection());
}

/// The watchdog expired: the stream stops the latched motion, the user sees no state.
fn on_disconnected<I: Wire>(session: &Session<I>, watchdog: &Watchdog, now: Time) {
    session.stream.disconnected_at.store(now.as_nanos(), Ordering::Release);
    if let Some(waker) = session.waker.get() {
        waker.wake();
    }
    session.counters.disconnects.set(watchdog.counters().disconnects);
    session.state.send_replace(None);
    session.connection.send_replace(Connection::Disconnected);
}

/// After a socket error on receive, wait this long before the next receive.
const RECEIVE_ERROR_BACKOFF: Duration = Duration::from_millis(10);

/// The accessors HighLevel and LowLevel share, over `self.session()`.
macro_rules! client_accessors {
    ($wire_state:ty, $state:ty, $wire_command:ty) => {
        /// The state, typed (`None` before the first state and after a watchdog timeout).
        pub fn state(&self) -> Option<$state> {
            self.session().read(|s| s.into())
        }

        /// The state datagram as received, in the vendor's layout (`zsl_proto::udp`), for
        /// logging and inspection (`None` before the first state and after a timeout).
        pub fn wire_state(&self) -> Option<$wire_state> {
            self.session().read(|s| *s)
        }

        /// `checkConnect()`: state arrived within the watchdog timeout.
        pub fn check_connection(&self) -> bool {
            self.connection() == Connection::Connected
        }

        /// The connection now.
        pub fn connection(&self) -> Connection {
            self.session().connection()
        }

        /// Connection events: `Waiting` → `Connected` → `Disconnected` → `Connected` ….
        pub fn connection_events(&self) -> tokio::sync::watch::Receiver<Connection> {
            self.session().connection_events()
        }

        /// Waits until a state satisfies `accept`, up to `timeout`.
        pub async fn wait_for_state(
            &self,
            timeout: std::time::Duration,
            accept: impl Fn(&$state) -> bool,
        ) -> Option<$state> {
            let state = self.session().wait_for(timeout, |s| accept(&s.into())).await?;
            Some((&state).into())
        }

        /// Every state as it arrives: `changed()` resolves at each state datagram (and with
        /// `None` at a watchdog timeout); read it with `borrow_and_update()`.
        pub fn state_updates(&self) -> tokio::sync::watch::Receiver<Option<$wire_state>> {
            self.session().state_updates()
        }

        /// Waits for state, up to `timeout`; whether the client is connected.
        pub async fn wait_connected(&self, timeout: std::time::Duration) -> bool {
            self.session().wait_for(timeout, |_| true).await.is_some()
        }

        /// The command datagram being streamed, in the vendor's layout (`zsl_proto::udp`): the
        /// last one sent, or a call's that goes out next.
        pub fn wire_command(&self) -> $wire_command {
            self.session().latched()
        }

        /// Counters: link, calls and refreshes, state anomalies, disconnects, stream lateness.
        pub fn stats(&self) -> ClientStats {
            self.session().stats()
        }

        /// The bound local address.
        pub fn local_addr(&self) -> std::net::SocketAddr {
            self.session().local_addr()
        }
    };
}

pub(super) use client_accessors;
