//! The observations read from the host, the network and serial ports, and a run of the checks
//! on them.

mod dds;
mod kmc;
mod zsl1;

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::PathBuf;
use std::time::Duration;

use robowire_dds::ParticipantOptions;
use robowire_devices::{DeviceAddress, DeviceKind};
use robowire_sim::g1::{G1Sim, G1SimConfig};
use robowire_sim::go2::{Go2Sim, Go2SimConfig};
use robowire_sim::kmc::{ChassisSim, ChassisSimConfig};
use robowire_sim::zsl1::{Zsl1Sim, Zsl1SimConfig};
use robowire_udp::host::{self, InterfaceInfo};
use zsl_proto::udp::{DEFAULT_LOCAL_PORT, HIGH_LEVEL_PORT, Model};

use crate::check::{Check, Report};
use crate::host::{HostExpectations, HostObservation, RobotNet, on_subnet, route_to};

/// How to diagnose.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Options {
    /// The interface, when the address names none (`zsl1:`, no address) or to override it.
    pub interface: Option<String>,
    /// The DDS domain.
    pub domain: u16,
    /// How long to listen.
    pub timeout: Duration,
}

/// What is diagnosed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Target {
    /// A Unitree robot over DDS on an interface: `go2:`, `g1:`, `hg:` (its kind for its subnet).
    Unitree {
        /// Go2, G1 or HG.
        kind: DeviceKind,
        /// The interface.
        interface: String,
    },
    /// Whatever speaks DDS on an interface (no address given).
    Interface(String),
    /// A ZSL-1 or ZSL-1W at its HighLevel address.
    Zsl1 {
        /// Its HighLevel address (port 43997 on a robot).
        robot: SocketAddr,
        /// ZSL-1 or ZSL-1W.
        model: Model,
        /// The interface, when given.
        interface: Option<String>,
    },
    /// A KMC chassis on a serial port.
    Kmc(PathBuf),
}

/// Why nothing could be diagnosed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DoctorError {
    /// Neither an address nor an interface.
    #[error(
        "name a device (go2:eth0, g1:eth0, hg:eth0, zsl1:IP, zsl1w:IP, kmc:PATH, sim:go2|g1|zsl1|kmc) or --interface IFACE"
    )]
    Nothing,
    /// An address whose kind is not diagnosed.
    #[error("robowire doctor does not diagnose {0} (the spline daemon is on this host's shared memory)")]
    Unsupported(DeviceAddress),
    /// The simulator of a `sim:` address did not start.
    #[error("the simulator did not start")]
    Simulator(#[source] Box<dyn std::error::Error + Send + Sync>),
}

/// A simulator started for a `sim:` address; it stops when dropped.
#[derive(Debug)]
#[non_exhaustive]
pub enum Simulated {
    /// A Go2 on DDS.
    Go2(Go2Sim),
    /// A G1 on DDS.
    G1(G1Sim),
    /// A ZSL-1 on loopback UDP.
    Zsl1(Zsl1Sim),
    /// A KMC chassis on a pseudo-terminal.
    Kmc(ChassisSim),
}

/// The target an address names (`--interface` overriding its interface), and the simulator a
/// `sim:` address starts (on `lo` or `--interface`, domain `options.domain`).
pub fn prepare(address: Option<&DeviceAddress>, options: &Options) -> Result<(Target, Option<Simulated>), DoctorError> {
    let interface = |named: &str| options.interface.clone().unwrap_or_else(|| named.to_owned());
    let unitree = |kind, named: &str| Target::Unitree { kind, interface: interface(named) };
    let zsl1 = |ip: IpAddr, model| Target::Zsl1 {
        robot: SocketAddr::new(ip, HIGH_LEVEL_PORT),
        model,
        interface: options.interface.clone(),
    };
    let failed = |e: Box<dyn std::error::Error + Send + Sync>| DoctorError::Simulator(e);
    Ok(match address {
        Some(DeviceAddress::Go2(i)) => (unitree(DeviceKind::Go2, i), None),
        Some(DeviceAddress::G1(i)) => (unitree(DeviceKind::G1, i), None),
        Some(DeviceAddress::Hg(i)) => (unitree(DeviceKind::Hg, i), None),
        Some(DeviceAddress::Zsl1(ip)) => (zsl1(*ip, Model::Zsl1), None),
        Some(DeviceAddress::Zsl1w(ip)) => (zsl1(*ip, Model::Zsl1W), None),
        Some(DeviceAddress::Kmc(path)) => (Target::Kmc(path.clone()), None),
        Some(DeviceAddress::Sim(kind @ (DeviceKind::Go2 | DeviceKind::G1))) => {
            let participant = ParticipantOptions::new(options.domain, Some(&interface("lo")));
            let sim = if *kind == DeviceKind::Go2 {
                Simulated::Go2(
                    Go2Sim::spawn(Go2SimConfig { participant, ..Go2SimConfig::default() })
                        .map_err(|e| failed(e.into()))?,
                )
            } else {
                Simulated::G1(
                    G1Sim::spawn(G1SimConfig { participant, ..G1SimConfig::default() })
                        .map_err(|e| failed(e.into()))?,
                )
            };
            (unitree(*kind, "lo"), Some(sim))
        }
        Some(DeviceAddress::Sim(kind @ (DeviceKind::Zsl1 | DeviceKind::Zsl1w))) => {
            let model = if *kind == DeviceKind::Zsl1 { Model::Zsl1 } else { Model::Zsl1W };
            let sim =
                Zsl1Sim::spawn(Zsl1SimConfig { model, ..Zsl1SimConfig::loopback() }).map_err(|e| failed(e.into()))?;
            let target = Target::Zsl1 { robot: sim.high_level_addr(), model, interface: options.interface.clone() };
            (target, Some(Simulated::Zsl1(sim)))
        }
        Some(DeviceAddress::Sim(DeviceKind::Kmc)) => {
            let sim = ChassisSim::spawn(ChassisSimConfig::default()).map_err(|e| failed(e.into()))?;
            (Target::Kmc(sim.path()), Some(Simulated::Kmc(sim)))
        }
        Some(other) => return Err(DoctorError::Unsupported(other.clone())),
        None => (Target::Interface(options.interface.clone().ok_or(DoctorError::Nothing)?), None),
    })
}

impl Target {
    /// How the report names it: `go2:eth0`, `zsl1:192.168.234.1:43997`, `kmc:/dev/ttyUSB0`.
    pub fn name(&self) -> String {
        match self {
            Self::Unitree { kind, interface } => format!("{}:{interface}", kind.name()),
            Self::Interface(interface) => format!("interface {interface}"),
            Self::Zsl1 { robot, model, .. } => {
                format!("{}:{robot}", if *model == Model::Zsl1 { "zsl1" } else { "zsl1w" })
            }
            Self::Kmc(path) => format!("kmc:{}", path.display()),
        }
    }
}

/// Reads the host, listens on the network or the port for `options.timeout` and runs every
/// check.
pub fn diagnose(target: &Target, options: &Options) -> Report {
    let checks = match target {
        Target::Unitree { kind, interface } => {
            let robot = if *kind == DeviceKind::Go2 { [192, 168, 123, 161] } else { [192, 168, 123, 164] };
            let net = RobotNet { robot: robot.into(), prefix: 24, host: [192, 168, 123, 99].into() };
            unitree(interface, Some(net), options)
        }
        Target::Interface(interface) => {
            let mut checks = unitree(interface, None, options);
            let heard = zsl1::overhear(DEFAULT_LOCAL_PORT, options.timeout);
            checks.push(crate::zsl1::overheard(&heard, DEFAULT_LOCAL_PORT, options.timeout.as_secs_f64()));
            checks
        }
        Target::Zsl1 { robot, model, interface } => zsl1_checks(*robot, *model, interface.as_deref(), options),
        Target::Kmc(path) => crate::kmc::checks(&kmc::read(path, options.timeout)),
    };
    Report { target: target.name(), checks }
}

/// The host and interface checks, then DDS's when the interface exists.
fn unitree(interface: &str, net: Option<RobotNet>, options: &Options) -> Vec<Check> {
    let seen = observe_host(interface);
    let expect = HostExpectations { interface: interface.to_owned(), net, multicast: true, ports: vec![7400..=7700] };
    let mut checks = crate::host::checks(&seen, &expect);
    let Some(found) = found(&seen, interface) else { return checks };
    match dds::listen(options.domain, interface, options.timeout) {
        Ok(mut heard) => {
            (heard.interface_ipv4, heard.loopback) = (found.ipv4.clone(), found.loopback);
            checks.extend(crate::dds::checks(&heard));
        }
        Err(e) => checks.push(Check::unknown(
            "DDS participants",
            format!("cannot join domain {} on {interface}: {}", options.domain, robowire_devices::error_chain(&e)),
        )),
    }
    checks
}

fn found(seen: &HostObservation, interface: &str) -> Option<InterfaceInfo> {
    seen.interfaces.as_ref().ok()?.iter().find(|i| i.name == interface).cloned()
}

/// The interface toward `ip`: the one on its subnet (loopback for a loopback address), else the
/// one its route goes out.
fn interface_toward(ip: Ipv4Addr) -> Option<String> {
    let all = host::interfaces().ok()?;
    let on = all.iter().find(|i| {
        (ip.is_loopback() && i.loopback)
            || i.ipv4.iter().any(|&(own, prefix)| !i.loopback && on_subnet(ip, own, prefix))
    });
    match on {
        Some(i) => Some(i.name.clone()),
        None => route_to(&host::ipv4_routes().ok()?, ip).map(|r| r.interface.clone()),
    }
}

/// The host checks for the ZSL-1's interface, then the ZSL-1's.
fn zsl1_checks(robot: SocketAddr, model: Model, interface: Option<&str>, options: &Options) -> Vec<Check> {
    let IpAddr::V4(ip) = robot.ip() else {
        return vec![Check::fail(
            "address",
            format!("{robot} is IPv6"),
            "the ZSL-1 speaks IPv4: name its IPv4 address",
        )];
    };
    let net = RobotNet { robot: ip, prefix: 24, host: Ipv4Addr::from(u32::from(ip) & !0xff | 99) };
    let Some(interface) = interface.map(str::to_owned).or_else(|| interface_toward(ip)) else {
        return vec![Check::fail(
            "interface",
            format!("no interface on {ip}'s subnet and no route to it"),
            format!("sudo ip addr add {}/24 dev IFACE (the interface cabled to the robot)", net.host),
        )];
    };
    let seen = observe_host(&interface);
    let expect = HostExpectations {
        interface: interface.clone(),
        net: Some(net),
        multicast: false,
        ports: vec![DEFAULT_LOCAL_PORT..=DEFAULT_LOCAL_PORT],
    };
    let mut checks = crate::host::checks(&seen, &expect);
    let Some(found) = found(&seen, &interface) else { return checks };
    let our_ip = found
        .ipv4
        .iter()
        .find(|(own, _)| on_subnet(ip, *own, 24))
        .or(found.ipv4.first())
        .map(|(own, _)| IpAddr::V4(*own));
    checks.extend(crate::zsl1::checks(&zsl1::listen(robot, model, DEFAULT_LOCAL_PORT, our_ip, options.timeout)));
    checks
}

/// The host as the calling thread's network namespace shows it, for `interface`.
pub(crate) fn observe_host(interface: &str) -> HostObservation {
    HostObservation {
        interfaces: host::interfaces().map_err(|e| e.to_string()),
        routes: host::ipv4_routes().map_err(|e| e.to_string()),
        rp_filter: host::rp_filter(interface),
        firewall: host::nft_ruleset().map_err(|e| e.to_string()),
    }
}
