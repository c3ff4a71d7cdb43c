//! Several devices in one process, each a ROS 2 node in its namespace on one DDS participant.

use std::future::Future;
use std::pin::Pin;
use std::sync::Arc;
use std::time::Duration;

use robowire_dds::{Participant, ParticipantOptions};
use robowire_devices::{AnyDevice, DeviceAddress, OpenOptions, SimPhysics};
use robowire_record::RecordLinks;
use tokio::sync::watch;

use ros2_proto::rmw_dds_common::NAME_BOUND;

use crate::error::BridgeError;
use crate::graph::{RosDistro, RosGraph};
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
    /// Record every ROS 2 topic the bridge publishes or takes (as `cdr` under its `ros2msg`
    /// definition, on the ROS topic) with this recorder.
    pub record: Option<RecordLinks>,
    /// Record every device's own links with this recorder, under the device's namespace
    /// (`kmc0/kmc/serial`).
    pub record_devices: Option<RecordLinks>,
    /// The layout of `ros_discovery_info` (the nodes in the ROS graph): Humble's 24-byte GIDs
    /// or Jazzy's 16-byte ones. Default Jazzy.
    pub ros_distro: RosDistro,
    /// MuJoCo physics behind the `sim:go2` and `sim:g1` devices (`--physics`; robowire-devices'
    /// feature `mujoco`); any other device asked for it fails to open
    /// (`robowire_devices::DeviceError::NoPhysics`). `None`: their kinematic bodies.
    pub sim_physics: Option<SimPhysics>,
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
            record: None,
            record_devices: None,
            ros_distro: RosDistro::default(),
            sim_physics: None,
        }
    }
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

/// The namespace of each device: with one device and no `--namespace`, the root; with one
/// device and a namespace, that namespace; with several, `NS/KIND INDEX`, the index counted per
/// kind (`/kmc0`, `/kmc1`, `/zsl1_0`: an underscore after a kind that ends in a digit).
pub fn namespaces(devices: &[DeviceAddress], namespace: Option<&str>) -> Vec<String> {
    let base = namespace.map(|ns| ns.trim_matches('/')).filter(|ns| !ns.is_empty());
    if devices.len() == 1 {
        return vec![base.map(|ns| format!("/{ns}")).unwrap_or_default()];
    }
    devices
        .iter()
        .enumerate()
        .map(|(n, device)| {
            let kind = device.kind();
            let i = devices[..n].iter().filter(|d| d.kind() == kind).count();
            let kind = kind.name();
            let sep = if kind.ends_with(|c: char| c.is_ascii_digit()) { "_" } else { "" };
            let own = format!("{kind}{sep}{i}");
            match base {
                Some(ns) => format!("/{ns}/{own}"),
                None => format!("/{own}"),
            }
        })
        .collect()
}

/// How long the bridge waits at its stop for `ros_discovery_info`'s readers to acknowledge that
/// its nodes are gone.
const GRAPH_GOODBYE: Duration = Duration::from_secs(1);

/// Runs the bridge until `stop` is set, then stops every device (chassis stop burst, dog
/// stop) and removes its nodes from the ROS graph before returning. `started` receives the
/// devices once every one is open.
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
    // The participant's USER_DATA says its enclave, as rmw's participants do.
    let participant = Participant::new(ParticipantOptions {
        user_data: crate::graph::ENCLAVE_USER_DATA.to_vec(),
        ..ParticipantOptions::new(options.domain, options.interface.as_deref())
    })?;
    let spaces = namespaces(&options.devices, options.namespace.as_deref());
    if let Some(long) = spaces.iter().find(|ns| ns.len() > NAME_BOUND) {
        return Err(BridgeError::Option(format!("namespace {long:?} is longer than ROS 2's {NAME_BOUND} bytes")));
    }
    let graph = RosGraph::new(&participant, options.ros_distro)?;
    let devices: Vec<BridgedDevice> = options
        .devices
        .iter()
        .zip(spaces)
        .map(|(address, namespace)| BridgedDevice { address: address.clone(), namespace, report: Arc::default() })
        .collect();
    let mut opened: Vec<Arc<AnyDevice>> = Vec::new();
    for device in &devices {
        let failed = |source| BridgeError::Device { address: device.address.clone(), source };
        // A device's own links are recorded under its namespace (`kmc0/kmc/serial`), beside its
        // ROS topics (`kmc0/odom`).
        let namespace = device.namespace.trim_matches('/');
        let open_options = OpenOptions {
            domain: options.domain,
            sim_interface: options.interface.clone(),
            record: options
                .record_devices
                .as_ref()
                .map(|r| if namespace.is_empty() { r.clone() } else { r.under(namespace) }),
            sim_physics: options.sim_physics.clone(),
            ..OpenOptions::default()
        };
        opened.push(Arc::new(robowire_devices::open(&device.address, &open_options).map_err(failed)?));
    }
    let ids: Vec<_> = devices.iter().map(|d| graph.add_node(&d.namespace)).collect();
    started(&devices);
    let stopped = |mut stop: watch::Receiver<bool>| async move {
        let _ = stop.wait_for(|s| *s).await;
    };
    let mut runs: Vec<DeviceFuture<'_>> = devices
        .iter()
        .zip(&opened)
        .zip(ids)
        .map(|((device, open), id)| {
            let node = Node {
                participant: &participant,
                graph: &graph,
                id,
                options: NodeOptions {
                    namespace: device.namespace.clone(),
                    armed: options.armed,
                    deadman: options.deadman,
                    rate_cap_hz: options.rate_cap_hz,
                    record: options.record.clone(),
                },
            };
            let report = device.report.clone();
            let run: DeviceFuture<'_> = Box::pin(crate::device::run(node, open.clone(), report, stopped(stop.clone())));
            run
        })
        .collect();
    runs.push(Box::pin(graph.warn_on_other_layout(&participant, stopped(stop.clone()))));
    let outcome = futures::future::try_join_all(runs).await;
    // Each device's safe action (the chassis's stop burst, the dog's stop, damping) on close,
    // first; then the nodes leave the graph.
    for device in opened {
        let address = device.address().clone();
        // The runs, and the `cmd_vel` listeners with them, are gone: each device is held here only.
        let Ok(device) = Arc::try_unwrap(device) else {
            eprintln!("{address}: still in use at close; dropped without its close");
            continue;
        };
        if let Err(e) = device.close() {
            eprintln!("{address}: closing: {}", robowire_devices::error_chain(&e));
        }
    }
    if let Err(e) = graph.stop(GRAPH_GOODBYE).await {
        eprintln!("ros2: removing the nodes from the ROS graph: {e}");
    }
    outcome.map(|_| devices)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_device_is_at_the_root_several_by_kind_and_index() {
        let kmc: DeviceAddress = "sim:kmc".parse().unwrap();
        let dog: DeviceAddress = "sim:zsl1".parse().unwrap();
        assert_eq!(namespaces(std::slice::from_ref(&kmc), None), [""]);
        assert_eq!(namespaces(std::slice::from_ref(&kmc), Some("/robot1/")), ["/robot1"]);
        assert_eq!(namespaces(&[kmc.clone(), dog.clone(), kmc.clone()], None), ["/kmc0", "/zsl1_0", "/kmc1"]);
        assert_eq!(namespaces(&[kmc, dog], Some("lab")), ["/lab/kmc0", "/lab/zsl1_0"]);
    }
}
