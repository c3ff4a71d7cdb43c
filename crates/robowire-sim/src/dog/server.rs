//! [`DogSim`]: the [`DogModel`] on the two UDP ports of the ZSL-1, through `robowire-udp`'s
//! device side and the ZSL-1 dog codecs, so that the transport is exercised from both ends.
//!
//! A thread runs a small tokio runtime that receives commands on both ports and answers a
//! command that changes something at once; a second thread streams state to each client every
//! `state_period` on absolute deadlines.

use std::io;
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use robowire_core::DatagramCodec;
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
}

/// One port: its sending half and counters.
struct Port<C> {
    sender: UdpSender<C>,
    stats: PortStats,
}

struct Shared {
    dog: DogModel,
    high: Port<HighLevelDogCodec>,
    low: Port<LowLevelDogCodec>,
    cycles: u64,
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
    stop: Arc<AtomicBool>,
    stop_receiving: watch::Sender<bool>,
    threads: Vec<JoinHandle<()>>,
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
        let high =
            UdpLink::bind(SocketAddr::new(config.bind, config.high_level_port), reply, HighLevelDogCodec::default())
                .await
                .map_err(|e| bind_error(config.high_level_port, e))?;
        let low =
            UdpLink::bind(SocketAddr::new(config.bind, config.low_level_port), reply, LowLevelDogCodec::default())
                .await
                .map_err(|e| bind_error(config.low_level_port, e))?;
        let (high_tx, high_rx) = high.into_split();
        let (low_tx, low_rx) = low.into_split();
        let shared = Shared {
            dog: DogModel::new(config.model),
            high: Port { sender: high_tx, stats: PortStats { client: config.client, ..PortStats::default() } },
            low: Port { sender: low_tx, stats: PortStats { client: config.client, ..PortStats::default() } },
            cycles: 0,
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
        let receiver = std::thread::Builder::new().name("dog-sim-rx".into()).spawn({
            let config = config.clone();
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
                runtime.block_on(receive(shared, high, low, &mut stop_rx));
            }
        })?;
        let shared = started.recv().map_err(|_| io::Error::other("the dog simulator thread died"))??;
        let (high_level_addr, low_level_addr) = {
            let s = lock(&shared);
            (s.high.sender.local_addr()?, s.low.sender.local_addr()?)
        };
        let stop = Arc::new(AtomicBool::new(false));
        let stream = std::thread::Builder::new().name("dog-sim-state".into()).spawn({
            let (shared, stop, config) = (shared.clone(), stop.clone(), config.clone());
            move || {
                if let Some(cpu) = config.cpu {
                    let _ = robowire_rt::pin_current_thread(cpu);
                }
                stream_state(&shared, &stop, config.state_period);
            }
        })?;
        Ok(Self { shared, stop, stop_receiving, threads: vec![receiver, stream], high_level_addr, low_level_addr })
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
        let port = |stats: PortStats, client: Option<SocketAddr>| PortStats { client, ..stats };
        DogSnapshot {
            dog: s.dog.clone(),
            high_level: port(s.high.stats, s.high.sender.destination()),
            low_level: port(s.low.stats, s.low.sender.destination()),
            cycles: s.cycles,
        }
    }
}

impl Drop for DogSim {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        let _ = self.stop_receiving.send(true);
        for thread in self.threads.drain(..) {
            let _ = thread.join();
        }
    }
}

/// Receives commands on both ports until told to stop; a command that changes what the dog was
/// told to do is answered at once, before the socket is drained further (low latency for the
/// client's acknowledgement).
async fn receive(
    shared: Arc<Mutex<Shared>>,
    mut high: UdpReceiver<HighLevelDogCodec>,
    mut low: UdpReceiver<LowLevelDogCodec>,
    stop: &mut watch::Receiver<bool>,
) {
    loop {
        tokio::select! {
            _ = stop.changed() => return,
            received = high.recv() => {
                let mut s = lock(&shared);
                match received {
                    Ok((command, model)) => {
                        s.high.stats.commands += 1;
                        if s.dog.on_high_level(&command, model) {
                            s.send_high_level();
                        }
                    }
                    Err(UdpError::Decode(_)) => s.high.stats.invalid += 1,
                    // Socket errors are counted by the link.
                    Err(_) => {}
                }
            }
            received = low.recv() => {
                let mut s = lock(&shared);
                match received {
                    Ok((command, _)) => {
                        s.low.stats.commands += 1;
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

/// Steps the dog and sends state every `period` on absolute deadlines; more than ten periods
/// behind, the grid restarts from now.
fn stream_state(shared: &Mutex<Shared>, stop: &AtomicBool, period: Duration) {
    let mut next = Instant::now() + period;
    let mut last_step = Instant::now();
    while !stop.load(Ordering::Relaxed) {
        std::thread::sleep(next.saturating_duration_since(Instant::now()));
        let now = Instant::now();
        let dt = now.duration_since(last_step).as_secs_f32().min(0.05);
        last_step = now;
        {
            let mut s = lock(shared);
            s.dog.step(dt);
            s.cycles += 1;
            s.send_high_level();
            s.send_low_level();
        }
        next += period;
        if now > next + period * 10 {
            next = now + period;
        }
    }
}
