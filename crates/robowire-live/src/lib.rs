#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod front;
mod head;
mod messages;
mod page;
mod pump;
mod relay;
mod resubscribe;
mod ws_frame;

use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

use foxglove::{ChannelBuilder, Context, RawChannel, WebSocketServer, WebSocketServerHandle};
use robowire_core::json::{JsonFrame, LinkPlots};
use robowire_core::kinematics::Kinematics;
use robowire_tap::{LinkRegistry, RecordLinks, TapRing};
use serde_json::json;

pub use messages::Level;

/// How a live view runs.
#[derive(Debug, Clone)]
pub struct LiveOptions {
    /// At most this many messages a second per link, direction and frame length (a stand-in
    /// for the message type that costs no decoding), and 16 times as many per link and
    /// direction, reach the viewers; every frame is counted.
    pub rate_hz: f64,
    /// The plots the page draws, by protocol (each codec's `PLOTS`).
    pub plots: Vec<&'static LinkPlots>,
    /// The robots whose bodies are placed from their states' joint positions (`/tf_joints`),
    /// each for the devices of its name.
    pub robots: Vec<&'static Kinematics>,
    /// The server's name, as Foxglove shows it.
    pub name: String,
    /// Slots of the taps' ring ([`TapRing::with_slots`]): frames waiting for the live view's
    /// thread, at most; more are dropped and counted.
    pub ring_slots: usize,
}

impl Default for LiveOptions {
    fn default() -> Self {
        Self { rate_hz: 50.0, plots: Vec::new(), robots: Vec::new(), name: "robowire".into(), ring_slots: 4096 }
    }
}

/// Why a live view did not start.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LiveError {
    /// The rate is not a number of messages a second.
    #[error("live rate {0} Hz: a finite rate above 0 and at most 10000 Hz")]
    Rate(f64),
    /// The address is taken or not this machine's.
    #[error("listening on {addr}: {source}")]
    Bind {
        /// The address asked for.
        addr: SocketAddr,
        /// Why.
        source: std::io::Error,
    },
    /// The runtime's threads could not start.
    #[error("starting the live view's threads: {0}")]
    Threads(std::io::Error),
    /// Foxglove's server did not start.
    #[error("starting Foxglove's WebSocket server: {0}")]
    Foxglove(String),
}

/// What one link and direction got: frames seen, sent to the viewers, not decodable.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct LinkCount {
    /// `/{link}/{direction}`.
    pub topic: String,
    /// Frames tapped.
    pub seen: u64,
    /// Frames let through to the viewers.
    pub sent: u64,
    /// Of those, frames the link's description could not decode.
    pub undecodable: u64,
}

/// What one viewer got and lost.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ViewerCount {
    /// Its address.
    pub addr: SocketAddr,
    /// Messages passed to it.
    pub forwarded: u64,
    /// Data messages dropped because it did not read them.
    pub dropped: u64,
}

/// A live view's counts, as of its last second.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct LiveStats {
    /// Per link and direction.
    pub links: Vec<LinkCount>,
    /// Per viewer connected.
    pub viewers: Vec<ViewerCount>,
    /// Data messages dropped for slow viewers, all viewers ever (those gone too).
    pub viewer_dropped_total: u64,
    /// Frames the taps dropped because the live view's thread fell behind.
    pub ring_dropped: u64,
}

/// Events for the viewers (`/robowire/log`, `foxglove.Log`) and where a robot's base is
/// (`/tf`), from any thread.
#[derive(Clone)]
pub struct LiveEvents {
    channel: Arc<RawChannel>,
    transforms: Arc<RawChannel>,
    /// `/tf_joints`: a robot's bodies, by [`LiveOptions::robots`].
    joints: Arc<RawChannel>,
    robots: Arc<[&'static Kinematics]>,
    /// Devices whose base is given by [`base_pose`](Self::base_pose): no attitude from their
    /// IMU is sent for them.
    posed: Arc<Mutex<Vec<String>>>,
}

impl std::fmt::Debug for LiveEvents {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LiveEvents").finish_non_exhaustive()
    }
}

impl LiveEvents {
    /// `message` about `name` (a device: `go2`) at `level`.
    pub fn log(&self, level: Level, name: &str, message: &str) {
        messages::log(&self.channel, level, name, message);
    }

    /// Whether `device`'s base is given by [`base_pose`](Self::base_pose).
    pub(crate) fn posed(&self, device: &str) -> bool {
        self.posed.lock().unwrap_or_else(PoisonError::into_inner).iter().any(|d| d == device)
    }

    /// `device`'s bodies from its decoded `state`, if a robot of its name has a table and the
    /// state is that robot's.
    pub(crate) fn joints(&self, device: &str, state: &JsonFrame, meta: foxglove::PartialMetadata) {
        let unix_ns = meta.log_time.unwrap_or(0);
        let robot = self.robots.iter().find(|r| r.robot == device && r.state_schema == state.schema);
        if let Some(transforms) = robot.and_then(|r| messages::joint_transforms(device, r, &state.value, unix_ns))
            && let Ok(bytes) = serde_json::to_vec(&transforms)
        {
            self.joints.log_with_meta(&bytes, meta);
        }
    }

    /// `device`'s base (`{device}/base`) in the world: its position, m, and roll, pitch, yaw
    /// (ZYX), rad, as a simulator's physics has it. From then on, this is the device's base and
    /// its IMU's attitude is not sent.
    pub fn base_pose(&self, device: &str, position_m: [f64; 3], rpy_rad: [f64; 3]) {
        {
            let mut posed = self.posed.lock().unwrap_or_else(PoisonError::into_inner);
            if !posed.iter().any(|d| d == device) {
                posed.push(device.to_owned());
            }
        }
        let transform = messages::base_transform(device, position_m, rpy_rad, messages::unix_now_ns());
        self.transforms.log(&serde_json::to_vec(&transform).unwrap_or_default());
    }
}

/// A live view: Foxglove's WebSocket protocol and the built-in page on one address, fed by the
/// taps of [`links`](Self::links). Stops on drop.
pub struct LiveServer {
    addr: SocketAddr,
    ring: TapRing,
    links: RecordLinks,
    events: LiveEvents,
    stats: Arc<Mutex<LiveStats>>,
    viewers: Arc<relay::Viewers>,
    stop: Arc<AtomicBool>,
    pump: Option<std::thread::JoinHandle<()>>,
    foxglove: Option<WebSocketServerHandle>,
    runtime: Background,
}

/// The view's runtime, shut down in the background when dropped: a runtime dropped outright
/// inside another one panics, and a caller may be inside one.
struct Background(Option<tokio::runtime::Runtime>);

impl Background {
    fn handle(&self) -> tokio::runtime::Handle {
        match &self.0 {
            Some(runtime) => runtime.handle().clone(),
            None => unreachable!("taken only on drop"),
        }
    }
}

impl Drop for Background {
    fn drop(&mut self) {
        if let Some(runtime) = self.0.take() {
            runtime.shutdown_background();
        }
    }
}

impl std::fmt::Debug for LiveServer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LiveServer").field("addr", &self.addr).finish_non_exhaustive()
    }
}

/// The page's `/plots.json`: every link registered so far with its protocol's panels.
struct Plots {
    registry: LinkRegistry,
    plots: Vec<&'static LinkPlots>,
}

impl front::Site for Plots {
    fn plots_json(&self) -> Vec<u8> {
        let links: Vec<_> = pump::registered(&self.registry)
            .into_iter()
            .map(|(link, protocol)| {
                let panels = self.plots.iter().filter(|p| p.protocol == protocol).flat_map(|p| p.panels.iter());
                let panels: Vec<_> = panels
                    .map(|panel| {
                        let series: Vec<_> = panel
                            .series
                            .iter()
                            .map(|s| {
                                json!({ "name": s.name, "direction": s.direction.name(), "schema": s.schema,
                                        "pointer": s.pointer, "held": s.held, "range": [s.range.0, s.range.1] })
                            })
                            .collect();
                        json!({ "title": panel.title, "y_label": panel.y_label, "series": series })
                    })
                    .collect();
                json!({ "link": link, "protocol": protocol, "panels": panels })
            })
            .collect();
        serde_json::to_vec(&json!({ "links": links })).unwrap_or_default()
    }
}

impl LiveServer {
    /// Listens on `addr` (port 0: any free port) and starts the view's threads: one runtime
    /// thread (the server, the page, the viewers) and one that empties the taps' ring.
    ///
    /// ```
    /// use robowire_live::{LiveOptions, LiveServer};
    ///
    /// let live = LiveServer::start("127.0.0.1:0".parse().unwrap(), LiveOptions::default()).unwrap();
    /// let tap = live.links().link("kmc/serial", &robowire_core::json::SKIPPED_BYTES);
    /// tap.record(robowire_core::Direction::Sent, &[0xA5]);
    /// println!("open http://{}/", live.addr());
    /// live.stop();
    /// ```
    pub fn start(addr: SocketAddr, options: LiveOptions) -> Result<Self, LiveError> {
        if !(options.rate_hz.is_finite() && options.rate_hz > 0.0 && options.rate_hz <= 10_000.0) {
            return Err(LiveError::Rate(options.rate_hz));
        }
        // Set up on a thread of its own: the caller may be inside a runtime, where another
        // runtime cannot block.
        let context = Context::new();
        let (runtime, listener, foxglove) =
            std::thread::scope(|s| s.spawn(|| serve(addr, &options.name, &context)).join())
                .map_err(|_| LiveError::Foxglove("its set-up panicked".into()))??;
        let addr = listener.local_addr().map_err(|source| LiveError::Bind { addr, source })?;
        let upstream = SocketAddr::from(([127, 0, 0, 1], foxglove.port()));
        let channel = |topic: &str, schema| {
            ChannelBuilder::new(topic)
                .context(&context)
                .message_encoding("json")
                .schema(schema)
                .build_raw()
                .map_err(|e| LiveError::Foxglove(e.to_string()))
        };
        let log = channel("/robowire/log", messages::log_schema())?;
        let transforms = channel("/tf", messages::frame_transform_schema())?;
        let joints = channel("/tf_joints", messages::frame_transforms_schema())?;
        let robots = options.robots.clone().into();
        let events = LiveEvents { channel: log, transforms, joints, robots, posed: Arc::default() };
        let (ring, registry) = (TapRing::with_slots(options.ring_slots), LinkRegistry::default());
        let viewers = Arc::new(relay::Viewers::default());
        let site = Arc::new(Plots { registry: registry.clone(), plots: options.plots.clone() });
        let (viewers_for_pump, viewers_for_server) = (viewers.clone(), viewers.clone());
        runtime.handle().spawn(async move {
            // Registered with the runtime that polls it.
            if let Ok(listener) = tokio::net::TcpListener::from_std(listener) {
                front::serve(listener, upstream, site, viewers).await;
            }
        });
        let stats = Arc::new(Mutex::new(LiveStats::default()));
        let period_ns = (1e9 / options.rate_hz) as u64;
        let stop = Arc::new(AtomicBool::new(false));
        let viewers = viewers_for_pump;
        let pump =
            pump::Pump::new(ring.clone(), registry.clone(), context, period_ns, viewers, stats.clone(), events.clone());
        let pump = {
            let stop = stop.clone();
            std::thread::Builder::new()
                .name("robowire-live-pump".into())
                .spawn(move || pump.run(&stop))
                .map_err(LiveError::Threads)?
        };
        Ok(Self {
            addr,
            ring: ring.clone(),
            links: RecordLinks::new(ring, registry),
            events,
            stats,
            viewers: viewers_for_server,
            stop,
            pump: Some(pump),
            foxglove: Some(foxglove),
            runtime,
        })
    }

    /// Where viewers connect: `ws://ADDR/` for Foxglove, `http://ADDR/` for the page.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// Registers links whose taps feed this view (as a capture's do; [`RecordLinks::and`] feeds
    /// both).
    pub fn links(&self) -> RecordLinks {
        self.links.clone()
    }

    /// Where events go to the viewers.
    pub fn events(&self) -> LiveEvents {
        self.events.clone()
    }

    /// Waits until a viewer is connected (Foxglove or the page), at most `within`: whether one
    /// is. For a run that would otherwise be over before anyone looks (the demo).
    pub fn wait_for_viewer(&self, within: std::time::Duration) -> bool {
        let deadline = std::time::Instant::now() + within;
        loop {
            if !self.viewers.connected().is_empty() {
                return true;
            }
            if std::time::Instant::now() >= deadline {
                return false;
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
    }

    /// The counts as of the last second.
    pub fn stats(&self) -> LiveStats {
        self.stats.lock().unwrap_or_else(PoisonError::into_inner).clone()
    }

    /// Stops serving: what is in the ring is sent, viewers are disconnected; the final counts.
    pub fn stop(mut self) -> LiveStats {
        self.shut_down();
        self.stats()
    }

    fn shut_down(&mut self) {
        // Taps drop from now on; what the ring holds is sent.
        self.ring.close();
        self.stop.store(true, Ordering::Release);
        if let Some(pump) = self.pump.take() {
            pump.thread().unpark();
            let _ = pump.join();
        }
        if let Some(server) = self.foxglove.take() {
            // Dropping the handle aborts the viewers' tasks.
            drop(server.stop());
        }
        if let Some(runtime) = self.runtime.0.take() {
            runtime.shutdown_background();
        }
    }
}

/// The runtime, the front's listener (non-blocking, for the runtime to take) and Foxglove's server
/// on a private port.
fn serve(
    addr: SocketAddr,
    name: &str,
    context: &Arc<Context>,
) -> Result<(Background, std::net::TcpListener, WebSocketServerHandle), LiveError> {
    let runtime = Background(Some(
        tokio::runtime::Builder::new_multi_thread()
            .worker_threads(1)
            .thread_name("robowire-live")
            .enable_all()
            .build()
            .map_err(LiveError::Threads)?,
    ));
    let handle = runtime.handle();
    let listener = std::net::TcpListener::bind(addr).map_err(|source| LiveError::Bind { addr, source })?;
    listener.set_nonblocking(true).map_err(|source| LiveError::Bind { addr, source })?;
    let server = WebSocketServer::new().name(name).context(context).bind("127.0.0.1", 0).tokio_runtime(&handle);
    let foxglove = handle.block_on(server.start()).map_err(|e| LiveError::Foxglove(e.to_string()))?;
    Ok((runtime, listener, foxglove))
}

impl Drop for LiveServer {
    fn drop(&mut self) {
        self.shut_down();
    }
}
