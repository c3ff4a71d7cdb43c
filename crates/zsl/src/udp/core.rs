//! What HighLevel and LowLevel share: the command stream, the receive loop and its watchdog,
//! connection events and statistics.

use std::fmt;
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use robowire_core::timing::{LatenessRing, LatenessSummary};
use robowire_udp::{LinkStats, StatsHandle, UdpError, UdpLink, UdpReceiver, UdpSender};
use tokio::sync::watch;
use tokio::task::JoinHandle;
use tokio::time::{Instant, MissedTickBehavior};
use zsl_proto::codec::{ClientCodec, CommandDatagram, StateDatagram, StateDecoding, StateReceived};
use zsl_proto::rules::ArgumentError;
use zsl_proto::udp::{
    ControlMode, DEFAULT_LOCAL_PORT, DatagramError, HIGH_LEVEL_PORT, LOW_LEVEL_PORT, Model, ReturnCode,
};

/// Where a client binds and whom it talks to (the vendor's `initRobot(local_ip, local_port, dog_ip)`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ClientOptions {
    /// Local address to bind; state arrives here. The robot sends to its configured target
    /// (`target_ip`/`target_port` in its `sdk_config.yaml`, port 43988 by default).
    pub local: SocketAddr,
    /// The robot's address: commands go here; state from any other IP is dropped.
    pub dog: SocketAddr,
    /// Model: ZSL-1 commands carry magic `0x5AA5`, ZSL-1W `0x5AA6`.
    pub model: Model,
    /// How state is decoded. Default lenient, like the vendor (see [`StateDecoding`]).
    pub state_decoding: StateDecoding,
    /// Command period. Default 2 ms (the vendor's cadence).
    pub period: Duration,
    /// Silence after which the connection is lost. Default 3 s (the vendor's).
    pub watchdog: Duration,
}

impl ClientOptions {
    /// The robot's address on its own network.
    pub const DEFAULT_DOG_IP: Ipv4Addr = Ipv4Addr::new(192, 168, 234, 1);

    fn new(local_ip: IpAddr, local_port: u16, dog_ip: IpAddr, dog_port: u16) -> Self {
        Self {
            local: SocketAddr::new(local_ip, local_port),
            dog: SocketAddr::new(dog_ip, dog_port),
            model: Model::Zsl1,
            state_decoding: StateDecoding::Lenient,
            period: Duration::from_millis(2),
            watchdog: Duration::from_secs(3),
        }
    }

    /// HighLevel: commands to `dog_ip:43997`.
    pub fn high_level(local_ip: IpAddr, local_port: u16, dog_ip: IpAddr) -> Self {
        Self::new(local_ip, local_port, dog_ip, HIGH_LEVEL_PORT)
    }

    /// LowLevel: commands to `dog_ip:43900`.
    pub fn low_level(local_ip: IpAddr, local_port: u16, dog_ip: IpAddr) -> Self {
        Self::new(local_ip, local_port, dog_ip, LOW_LEVEL_PORT)
    }

    /// Sets the model.
    pub fn with_model(mut self, model: Model) -> Self {
        self.model = model;
        self
    }

    /// Sets the state decoding.
    pub fn with_state_decoding(mut self, decoding: StateDecoding) -> Self {
        self.state_decoding = decoding;
        self
    }

    /// Sets the watchdog timeout.
    pub fn with_watchdog(mut self, watchdog: Duration) -> Self {
        self.watchdog = watchdog;
        self
    }
}

impl Default for ClientOptions {
    /// HighLevel on `0.0.0.0:43988` to `192.168.234.1:43997`.
    fn default() -> Self {
        Self::high_level(Ipv4Addr::UNSPECIFIED.into(), DEFAULT_LOCAL_PORT, Self::DEFAULT_DOG_IP.into())
    }
}

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

/// Why a client could not start.
pub type ConnectError = UdpError<DatagramError>;

/// Why a call was refused, or what went wrong after it was accepted. Each maps to the vendor's
/// return code ([`CallError::return_code`]).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CallError {
    /// The robot reports a non-zero error word (self-check failed); nothing was changed.
    #[error("the robot reports error {0:?} (self-check failed); nothing was sent")]
    SelfCheck(ReturnCode),
    /// The robot is lying down (mode 0, 10 or 51); it must stand first. Nothing was changed.
    #[error("refused in mode {0:?}: the robot must stand first; nothing was sent")]
    LyingDown(ControlMode),
    /// `move` while a two-leg stand is active; cancel it first. Nothing was changed.
    #[error("move refused during a two-leg stand (cancel it first); nothing was sent")]
    TwoLegStandActive,
    /// The robot is moving (|vx|, |vy| or |yaw rate| above 0.2); nothing was changed.
    #[error("refused while the robot is moving (|vx|, |vy| or |yaw rate| > 0.2) in mode {0:?}; nothing was sent")]
    Running(ControlMode),
    /// `attitudeControl` with |roll| above 1.0 rad; nothing was changed.
    #[error("attitude refused: |roll| = {0} rad is above 1.0 rad; nothing was sent")]
    Unbalanced(f32),
    /// An argument is NaN, infinite or out of range; nothing was changed.
    #[error("{0}; nothing was sent")]
    Argument(#[from] ArgumentError),
    /// The call is not in this model's API (ZSL-1W `crawl`/`climb` on a ZSL-1).
    #[error("{call} is a {needs:?} call; this client is configured for {model:?}")]
    WrongModel {
        /// The call.
        call: &'static str,
        /// The model that has it.
        needs: Model,
        /// The client's model.
        model: Model,
    },
    /// The command **was** written and sent, but the robot has not reported the target mode
    /// for 11 calls in a row (the vendor's 0x3007 on the 11th miss).
    #[error(
        "the robot has not reported mode {target:?} for 11 calls in a row (it reports {reported:?}); the command was sent"
    )]
    NotAcknowledged {
        /// The mode the call asks for.
        target: ControlMode,
        /// The mode the robot reports.
        reported: ControlMode,
    },
    /// The robot raised its "SDK mismatch" flag (state 0x1F8 = 1): the client has stopped
    /// streaming for good, like the vendor's. Check the model (ZSL-1 vs ZSL-1W).
    #[error("the robot reported an SDK mismatch; this client stopped streaming (check --model)")]
    SdkMismatch,
    /// The command is latched but the immediate send failed; the 2 ms stream retries it.
    #[error("send failed ({0}); the command is latched and the stream retries it")]
    Send(std::io::Error),
}

impl CallError {
    /// The vendor's return code for this outcome.
    pub fn return_code(&self) -> ReturnCode {
        match self {
            Self::SelfCheck(word) => *word,
            Self::Argument(e) => e.return_code(),
            Self::LyingDown(_)
            | Self::TwoLegStandActive
            | Self::Running(_)
            | Self::Unbalanced(_)
            | Self::NotAcknowledged { .. }
            | Self::WrongModel { .. }
            | Self::SdkMismatch => ReturnCode::SwitchFailed,
            Self::Send(_) => ReturnCode::Queued,
        }
    }
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

/// How a client shapes its command stream.
pub(super) trait Profile: Send + Sync + 'static {
    type Command: CommandDatagram + fmt::Debug;
    type State: StateDatagram + fmt::Debug;
    /// Per-stream memory of [`Profile::before_send`].
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

type Codec<P> = ClientCodec<<P as Profile>::Command, <P as Profile>::State>;

struct Outbox<P: Profile> {
    latched: P::Command,
    sender: UdpSender<Codec<P>>,
    memory: P::SendState,
    halted: bool,
}

pub(super) struct Core<P: Profile> {
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

/// A running client: the core plus its two tasks, stopped on drop.
pub(super) struct Client<P: Profile> {
    pub(super) core: Arc<Core<P>>,
    tasks: [JoinHandle<()>; 2],
}

impl<P: Profile> Drop for Client<P> {
    fn drop(&mut self) {
        for task in &self.tasks {
            task.abort();
        }
    }
}

impl<P: Profile> Client<P> {
    /// Binds, starts the stream (idle command at once, like the vendor) and the receive loop.
    pub(super) async fn start(options: ClientOptions) -> Result<Self, ConnectError> {
        let codec = Codec::<P>::new(options.model, options.state_decoding);
        let link = UdpLink::bind(options.local, options.dog, codec).await?;
        let local = link.local_addr()?;
        let stats = link.stats_handle();
        let (sender, receiver) = link.into_split();
        let core = Arc::new(Core {
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
        let stream = tokio::spawn(stream(core.clone()));
        let receive = tokio::spawn(receive(core.clone(), receiver));
        Ok(Self { core, tasks: [stream, receive] })
    }
}

impl<P: Profile> Core<P> {
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
        outbox.sender.send(&command).await.map_err(|e| match e {
            UdpError::Io(io) => CallError::Send(io),
            other => CallError::Send(std::io::Error::other(other.to_string())),
        })
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
async fn stream<P: Profile>(core: Arc<Core<P>>) {
    let mut ticks = tokio::time::interval(core.options.period);
    ticks.set_missed_tick_behavior(MissedTickBehavior::Skip);
    loop {
        let deadline = ticks.tick().await;
        let late_us = u32::try_from(deadline.elapsed().as_micros()).unwrap_or(u32::MAX);
        if let Ok(mut ring) = core.lateness.lock() {
            ring.record(late_us);
        }
        let mut outbox = core.outbox.lock().await;
        if outbox.halted {
            continue;
        }
        // A failed send is counted by the link; the next tick tries again.
        let _ = core.transmit(&mut outbox).await;
    }
}

/// Receives state, feeds the watchdog, and handles its timeout (spec decisions 2, 3, 6).
async fn receive<P: Profile>(core: Arc<Core<P>>, mut receiver: UdpReceiver<Codec<P>>) {
    let watchdog = core.options.watchdog;
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
                    on_state(&core, &received);
                }
                // Counted by the link; a datagram that does not decode does not feed the watchdog.
                Err(UdpError::Decode(_)) => {}
                Err(_) => tokio::time::sleep(Duration::from_millis(10)).await,
            },
            () = timeout => {
                deadline = None;
                bump(&core.counters.disconnects);
                core.state.send_replace(None);
                receiver.codec_mut().reset();
                P::stop_motion(&mut core.outbox.lock().await.latched);
                core.connection.send_replace(Connection::Disconnected);
            }
        }
    }
}

fn on_state<P: Profile>(core: &Core<P>, received: &StateReceived<P::State>) {
    let c = &core.counters;
    bump(&c.states);
    if let Ok(mut gaps) = core.state_gaps.lock() {
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
        core.state.send_replace(Some(received.state));
    }
    core.connection.send_if_modified(|connection| match *connection {
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

/// The accessors HighLevel and LowLevel share, over `self.core()`.
macro_rules! client_accessors {
    ($state:ty, $command:ty) => {
        /// The whole state as received (`None` before the first state and after a timeout).
        pub fn state(&self) -> Option<$state> {
            self.core().read(|s| *s)
        }

        /// `checkConnect()`: state arrived within the watchdog timeout.
        pub fn check_connection(&self) -> bool {
            self.connection() == Connection::Connected
        }

        /// The connection now.
        pub fn connection(&self) -> Connection {
            self.core().connection()
        }

        /// Connection events: `Waiting` → `Connected` → `Disconnected` → `Connected` ….
        pub fn connection_events(&self) -> tokio::sync::watch::Receiver<Connection> {
            self.core().connection_events()
        }

        /// Every accepted state, as it arrives (`None` after a timeout).
        pub fn state_updates(&self) -> tokio::sync::watch::Receiver<Option<$state>> {
            self.core().state.subscribe()
        }

        /// Waits until a state satisfies `accept`, up to `timeout`.
        pub async fn wait_for_state(
            &self,
            timeout: std::time::Duration,
            accept: impl Fn(&$state) -> bool,
        ) -> Option<$state> {
            self.core().wait_for(timeout, accept).await
        }

        /// Waits for state, up to `timeout`; whether the client is connected.
        pub async fn wait_connected(&self, timeout: std::time::Duration) -> bool {
            self.core().wait_for(timeout, |_| true).await.is_some()
        }

        /// The command being streamed now.
        pub async fn latched_command(&self) -> $command {
            self.core().latched().await
        }

        /// Counters: link, state anomalies, disconnects, stream lateness.
        pub fn stats(&self) -> ClientStats {
            self.core().stats()
        }

        /// The bound local address.
        pub fn local_addr(&self) -> std::net::SocketAddr {
            self.core().local_addr()
        }
    };
}

pub(super) use client_accessors;
