//! The session with the robot that HighLevel and LowLevel share: the latched command and its
//! 2 ms stream, the receive loop and its watchdog, connection events and statistics. What
//! differs between the two is an [`Interface`].

use std::fmt;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use robowire_core::timing::{LatenessRing, LatenessSummary};
use robowire_udp::{LinkStats, Peer, StatsHandle, UdpError, UdpLink, UdpReceiver, UdpSender};
use tokio::sync::watch;
use tokio::task::JoinHandle;
use tokio::time::{Instant, MissedTickBehavior};
use zsl_proto::codec::{ClientCodec, CommandDatagram, StateDatagram, StateReceived};

use super::{CallError, ClientOptions, ConnectError};

/// The connection as the watchdog sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Connection {
    /// No state yet since the client started.
    Waiting,
    /// State arrived within the watchdog timeout.
    Connected,
    /// No state for the watchdog timeout: state accessors return `None`, latched velocities
    /// are zero; the client returns to `Connected` by itself when state arrives.
    Disconnected,
}

/// Statistics of one client.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ClientStats {
    /// The socket's counters: commands sent, state datagrams received, decode errors, datagrams
    /// dropped from foreign sources.
    pub link: LinkStats,
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
    /// Lateness of the 2 ms stream against its absolute deadlines.
    pub stream_lateness: LatenessSummary,
    /// Time between consecutive accepted state datagrams, µs (the robot sends every 2 ms; the
    /// maximum shows how close the link came to the watchdog).
    pub state_gap: LatenessSummary,
}

#[derive(Debug, Default)]
struct StateCounters {
    states: AtomicU64,
    short_states: AtomicU64,
    header_anomalies: AtomicU64,
    disconnects: AtomicU64,
    reconnects: AtomicU64,
}

fn bump(counter: &AtomicU64) {
    counter.fetch_add(1, Ordering::Relaxed);
}

/// What distinguishes the HighLevel and the LowLevel interface of a session: their datagrams
/// and the vendor sender's per-datagram rules.
pub(super) trait Interface: Send + Sync + 'static {
    type Command: CommandDatagram + fmt::Debug;
    type State: StateDatagram + fmt::Debug;
    /// Per-stream memory of [`Interface::before_send`].
    type SendState: Default + Send + 'static;

    /// Applied to the latched command before every datagram; `false` halts the stream for good.
    fn before_send(latched: &mut Self::Command, memory: &mut Self::SendState, state: Option<&Self::State>) -> bool;

    /// Replaces a latched motion with a stop (watchdog timeout, spec decision 6).
    fn stop_motion(latched: &mut Self::Command);

    /// Whether the header or magic of an accepted state was as expected.
    fn header_ok(received: &StateReceived<Self::State>) -> bool {
        received.update.header_ok
    }
}

type Codec<P> = ClientCodec<<P as Interface>::Command, <P as Interface>::State>;

struct Outbox<P: Interface> {
    latched: P::Command,
    sender: UdpSender<Codec<P>>,
    memory: P::SendState,
    halted: bool,
}

pub(super) struct Session<P: Interface> {
    outbox: tokio::sync::Mutex<Outbox<P>>,
    pub(super) state: watch::Sender<Option<P::State>>,
    connection: watch::Sender<Connection>,
    counters: StateCounters,
    lateness: Mutex<LatenessRing<1024>>,
    /// When the last state was accepted, and the gaps between states.
    state_gaps: Mutex<(Option<Instant>, LatenessRing<1024>)>,
    link: StatsHandle,
    local: SocketAddr,
    pub(super) options: ClientOptions,
}

/// A running session: the shared state plus its two tasks, stopped on drop.
pub(super) struct Running<P: Interface> {
    pub(super) session: Arc<Session<P>>,
    tasks: [JoinHandle<()>; 2],
}

impl<P: Interface> Drop for Running<P> {
    fn drop(&mut self) {
        for task in &self.tasks {
            task.abort();
        }
    }
}

impl<P: Interface> Running<P> {
    /// Binds, starts the stream (idle command at once, like the vendor) and the receive loop.
    pub(super) async fn start(options: ClientOptions) -> Result<Self, ConnectError> {
        let codec = Codec::<P>::new(options.model, options.state_decoding);
        // The robot's sending port is not documented (spec §2): accept state from any port of its
        // IP, nothing from anyone else.
        let link = UdpLink::bind(options.local, Peer::AnyPortOf(options.dog), codec).await?;
        let local = link.local_addr()?;
        let stats = link.stats_handle();
        let (sender, receiver) = link.into_split();
        let session = Arc::new(Session {
            outbox: tokio::sync::Mutex::new(Outbox {
                latched: P::Command::default(),
                sender,
                memory: P::SendState::default(),
                halted: false,
            }),
            state: watch::Sender::new(None),
            connection: watch::Sender::new(Connection::Waiting),
            counters: StateCounters::default(),
            lateness: Mutex::new(LatenessRing::new()),
            state_gaps: Mutex::new((None, LatenessRing::new())),
            link: stats,
            local,
            options,
        });
        let stream = tokio::spawn(stream(session.clone()));
        let receive = tokio::spawn(receive(session.clone(), receiver));
        Ok(Self { session, tasks: [stream, receive] })
    }
}

impl<P: Interface> Session<P> {
    /// Rewrites the latched command and puts it on the wire at once.
    pub(super) async fn submit(&self, write: impl FnOnce(&mut P::Command)) -> Result<(), CallError> {
        let mut outbox = self.outbox.lock().await;
        if outbox.halted {
            return Err(CallError::SdkMismatch);
        }
        write(&mut outbox.latched);
        self.transmit(&mut outbox).await
    }

    async fn transmit(&self, outbox: &mut Outbox<P>) -> Result<(), CallError> {
        let proceed = {
            let state = self.state.borrow();
            P::before_send(&mut outbox.latched, &mut outbox.memory, state.as_ref())
        };
        if !proceed {
            outbox.halted = true;
            return Err(CallError::SdkMismatch);
        }
        let command = outbox.latched;
        outbox.sender.send(&command).await.map_err(CallError::Send)
    }

    /// The latched command (what the stream is sending).
    pub(super) async fn latched(&self) -> P::Command {
        self.outbox.lock().await.latched
    }

    /// Whether the stream halted on the robot's SDK-mismatch flag.
    pub(super) async fn halted(&self) -> bool {
        self.outbox.lock().await.halted
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
        let c = &self.counters;
        ClientStats {
            link: self.link.get(),
            states: c.states.load(Ordering::Relaxed),
            short_states: c.short_states.load(Ordering::Relaxed),
            header_anomalies: c.header_anomalies.load(Ordering::Relaxed),
            disconnects: c.disconnects.load(Ordering::Relaxed),
            reconnects: c.reconnects.load(Ordering::Relaxed),
            stream_lateness: self.lateness.lock().map(|r| r.summary()).unwrap_or_default(),
            state_gap: self.state_gaps.lock().map(|g| g.1.summary()).unwrap_or_default(),
        }
    }

    /// The state, or `None` before the first state and after a timeout.
    pub(super) fn read<T>(&self, f: impl FnOnce(&P::State) -> T) -> Option<T> {
        self.state.borrow().as_ref().map(f)
    }

    /// Waits until a state satisfies `accept`, up to `timeout`.
    pub(super) async fn wait_for(&self, timeout: Duration, accept: impl Fn(&P::State) -> bool) -> Option<P::State> {
        let mut rx = self.state.subscribe();
        let wait = rx.wait_for(|s| s.as_ref().is_some_and(&accept));
        match tokio::time::timeout(timeout, wait).await {
            Ok(Ok(state)) => *state,
            _ => None,
        }
    }
}

/// The 2 ms command stream on absolute deadlines (a late tick does not shift the grid).
async fn stream<P: Interface>(session: Arc<Session<P>>) {
    let mut ticks = tokio::time::interval(session.options.period);
    ticks.set_missed_tick_behavior(MissedTickBehavior::Skip);
    loop {
        let deadline = ticks.tick().await;
        let late_us = u32::try_from(deadline.elapsed().as_micros()).unwrap_or(u32::MAX);
        if let Ok(mut ring) = session.lateness.lock() {
            ring.record(late_us);
        }
        let mut outbox = session.outbox.lock().await;
        if outbox.halted {
            continue;
        }
        // A failed send is counted by the link; the next tick tries again.
        let _ = session.transmit(&mut outbox).await;
    }
}

/// Receives state, feeds the watchdog, and handles its timeout (spec decisions 2, 3, 6).
async fn receive<P: Interface>(session: Arc<Session<P>>, mut receiver: UdpReceiver<Codec<P>>) {
    let watchdog = session.options.watchdog;
    // As the vendor's: the first timeout is `watchdog` after start if nothing ever arrives.
    let mut deadline = Some(Instant::now() + watchdog);
    loop {
        let timeout = async {
            match deadline {
                Some(at) => tokio::time::sleep_until(at).await,
                None => std::future::pending().await,
            }
        };
        tokio::select! {
            received = receiver.recv() => match received {
                Ok(received) => {
                    deadline = Some(Instant::now() + watchdog);
                    on_state(&session, &received);
                }
                // Counted by the link; a datagram that does not decode does not feed the watchdog.
                Err(UdpError::Decode(_)) => {}
                // A socket error (counted by the link as a receive error): back off briefly
                // instead of spinning on a broken socket.
                Err(_) => tokio::time::sleep(RECEIVE_ERROR_BACKOFF).await,
            },
            () = timeout => {
                deadline = None;
                bump(&session.counters.disconnects);
                session.state.send_replace(None);
                receiver.codec_mut().reset();
                P::stop_motion(&mut session.outbox.lock().await.latched);
                session.connection.send_replace(Connection::Disconnected);
            }
        }
    }
}

fn on_state<P: Interface>(session: &Session<P>, received: &StateReceived<P::State>) {
    let c = &session.counters;
    bump(&c.states);
    if let Ok(mut gaps) = session.state_gaps.lock() {
        let now = Instant::now();
        if let Some(last) = gaps.0.replace(now) {
            gaps.1.record(u32::try_from((now - last).as_micros()).unwrap_or(u32::MAX));
        }
    }
    if received.update.short {
        bump(&c.short_states);
    }
    if received.update.len > 0 {
        if !P::header_ok(received) {
            bump(&c.header_anomalies);
        }
        // A 0-byte datagram only feeds the watchdog: zeros never pose as a state.
        session.state.send_replace(Some(received.state));
    }
    session.connection.send_if_modified(|connection| match *connection {
        Connection::Connected => false,
        Connection::Disconnected => {
            bump(&c.reconnects);
            *connection = Connection::Connected;
            true
        }
        Connection::Waiting => {
            *connection = Connection::Connected;
            true
        }
    });
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

        /// Waits for state, up to `timeout`; whether the client is connected.
        pub async fn wait_connected(&self, timeout: std::time::Duration) -> bool {
            self.session().wait_for(timeout, |_| true).await.is_some()
        }

        /// The command datagram being streamed now, in the vendor's layout (`zsl_proto::udp`).
        pub async fn wire_command(&self) -> $wire_command {
            self.session().latched().await
        }

        /// Counters: link, state anomalies, disconnects, stream lateness.
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
