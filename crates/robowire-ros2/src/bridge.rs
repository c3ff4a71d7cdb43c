//! Several devices in one process, each a ROS 2 node in its namespace on one DDS participant.

use std::future::Future;
use std::pin::Pin;
use std::sync::Arc;
use std::time::Duration;

use robowire_dds::{DdsError, Participant, ParticipantOptions};
use robowire_sim::dog::{DogSim, DogSimConfig};
use robowire_sim::go2::{Go2Sim, Go2SimConfig};
use robowire_sim::kmc::{ChassisSim, ChassisSimConfig};
use tokio::sync::watch;
use zsl::udp::{ClientOptions, HighLevel, Model};

use crate::address::{DeviceAddress, SimKind, namespaces};
use crate::node::{Node, NodeOptions};
use crate::report::{DeviceCounters, DeviceReport};

/// What `robowire ros2` was asked to bridge, and how.
#[derive(Debug, Clone)]
pub struct BridgeOptions {
    /// The devices, in order.
    pub devices: Vec<DeviceAddress>,
    /// `--namespace`.
    pub namespace: Option<String>,
    /// DDS domain (ROS_DOMAIN_ID).
    pub domain: u16,
    /// Network interface for DDS (`None`: the library's choice).
    pub interface: Option<String>,
    /// `cmd_vel` moves the robots; without it the bridge only publishes.
    pub armed: bool,
    /// A `cmd_vel` older than this stops the robot. Default 0.5 s.
    pub deadman: Duration,
    /// Publish at most this often per topic, Hz.
    pub rate_cap_hz: Option<f64>,
}

impl BridgeOptions {
    /// `devices` on domain 0, unarmed, deadman 0.5 s, native rates.
    pub fn new(devices: Vec<DeviceAddress>) -> Self {
        Self {
            devices,
            namespace: None,
            domain: 0,
            interface: None,
            armed: false,
            deadman: Duration::from_millis(500),
            rate_cap_hz: None,
        }
    }
}

/// Why the bridge could not start or stopped.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BridgeError {
    /// A bad option.
    #[error("{0}")]
    Option(String),
    /// DDS.
    #[error(transparent)]
    Dds(#[from] DdsError),
    /// A device could not be opened.
    #[error("{device}: {reason}")]
    Device {
        /// The device's address.
        device: String,
        /// Why.
        reason: String,
    },
}

/// One bridged device: its address, namespace and counters.
#[derive(Debug)]
pub struct BridgedDevice {
    /// The address given.
    pub address: DeviceAddress,
    /// Its namespace (`""`: the root).
    pub namespace: String,
    /// Its counters, live.
    pub report: Arc<DeviceReport>,
}

impl BridgedDevice {
    /// The counters now.
    pub fn counters(&self) -> DeviceCounters {
        self.report.counters()
    }
}

type DeviceFuture<'a> = Pin<Box<dyn Future<Output = Result<(), BridgeError>> + Send + 'a>>;

/// Runs the bridge until `stop` is set, then stops every device (chassis stop burst, dog
/// stop) before returning. `started` receives the devices once every one is open.
pub async fn run(
    options: BridgeOptions,
    stop: watch::Receiver<bool>,
    started: impl FnOnce(&[BridgedDevice]) + Send,
) -> Result<Vec<BridgedDevice>, BridgeError> {
    if options.devices.is_empty() {
        return Err(BridgeError::Option("no --device given".into()));
    }
    if !(options.deadman > Duration::ZERO && options.deadman <= Duration::from_secs(60)) {
        return Err(BridgeError::Option(format!("--deadman {:?} is outside (0, 60 s]", options.deadman)));
    }
    if let Some(hz) = options.rate_cap_hz
        && !(hz.is_finite() && hz > 0.0 && hz <= 10_000.0)
    {
        return Err(BridgeError::Option(format!("--rate {hz} Hz is outside (0, 10000]")));
    }
    let participant = Participant::new(ParticipantOptions::new(options.domain, options.interface.as_deref()))?;
    let spaces = namespaces(&options.devices, options.namespace.as_deref());
    let devices: Vec<BridgedDevice> = options
        .devices
        .iter()
        .zip(spaces)
        .map(|(address, namespace)| BridgedDevice { address: address.clone(), namespace, report: Arc::default() })
        .collect();
    let mut opened = Vec::new();
    for device in &devices {
        opened.push(open(&device.address, &options).await?);
    }
    started(&devices);
    let runs: Vec<DeviceFuture<'_>> = devices
        .iter()
        .zip(&opened)
        .map(|(device, open)| {
            let node = Node {
                participant: &participant,
                options: NodeOptions {
                    namespace: device.namespace.clone(),
                    armed: options.armed,
                    deadman: options.deadman,
                    rate_cap_hz: options.rate_cap_hz,
                },
            };
            let mut stop = stop.clone();
            let stopped = async move {
                let _ = stop.wait_for(|s| *s).await;
            };
            let report = &*device.report;
            let run: DeviceFuture<'_> = match open {
                Opened::Kmc { driver, .. } => {
                    Box::pin(async move { Ok(crate::kmc::run(node, driver, report, stopped).await?) })
                }
                Opened::Zsl { dog, model, .. } => {
                    Box::pin(async move { Ok(crate::zsl::run(node, dog, *model, report, stopped).await?) })
                }
                Opened::Go2 { robot, .. } => {
                    Box::pin(async move { Ok(crate::go2::run(node, robot, report, stopped).await?) })
                }
            };
            run
        })
        .collect();
    let outcome = futures::future::try_join_all(runs).await;
    for device in opened {
        device.close().await;
    }
    outcome.map(|_| devices)
}

/// An open device with the simulator it needs, if any.
enum Opened {
    Kmc { driver: kmc::Driver, _sim: Option<ChassisSim> },
    Zsl { dog: HighLevel, model: Model, _sim: Option<DogSim> },
    Go2 { robot: Box<go2::LowLevel<go2::Go2>>, _sim: Option<Go2Sim> },
}

impl Opened {
    /// Stops the device safely: the chassis's stop burst, the dog's stop and socket.
    async fn close(self) {
        match self {
            Self::Kmc { mut driver, .. } => {
                let _ = driver.stop();
            }
            Self::Zsl { dog, .. } => {
                let _ = dog.move_velocity(0.0, 0.0, 0.0).await;
                dog.close().await;
            }
            Self::Go2 { .. } => {}
        }
    }
}

async fn open(address: &DeviceAddress, options: &BridgeOptions) -> Result<Opened, BridgeError> {
    let failed = |reason: String| BridgeError::Device { device: format!("{address:?}"), reason };
    let kmc_options = kmc::DriverOptions { poll_battery: true, poll_allstate: true, ..Default::default() };
    let go2_options = |interface: Option<&str>| go2::LowLevelOptions {
        participant: ParticipantOptions::new(options.domain, interface),
        ..Default::default()
    };
    match address {
        DeviceAddress::Kmc(path) => {
            let mut driver = kmc::Driver::new(path, kmc_options).map_err(|e| failed(e.to_string()))?;
            driver.start().map_err(|e| failed(e.to_string()))?;
            Ok(Opened::Kmc { driver, _sim: None })
        }
        DeviceAddress::Sim(SimKind::Kmc) => {
            let sim = ChassisSim::spawn(ChassisSimConfig::default()).map_err(|e| failed(e.to_string()))?;
            let mut driver = kmc::Driver::new(sim.path(), kmc_options).map_err(|e| failed(e.to_string()))?;
            driver.start().map_err(|e| failed(e.to_string()))?;
            Ok(Opened::Kmc { driver, _sim: Some(sim) })
        }
        DeviceAddress::Zsl { wheeled, ip } => {
            let model = if *wheeled { Model::Zsl1W } else { Model::Zsl1 };
            let client =
                ClientOptions::high_level(std::net::Ipv4Addr::UNSPECIFIED.into(), 43988, *ip).with_model(model);
            let dog = HighLevel::connect(client).await.map_err(|e| failed(e.to_string()))?;
            Ok(Opened::Zsl { dog, model, _sim: None })
        }
        DeviceAddress::Sim(kind @ (SimKind::Zsl1 | SimKind::Zsl1w)) => {
            let model = if *kind == SimKind::Zsl1w { Model::Zsl1W } else { Model::Zsl1 };
            let sim =
                DogSim::spawn(DogSimConfig { model, ..DogSimConfig::loopback() }).map_err(|e| failed(e.to_string()))?;
            let client = ClientOptions {
                dog: sim.high_level_addr(),
                ..ClientOptions::high_level(std::net::Ipv4Addr::LOCALHOST.into(), 0, sim.high_level_addr().ip())
            }
            .with_model(model);
            let dog = HighLevel::connect(client).await.map_err(|e| failed(e.to_string()))?;
            Ok(Opened::Zsl { dog, model, _sim: Some(sim) })
        }
        DeviceAddress::Go2 { interface } => {
            let robot = go2::LowLevel::<go2::Go2>::connect(go2_options(Some(interface)))
                .await
                .map_err(|e| failed(e.to_string()))?;
            Ok(Opened::Go2 { robot: Box::new(robot), _sim: None })
        }
        DeviceAddress::Sim(SimKind::Go2) => {
            let interface = options.interface.as_deref();
            let sim = Go2Sim::spawn(Go2SimConfig {
                participant: ParticipantOptions::new(options.domain, interface),
                ..Go2SimConfig::default()
            })
            .map_err(|e| failed(e.to_string()))?;
            let robot =
                go2::LowLevel::<go2::Go2>::connect(go2_options(interface)).await.map_err(|e| failed(e.to_string()))?;
            Ok(Opened::Go2 { robot: Box::new(robot), _sim: Some(sim) })
        }
    }
}
