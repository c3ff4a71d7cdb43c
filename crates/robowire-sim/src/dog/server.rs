//! [`DogSim`]: the [`DogModel`] on the two UDP ports of the ZSL-1, through `robowire-udp`'s
//! device side and the ZSL-1 dog codecs, so that the transport is exercised from both ends.
//!
//! A thread runs a small tokio runtime that receives commands on both ports and answers a
//! command that changes something at once; robowire's runner streams state to each client every
//! `state_period` on absolute deadlines (a late tick is sent once, the missed slots counted).

use std::io;
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::Duration;

use robowire_core::DatagramCodec;
use robowire_core::schedule::{Periodic, Time};
use robowire_core::timing::LatenessSummary;
use robowire_rt::runner::{Job, Runner, RunnerOptions};
use robowire_rt::stats::{SharedLateness, micros};
use robowire_udp::{Peer, UdpError, UdpLink, UdpReceiver, UdpSender};
use tokio::sync::watch;
use zsl_proto::codec::{HighLevelDogCodec, LowLevelDogCodec};
use zsl_proto::udp::{HIGH_LEVEL_PORT, LOW_LEVEL_PORT, Model};

use super::model::{DogFault, DogModel, Faults};

/// Simulator settings.
#[derive(Debug, Clone, PartialEq)]
pub struct DogSimConfig {
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

impl Default for DogSimConfig {
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

impl DogSimConfig {
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
pub struct DogSnapshot {
    /// The robot.
    pub dog: DogModel,
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

/// One port: its sending half and counters.
struct Port<C> {
    sender: UdpSender<C>,
    stats: PortStats,
    /// When the last valid command arrived (the kernel's stamp, or the monotonic clock).
    last_command: Option<Duration>,
}

impl<C: DatagramCodec> Port<C> {
    fn new(sender: UdpSender<C>, client: Option<SocketAddr>) -> Self {
        Self { sender, stats: PortStats { client, ..PortStats::default() }, last_command: None }
    }

    /// A valid command arrived at `stamp` (the kernel's arrival stamp: the interval on the wire,
    /// whatever the receiving thread's scheduling; without one, now); records |interval −
    /// `period`| in `jitter`.
    fn on_command(&mut self, period: Duration, jitter: &SharedLateness<4096>, stamp: Option<Duration>) {
        let at = stamp.unwrap_or_else(|| Duration::from_nanos(robowire_rt::monotonic_ns()));
        self.stats.commands += 1;
        if let Some(last) = self.last_command.replace(at) {
            jitter.record(micros(at.saturating_sub(last).abs_diff(period)));
        }
    }

    fn stats(&self, jitter: &SharedLateness<4096>) -> PortStats {
        PortStats { client: self.sender.destination(), command_jitter: jitter.summary(), ..self.stats }
    }
}

struct Shared {
    dog: DogModel,
    high: Port<HighLevelDogCodec>,
    low: Port<LowLevelDogCodec>,
    period: Duration,
    cycles: u64,
    missed_cycles: u64,
}

/// Timing statistics, kept out of the model's lock: each ring has one writer, and a reader
/// sorts its copy without holding up the state stream.
#[derive(Default)]
struct Timing {
    state_lateness: SharedLateness<4096>,
    high_level_jitter: SharedLateness<4096>,
    low_level_jitter: SharedLateness<4096>,
}

fn lock(shared: &Mutex<Shared>) -> MutexGuard<'_, Shared> {
    shared.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Junk the garbage fault sends: longer than any state, so no decoder accepts it.
const GARBAGE: [u8; 600] = [0xEE; 600];

impl<C: DatagramCodec> Port<C> {
    /// Sends `state` (or junk, or nothing, as `faults` say) to the port's client, if it has one.
    fn send_state(&mut self, faults: Faults, state: impl FnOnce() -> C::Outgoing) {
        if faults.silence || self.sender.destination().is_none() {
            return;
        }
        if faults.garbage {
            self.stats.garbage_sent += u64::from(self.sender.send_bytes_now(&GARBAGE).is_ok());
        } else {
            self.stats.states_sent += u64::from(self.sender.send_now(&state()).is_ok());
        }
    }
}

impl Shared {
    fn send_high_level(&mut self) {
        let dog = &self.dog;
        self.high.send_state(dog.faults(), || dog.high_level_state());
    }

    fn send_low_level(&mut self) {
        let dog = &self.dog;
        self.low.send_state(dog.faults(), || dog.low_level_state());
    }
}

/// The dog on two UDP ports, on its own threads; stopped on drop.
pub struct DogSim {
    shared: Arc<Mutex<Shared>>,
    timing: Arc<Timing>,
    stream: Option<Runner<StateStream>>,
    stop_receiving: watch::Sender<bool>,
    receiver: Option<JoinHandle<()>>,
    high_level_addr: SocketAddr,
    low_level_addr: SocketAddr,
}

impl std::fmt::Debug for DogSim {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DogSim")
            .field("high_level", &self.high_level_addr)
            .field("low_level", &self.low_level_addr)
            .finish_non_exhaustive()
    }
}

type Receivers = (UdpReceiver<HighLevelDogCodec>, UdpReceiver<LowLevelDogCodec>);

/// Binds both ports inside `runtime`.
fn bind(runtime: &tokio::runtime::Runtime, config: &DogSimConfig) -> io::Result<(Shared, Receivers)> {
    let reply = Peer::Any { reply_to: config.client };
    let bind_error = |port: u16, e: UdpError<zsl_proto::udp::DatagramError>| {
        let kind = match &e {
            UdpError::Bind { source, .. } => source.kind(),
            _ => io::ErrorKind::Other,
        };
        io::Error::new(kind, format!("dog simulator cannot bind {}:{port}: {}", config.bind, error_chain(&e)))
    };
    runtime.block_on(async {
        let mut high =
            UdpLink::bind(SocketAddr::new(config.bind, config.high_level_port), reply, HighLevelDogCodec::default())
                .await
                .map_err(|e| bind_error(config.high_level_port, e))?;
        let mut low =
            UdpLink::bind(SocketAddr::new(config.bind, config.low_level_port), reply, LowLevelDogCodec::default())
                .await
                .map_err(|e| bind_error(config.low_level_port, e))?;
        high.set_tap(config.high_level_tap.clone());
        low.set_tap(config.low_level_tap.clone());
        let (high_tx, high_rx) = high.into_split();
        let (low_tx, low_rx) = low.into_split();
        let shared = Shared {
            dog: DogModel::new(config.model),
            high: Port::new(high_tx, config.client),
            low: Port::new(low_tx, config.client),
            period: config.state_period,
            cycles: 0,
            missed_cycles: 0,
        };
        Ok((shared, (high_rx, low_rx)))
    })
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

impl DogSim {
    /// Binds both ports and starts the robot lying down.
    pub fn spawn(config: DogSimConfig) -> io::Result<Self> {
        let (started_tx, started) = std::sync::mpsc::sync_channel(1);
        let (stop_receiving, mut stop_rx) = watch::channel(false);
        let timing = Arc::new(Timing::default());
        let receiver = std::thread::Builder::new().name("dog-sim-rx".into()).spawn({
            let (config, timing) = (config.clone(), timing.clone());
            move || {
                let setup = || -> io::Result<_> {
                    if let Some(cpu) = config.cpu {
                        robowire_rt::pin_current_thread(cpu)
                            .map_err(|e| io::Error::new(io::ErrorKind::InvalidInput, error_chain(&e)))?;
                    }
                    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build()?;
                    let (shared, receivers) = bind(&runtime, &config)?;
                    Ok((runtime, Arc::new(Mutex::new(shared)), receivers))
                };
                let (runtime, shared, (high, low)) = match setup() {
                    Ok(ok) => ok,
                    Err(e) => {
                        let _ = started_tx.send(Err(e));
                        return;
                    }
                };
                let _ = started_tx.send(Ok(shared.clone()));
                runtime.block_on(receive(shared, &timing, high, low, &mut stop_rx));
            }
        })?;
        let shared = started.recv().map_err(|_| io::Error::other("the dog simulator thread died"))??;
        let (high_level_addr, low_level_addr) = {
            let s = lock(&shared);
            (s.high.sender.local_addr()?, s.low.sender.local_addr()?)
        };
        let job = StateStream {
            shared: shared.clone(),
            timing: timing.clone(),
            grid: Periodic::new(robowire_rt::now(), config.state_period),
            last_step: None,
        };
        let stream = Runner::spawn(
            RunnerOptions::placed("dog-sim-state", robowire_rt::Placement { cpu: config.cpu, ..Default::default() }),
            job,
        )
        .map_err(|e| io::Error::new(io::ErrorKind::InvalidInput, error_chain(&e)))?;
        Ok(Self {
            shared,
            timing,
            stream: Some(stream),
            stop_receiving,
            receiver: Some(receiver),
            high_level_addr,
            low_level_addr,
        })
    }

    /// Where HighLevel commands go.
    pub fn high_level_addr(&self) -> SocketAddr {
        self.high_level_addr
    }

    /// Where LowLevel commands go.
    pub fn low_level_addr(&self) -> SocketAddr {
        self.low_level_addr
    }

    /// Injects a fault.
    pub fn inject(&self, fault: DogFault) {
        lock(&self.shared).dog.inject(fault);
    }

    /// Clears every fault.
    pub fn clear_faults(&self) {
        lock(&self.shared).dog.clear_faults();
    }

    /// Sets the battery level, %.
    pub fn set_battery_percent(&self, percent: f32) {
        lock(&self.shared).dog.set_battery_percent(percent);
    }

    /// The robot and the counters now.
    pub fn snapshot(&self) -> DogSnapshot {
        let s = lock(&self.shared);
        DogSnapshot {
            dog: s.dog.clone(),
            high_level: s.high.stats(&self.timing.high_level_jitter),
            low_level: s.low.stats(&self.timing.low_level_jitter),
            cycles: s.cycles,
            missed_cycles: s.missed_cycles,
            state_lateness: self.timing.state_lateness.summary(),
        }
    }
}

impl Drop for DogSim {
    fn drop(&mut self) {
        if let Some(stream) = self.stream.take() {
            stream.stop();
        }
        let _ = self.stop_receiving.send(true);
        if let Some(receiver) = self.receiver.take() {
            let _ = receiver.join();
        }
    }
}

/// Receives commands on both ports until told to stop; a command that changes what the dog was
/// told to do is answered at once, before the socket is drained further (low latency for the
/// client's acknowledgement).
async fn receive(
    shared: Arc<Mutex<Shared>>,
    timing: &Timing,
    mut high: UdpReceiver<HighLevelDogCodec>,
    mut low: UdpReceiver<LowLevelDogCodec>,
    stop: &mut watch::Receiver<bool>,
) {
    // Arrival as the network stack saw it: without the stamps, the intervals are the receiving
    // thread's wake-ups. Best effort.
    let _ = (high.enable_arrival_stamps(), low.enable_arrival_stamps());
    loop {
        tokio::select! {
            _ = stop.changed() => return,
            received = high.recv_stamped() => {
                let mut s = lock(&shared);
                match received {
                    Ok(((command, model), _, stamp)) => {
                        let period = s.period;
                        s.high.on_command(period, &timing.high_level_jitter, stamp);
                        if s.dog.on_high_level(&command, model) {
                            s.send_high_level();
                        }
                    }
                    Err(UdpError::Decode(_)) => s.high.stats.invalid += 1,
                    // Socket errors are counted by the link.
                    Err(_) => {}
                }
            }
            received = low.recv_stamped() => {
                let mut s = lock(&shared);
                match received {
                    Ok(((command, _), _, stamp)) => {
                        let period = s.period;
                        s.low.on_command(period, &timing.low_level_jitter, stamp);
                        if s.dog.on_low_level(&command) {
                            s.send_low_level();
                        }
                    }
                    Err(UdpError::Decode(_)) => s.low.stats.invalid += 1,
                    Err(_) => {}
                }
            }
        }
    }
}

/// The state stream: steps the dog and sends state on each tick of the grid.
struct StateStream {
    shared: Arc<Mutex<Shared>>,
    timing: Arc<Timing>,
    grid: Periodic,
    last_step: Option<Time>,
}

/// Longest step of the model, s: after a stall the dog does not jump.
const MAX_STEP_S: f32 = 0.05;

impl Job for StateStream {
    fn next_run(&mut self) -> Option<Time> {
        Some(self.grid.deadline())
    }

    fn run(&mut self, now: Time) {
        let Some(tick) = self.grid.poll(now) else { return };
        let dt = self.last_step.replace(now).map_or(0.0, |last| now.saturating_duration_since(last).as_secs_f32());
        self.timing.state_lateness.record(micros(tick.lateness));
        let mut s = lock(&self.shared);
        s.missed_cycles += tick.skipped;
        s.dog.step(dt.min(MAX_STEP_S));
        s.cycles += 1;
        s.send_high_level();
        s.send_low_level();
    }
}
