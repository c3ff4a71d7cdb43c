//! [`Zsl1Sim`]: the [`Zsl1Model`] on the two UDP ports of the ZSL-1, through `robowire-udp`'s
//! device side and the ZSL-1 codecs, so that the transport is exercised from both ends.
//!
//! The robot lives on its state stream (robowire's polling runner): it sends state to each client
//! every `state_period` on absolute deadlines (a late tick is sent once, the missed slots counted)
//! and, between deadlines, waits on both ports' sockets itself: a command is read, applied and,
//! if it changes something, answered at once on the same thread. The handle's requests and
//! snapshots go through the crate's `handover` module: the stream takes no lock.

mod stream;

use std::io;
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::os::fd::AsFd;
use std::sync::Arc;
use std::time::Duration;

use robowire_core::DatagramCodec;
use robowire_core::schedule::Periodic;
use robowire_core::timing::LatenessSummary;
use robowire_rt::runner::{Runner, RunnerOptions, Waker};
use robowire_rt::stats::{Counter, SharedLateness};
use robowire_udp::{Peer, UdpError, UdpLink, UdpSender};
use zsl_proto::codec::{HighLevelDogCodec, LowLevelDogCodec};
use zsl_proto::udp::{HIGH_LEVEL_PORT, LOW_LEVEL_PORT, Model};

use super::model::{Faults, Zsl1Fault, Zsl1Model};
use crate::handover::{Published, Requests, StreamStats};
use stream::{Port, StateStream};

/// Simulator settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Zsl1SimConfig {
    /// Address to bind both ports on. Default 127.0.0.1.
    pub bind: IpAddr,
    /// HighLevel port (default 43997; 0 picks a free one).
    pub high_level_port: u16,
    /// LowLevel port (default 43900; 0 picks a free one).
    pub low_level_port: u16,
    /// Where to send state; default: learned from each port's command datagrams.
    pub client: Option<SocketAddr>,
    /// ZSL-1 or ZSL-1W.
    pub model: Model,
    /// State period. Default 2 ms (500 Hz).
    pub state_period: Duration,
    /// Pin the simulator's threads to this CPU (Linux), to keep them off a control loop's core.
    pub cpu: Option<usize>,
    /// Hand every HighLevel datagram sent and received to a recorder. Default `None`.
    pub high_level_tap: Option<robowire_tap::Tap>,
    /// Hand every LowLevel datagram sent and received to a recorder. Default `None`.
    pub low_level_tap: Option<robowire_tap::Tap>,
}

impl Default for Zsl1SimConfig {
    fn default() -> Self {
        Self {
            bind: Ipv4Addr::LOCALHOST.into(),
            high_level_port: HIGH_LEVEL_PORT,
            low_level_port: LOW_LEVEL_PORT,
            client: None,
            model: Model::Zsl1,
            state_period: Duration::from_millis(2),
            cpu: None,
            high_level_tap: None,
            low_level_tap: None,
        }
    }
}

impl Zsl1SimConfig {
    /// On 127.0.0.1 with free ports (tests, demos): several can run at once.
    pub fn loopback() -> Self {
        Self { high_level_port: 0, low_level_port: 0, ..Self::default() }
    }
}

/// Counters of one port.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PortStats {
    /// Valid commands received.
    pub commands: u64,
    /// Datagrams that failed strict decoding (counted, ignored).
    pub invalid: u64,
    /// State datagrams sent.
    pub states_sent: u64,
    /// Junk datagrams sent (garbage fault).
    pub garbage_sent: u64,
    /// Where state goes (learned or configured).
    pub client: Option<SocketAddr>,
    /// |interval − `state_period`| between consecutive valid commands, by the kernel's arrival
    /// stamps, µs: how evenly the client streams (calls between refreshes show as outliers).
    pub command_jitter: LatenessSummary,
}

/// What the simulator has seen and done.
#[derive(Debug, Clone)]
pub struct Zsl1Snapshot {
    /// The robot.
    pub robot: Zsl1Model,
    /// HighLevel port.
    pub high_level: PortStats,
    /// LowLevel port.
    pub low_level: PortStats,
    /// State cycles run.
    pub cycles: u64,
    /// State cycles skipped because the stream was more than a period late.
    pub missed_cycles: u64,
    /// Lateness of the state stream against its absolute deadlines, µs.
    pub state_lateness: LatenessSummary,
}

/// What the API asks of the state stream.
#[derive(Debug, Clone, Copy)]
enum Request {
    Inject(Zsl1Fault),
    ClearFaults,
    SetBatteryPercent(f32),
}

/// The counters of one port, written by the state stream, read by the handle.
#[derive(Debug, Default)]
struct PortCounters {
    commands: Counter,
    invalid: Counter,
    states_sent: Counter,
    garbage_sent: Counter,
    jitter: SharedLateness<4096>,
}

impl PortCounters {
    fn stats(&self, client: Option<SocketAddr>) -> PortStats {
        PortStats {
            commands: self.commands.get(),
            invalid: self.invalid.get(),
            states_sent: self.states_sent.get(),
            garbage_sent: self.garbage_sent.get(),
            client,
            command_jitter: self.jitter.summary(),
        }
    }
}

/// What the state stream publishes: the robot and whom each port answers.
#[derive(Debug, Clone)]
struct View {
    robot: Zsl1Model,
    high_level_client: Option<SocketAddr>,
    low_level_client: Option<SocketAddr>,
}

/// What the state stream shares with the handle, none of it a lock the stream takes.
#[derive(Debug)]
struct Handover {
    requests: Requests<Request>,
    view: Published<View>,
    stream: StreamStats<4096>,
    high_level: PortCounters,
    low_level: PortCounters,
}

/// Requests the stream has not taken yet (the API waits for each).
const REQUESTS: usize = 16;

/// Junk the garbage fault sends: longer than any state, so no decoder accepts it.
const GARBAGE: [u8; 600] = [0xEE; 600];

/// Sends `state` (or junk, or nothing, as `faults` say) to the port's client, if it has one.
fn send_state<C: DatagramCodec>(
    sender: &mut UdpSender<C>,
    counters: &PortCounters,
    faults: Faults,
    state: impl FnOnce() -> C::Outgoing,
) {
    if faults.silence || sender.destination().is_none() {
        return;
    }
    if faults.garbage {
        counters.garbage_sent.add(u64::from(sender.send_bytes_now(&GARBAGE).is_ok()));
    } else {
        counters.states_sent.add(u64::from(sender.send_now(&state()).is_ok()));
    }
}

/// The robot on two UDP ports, on its own thread; stopped on drop.
pub struct Zsl1Sim {
    handover: Arc<Handover>,
    stream: Option<Runner<StateStream>>,
    waker: Waker,
    /// Dropped after the stream, which owns the sockets.
    _reactor: Reactor,
    high_level_addr: SocketAddr,
    low_level_addr: SocketAddr,
}

impl std::fmt::Debug for Zsl1Sim {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Zsl1Sim")
            .field("high_level", &self.high_level_addr)
            .field("low_level", &self.low_level_addr)
            .finish_non_exhaustive()
    }
}

/// The runtime the sockets are registered with; nothing runs on it (the stream reads and sends
/// without it). Shut down without waiting, so that a simulator can be dropped inside an async
/// task.
struct Reactor(Option<tokio::runtime::Runtime>);

impl Drop for Reactor {
    fn drop(&mut self) {
        if let Some(runtime) = self.0.take() {
            runtime.shutdown_background();
        }
    }
}

/// Binds both ports, registered with `runtime`.
fn bind(
    runtime: &tokio::runtime::Handle,
    config: &Zsl1SimConfig,
) -> io::Result<(UdpLink<HighLevelDogCodec>, UdpLink<LowLevelDogCodec>)> {
    let reply = Peer::Any { reply_to: config.client };
    let bind_error = |port: u16, e: UdpError<zsl_proto::udp::DatagramError>| {
        let kind = match &e {
            UdpError::Bind { source, .. } => source.kind(),
            _ => io::ErrorKind::Other,
        };
        io::Error::new(kind, format!("ZSL-1 simulator cannot bind {}:{port}: {}", config.bind, error_chain(&e)))
    };
    let at = |port| SocketAddr::new(config.bind, port);
    let mut high = UdpLink::bind_in(runtime, at(config.high_level_port), reply, HighLevelDogCodec::default())
        .map_err(|e| bind_error(config.high_level_port, e))?;
    let mut low = UdpLink::bind_in(runtime, at(config.low_level_port), reply, LowLevelDogCodec::default())
        .map_err(|e| bind_error(config.low_level_port, e))?;
    high.set_tap(config.high_level_tap.clone());
    low.set_tap(config.low_level_tap.clone());
    Ok((high, low))
}

fn error_chain(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(cause) = source {
        text.push_str(&format!(": {cause}"));
        source = cause.source();
    }
    text
}

impl Zsl1Sim {
    /// Binds both ports and starts the robot lying down.
    pub fn spawn(config: Zsl1SimConfig) -> io::Result<Self> {
        let runtime = tokio::runtime::Builder::new_current_thread().enable_io().build()?;
        let bound = bind(runtime.handle(), &config);
        let reactor = Reactor(Some(runtime));
        let (high, low) = bound?;
        let (high_level_addr, low_level_addr) = (high.local_addr()?, low.local_addr()?);
        let (high, low) = (Port::new(high), Port::new(low));
        let readable = vec![high.receiver.as_fd().try_clone_to_owned()?, low.receiver.as_fd().try_clone_to_owned()?];
        let robot = Zsl1Model::new(config.model);
        let handover = Arc::new(Handover {
            requests: Requests::new(REQUESTS),
            view: Published::new(&View { robot: robot.clone(), high_level_client: None, low_level_client: None }),
            stream: StreamStats::default(),
            high_level: PortCounters::default(),
            low_level: PortCounters::default(),
        });
        let job = StateStream {
            robot,
            high,
            low,
            handover: handover.clone(),
            grid: Periodic::new(robowire_rt::now(), config.state_period),
            period: config.state_period,
            last_step: None,
        };
        let placement = robowire_rt::Placement { cpu: config.cpu, ..Default::default() };
        let stream = Runner::spawn_polling(RunnerOptions::placed("zsl1-sim-state", placement), job, readable)
            .map_err(|e| io::Error::new(io::ErrorKind::InvalidInput, error_chain(&e)))?;
        let waker = stream.waker();
        Ok(Self { handover, stream: Some(stream), waker, _reactor: reactor, high_level_addr, low_level_addr })
    }

    /// Where HighLevel commands go.
    pub fn high_level_addr(&self) -> SocketAddr {
        self.high_level_addr
    }

    /// Where LowLevel commands go.
    pub fn low_level_addr(&self) -> SocketAddr {
        self.low_level_addr
    }

    /// Hands `request` to the state stream; returns once it is in force.
    fn call(&self, request: Request) {
        self.handover.requests.call(request, || self.waker.wake());
    }

    /// Injects a fault; in force when this returns.
    pub fn inject(&self, fault: Zsl1Fault) {
        self.call(Request::Inject(fault));
    }

    /// Clears every fault.
    pub fn clear_faults(&self) {
        self.call(Request::ClearFaults);
    }

    /// Sets the battery level, %.
    pub fn set_battery_percent(&self, percent: f32) {
        self.call(Request::SetBatteryPercent(percent));
    }

    /// The robot and the counters now.
    pub fn snapshot(&self) -> Zsl1Snapshot {
        let h = &self.handover;
        let view = h.view.read();
        let stream = h.stream.summary();
        Zsl1Snapshot {
            robot: view.robot,
            high_level: h.high_level.stats(view.high_level_client),
            low_level: h.low_level.stats(view.low_level_client),
            cycles: stream.cycles,
            missed_cycles: stream.missed,
            state_lateness: stream.lateness,
        }
    }
}

impl Drop for Zsl1Sim {
    fn drop(&mut self) {
        if let Some(stream) = self.stream.take() {
            stream.stop();
        }
    }
}
