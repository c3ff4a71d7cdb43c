//! The session with the robot that HighLevel and LowLevel share, on two threads.
//!
//! - The **stream thread** (robowire's runner) owns `zsl-proto`'s sans-IO [`CommandStream`]:
//!   it sends the latched command the moment a call changes it and every 2 ms on absolute
//!   deadlines ([`stream`](super::stream)).
//! - The **receive thread** (robowire-rt's one receive-with-watchdog loop) decodes state, feeds
//!   the watchdog, publishes stamped states and connection events, and tells the stream about
//!   states and disconnects.
//!
//! Nothing the stream thread reads is behind a lock another thread holds: calls and states
//! reach it through seqlocks ([`Latest`]), disconnects through an atomic, and what it sent
//! and how late comes back as a seqlock and atomics.

use std::net::SocketAddr;
use std::sync::Arc;
use std::sync::atomic::Ordering;

use robowire_core::timing::LatenessSummary;
use robowire_rt::Time;
use robowire_rt::device::{Receive, Received, Receiving, Stamped};
use robowire_rt::runner::{Runner, RunnerOptions};
use robowire_udp::{LinkStats, Peer, StatsHandle, UdpError, UdpLink, UdpReceiver};
use zsl_proto::codec::StateReceived;
use zsl_proto::stream::{CommandStream, Connection, Watchdog};

use super::shared::{Codec, Shared, Wire};
use super::stream::{Input, StreamJob, in_order};
use super::{CallError, ClientOptions, ConnectError};

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

/// The receive side of the link, as robowire-rt's receive loop drives it (spec decisions 2, 3,
/// 6): accepted states feed the watchdog, the stream's per-datagram rules and the user; a
/// timeout stops the latched motion.
struct StateReceiver<I: Wire> {
    receiver: UdpReceiver<Codec<I>>,
    shared: Arc<Shared<I>>,
}

impl<I: Wire> Receive for StateReceiver<I> {
    type Item = StateReceived<I::State>;
    type State = I::State;

    async fn receive(&mut self) -> Received<Self::Item> {
        match self.receiver.recv().await {
            Ok(received) => Received::Item(received),
            // Counted by the link; a datagram that does not decode does not feed the watchdog.
            Err(UdpError::Decode(_)) => Received::Rejected,
            // A socket error (counted by the link): back off instead of spinning on it.
            Err(_) => Received::Failed,
        }
    }

    fn on_item(&mut self, now: Time, received: Self::Item) -> Option<I::State> {
        let shared = &self.shared;
        shared.accepted.add(1);
        if received.update.short {
            shared.short_states.add(1);
        }
        // A 0-byte datagram only feeds the watchdog: zeros never pose as a state.
        if received.update.len == 0 {
            return None;
        }
        if !received.update.header_ok {
            shared.header_anomalies.add(1);
        }
        shared.states.write(now, &received.state);
        Some(received.state)
    }

    /// The stream stops the latched motion; the decoder forgets the last state.
    fn on_disconnected(&mut self, now: Time) {
        self.receiver.codec_mut().reset();
        self.shared.disconnected_at.store(now.as_nanos(), Ordering::Release);
        self.shared.wake();
    }
}

/// A running session: the receive thread, the stream thread and what they share. Dropping it
/// stops both after the stop burst (the latched motion stopped, sent three times).
pub(super) struct Session<I: Wire> {
    shared: Arc<Shared<I>>,
    receiving: Receiving<I::State>,
    stream: Option<Runner<StreamJob<I>>>,
    link: StatsHandle,
    local: SocketAddr,
    pub(super) options: ClientOptions,
}

impl<I: Wire> Session<I> {
    /// Binds, starts the receive thread and the stream (idle command at once, like the vendor).
    pub(super) fn open(options: ClientOptions, name: &str) -> Result<Self, ConnectError> {
        options.validate()?;
        let shared = Arc::new(Shared::<I>::new());
        let now = robowire_rt::now();
        let watchdog = Watchdog::new(now, options.watchdog);
        let (receiving, (sender, local, link)) = Receiving::spawn(&format!("{name}-receive"), watchdog, {
            let (options, shared) = (options.clone(), shared.clone());
            move || async move {
                let codec = Codec::<I>::new(options.model, options.state_decoding);
                // The robot's sending port is not documented (spec §2): accept state from any port
                // of its IP, nothing from anyone else.
                let mut link = UdpLink::bind(options.local, Peer::AnyPortOf(options.dog), codec).await?;
                link.set_tap(options.tap.clone());
                let local = link.local_addr().map_err(UdpError::from)?;
                let stats = link.stats_handle();
                let (sender, receiver) = link.into_split();
                Ok::<_, ConnectError>((StateReceiver { receiver, shared }, (sender, local, stats)))
            }
        })?;
        let job = StreamJob::new(CommandStream::new(now, options.period), sender, shared.clone());
        let stream = Runner::spawn(RunnerOptions::placed(format!("{name}-stream"), options.placement), job)?;
        let _ = shared.waker.set(stream.waker());
        Ok(Self { shared, receiving, stream: Some(stream), link, local, options })
    }

    /// Latches `command`; the stream thread sends it at once. A failed send is counted in the
    /// link's statistics and retried by the refresh.
    pub(super) fn submit(&self, command: I::Command) -> Result<(), CallError> {
        if self.halted() {
            return Err(CallError::SdkMismatch);
        }
        self.shared.calls.write(robowire_rt::now(), &command);
        self.shared.wake();
        Ok(())
    }

    /// The command being streamed: the last one sent, with what the stream thread has not
    /// taken yet applied (a call latches, a disconnect stops the motion): what goes out next,
    /// the per-datagram rules aside.
    pub(super) fn latched(&self) -> I::Command {
        let shared = &self.shared;
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
        self.shared.halted.load(Ordering::Acquire)
    }

    pub(super) fn receiving(&self) -> &Receiving<I::State> {
        &self.receiving
    }

    pub(super) fn local_addr(&self) -> SocketAddr {
        self.local
    }

    pub(super) fn stats(&self) -> ClientStats {
        let s = &self.shared;
        let feed = self.receiving.stats();
        ClientStats {
            link: self.link.get(),
            calls_sent: s.calls_sent.get(),
            refreshes_sent: s.refreshes_sent.get(),
            missed_ticks: s.missed_ticks.get(),
            states: s.accepted.get(),
            short_states: s.short_states.get(),
            header_anomalies: s.header_anomalies.get(),
            disconnects: feed.disconnects,
            reconnects: feed.reconnects,
            stream_lateness: s.lateness.summary(),
            state_gap: feed.state_gap,
        }
    }

    /// The latest state while connected: `None` before the first state and after a watchdog
    /// timeout (until state returns).
    pub(super) fn read<T>(&self, f: impl FnOnce(&I::State) -> T) -> Option<T> {
        if self.receiving.connection() != Connection::Connected {
            return None;
        }
        self.receiving.latest().map(|s: Stamped<I::State>| f(&s.state))
    }
}

/// The stop burst from the stream's last command; then the receive thread ends as the
/// `Receiving` field drops, and with it the last half of the socket.
impl<I: Wire> Drop for Session<I> {
    fn drop(&mut self) {
        if let Some(stream) = self.stream.take()
            && let Some(mut job) = stream.stop()
        {
            job.send_stop_burst();
        }
    }
}

/// The accessors and the device shape HighLevel and LowLevel share, over `self.session`.
macro_rules! client_accessors {
    ($client:ty, $interface:ty, $wire_state:ty, $state:ty, $wire_command:ty) => {
        impl $client {
            /// The state, typed (`None` before the first state and after a watchdog timeout).
            pub fn state(&self) -> Option<$state> {
                self.session.read(|s| s.into())
            }

            /// The state datagram as received, in the vendor's layout (`zsl_proto::udp`), for
            /// logging and inspection (`None` before the first state and after a timeout).
            pub fn wire_state(&self) -> Option<$wire_state> {
                self.session.read(|s| *s)
            }

            /// `checkConnect()`: state arrived within the watchdog timeout.
            pub fn check_connection(&self) -> bool {
                self.connection() == Connection::Connected
            }

            /// Waits until a state satisfies `accept`, up to `timeout` (any executor).
            pub async fn wait_for_state(
                &self,
                timeout: std::time::Duration,
                accept: impl Fn(&$state) -> bool + Send + Sync + 'static,
            ) -> Option<$state> {
                let state = self.session.receiving().wait_for(timeout, move |s| accept(&s.into())).await?;
                Some((&state.state).into())
            }

            /// Waits for state, up to `timeout`; whether the client is connected.
            pub async fn wait_connected(&self, timeout: std::time::Duration) -> bool {
                self.session.receiving().wait_for(timeout, |_| true).await.is_some()
            }

            /// The command datagram being streamed, in the vendor's layout (`zsl_proto::udp`): the
            /// last one sent, or a call's that goes out next.
            pub fn wire_command(&self) -> $wire_command {
                self.session.latched()
            }

            /// The bound local address.
            pub fn local_addr(&self) -> std::net::SocketAddr {
                self.session.local_addr()
            }

            /// The options in force.
            pub fn options(&self) -> &ClientOptions {
                &self.session.options
            }

            /// Sends the stop burst (the latched motion stopped), ends both threads and closes the
            /// socket: when this returns, the local port can be bound again. Dropping the client
            /// does the same.
            pub fn close(self) {
                drop(self);
            }
        }

        impl Device for $client {
            type State = $wire_state;
            type Stats = ClientStats;
            type Error = std::convert::Infallible;

            fn receiving(&self) -> &robowire_rt::device::Receiving<$wire_state> {
                self.session.receiving()
            }

            /// Counters: link, calls and refreshes, state anomalies, disconnects, stream lateness.
            fn stats(&self) -> ClientStats {
                self.session.stats()
            }

            fn close(self) -> Result<(), std::convert::Infallible> {
                drop(self);
                Ok(())
            }
        }
    };
}

pub(super) use client_accessors;
