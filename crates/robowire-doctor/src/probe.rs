//! The observations read from the host and the network, and a run of the checks on them.

use std::net::Ipv4Addr;
use std::time::{Duration, Instant};

use robowire_dds::qos::Qos;
use robowire_dds::{DdsError, Listener, Participant, ParticipantOptions, StatsHandle};
use robowire_devices::{DeviceAddress, DeviceKind};
use robowire_sim::g1::{G1Sim, G1SimConfig};
use robowire_sim::go2::{Go2Sim, Go2SimConfig};
use robowire_udp::host;
use unitree_proto::{HgLowState, LowState, Message};

use crate::check::{Check, Report};
use crate::dds::{self, DdsObservation, LOWSTATE};
use crate::host::{HostExpectations, HostObservation, RobotNet};

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
    /// Whatever is on an interface (no address given).
    Interface(String),
}

impl Target {
    /// The target an address names (`--interface` overriding its interface); `None` with
    /// neither.
    pub fn of(address: Option<&DeviceAddress>, options: &Options) -> Result<Self, DoctorError> {
        let interface = |named: &str| options.interface.clone().unwrap_or_else(|| named.to_owned());
        match address {
            Some(DeviceAddress::Go2(i)) => Ok(Self::Unitree { kind: DeviceKind::Go2, interface: interface(i) }),
            Some(DeviceAddress::G1(i)) => Ok(Self::Unitree { kind: DeviceKind::G1, interface: interface(i) }),
            Some(DeviceAddress::Hg(i)) => Ok(Self::Unitree { kind: DeviceKind::Hg, interface: interface(i) }),
            Some(DeviceAddress::Sim(kind @ (DeviceKind::Go2 | DeviceKind::G1))) => {
                Ok(Self::Unitree { kind: *kind, interface: interface("lo") })
            }
            Some(other) => Err(DoctorError::Unsupported(other.clone())),
            None => options.interface.clone().map(Self::Interface).ok_or(DoctorError::Nothing),
        }
    }

    fn interface(&self) -> &str {
        match self {
            Self::Unitree { interface, .. } | Self::Interface(interface) => interface,
        }
    }
}

/// Why nothing could be diagnosed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DoctorError {
    /// Neither an address nor an interface.
    #[error("name a device (go2:eth0, g1:eth0, hg:eth0, sim:go2, sim:g1) or --interface IFACE")]
    Nothing,
    /// An address whose kind is not diagnosed.
    #[error("robowire doctor diagnoses go2:, g1:, hg:, sim:go2 and sim:g1 so far, not {0:?}")]
    Unsupported(DeviceAddress),
    /// The simulator of a `sim:` address did not start.
    #[error("the simulator did not start")]
    Simulator(#[source] Box<dyn std::error::Error + Send + Sync>),
}

/// A simulator started for a `sim:` address; it stops when dropped.
#[derive(Debug)]
#[non_exhaustive]
pub enum Simulated {
    /// A Go2.
    Go2(Go2Sim),
    /// A G1.
    G1(G1Sim),
}

/// Starts the simulator a `sim:` address names, on the target's interface and `options.domain`
/// (`None` for other addresses).
pub fn simulate(address: &DeviceAddress, options: &Options) -> Result<Option<Simulated>, DoctorError> {
    let DeviceAddress::Sim(kind) = address else { return Ok(None) };
    let participant = ParticipantOptions::new(options.domain, Some(options.interface.as_deref().unwrap_or("lo")));
    let failed = |e: Box<dyn std::error::Error + Send + Sync>| DoctorError::Simulator(e);
    Ok(Some(match kind {
        DeviceKind::Go2 => Simulated::Go2(
            Go2Sim::spawn(Go2SimConfig { participant, ..Go2SimConfig::default() }).map_err(|e| failed(e.into()))?,
        ),
        DeviceKind::G1 => Simulated::G1(
            G1Sim::spawn(G1SimConfig { participant, ..G1SimConfig::default() }).map_err(|e| failed(e.into()))?,
        ),
        _ => return Err(DoctorError::Unsupported(address.clone())),
    }))
}

/// Reads the host, listens on the network for `options.timeout` and runs every check.
pub fn diagnose(target: &Target, options: &Options) -> Report {
    let interface = target.interface();
    let seen = observe_host(interface);
    let net = match target {
        Target::Unitree { kind, .. } => Some(RobotNet {
            robot: if *kind == DeviceKind::Go2 {
                Ipv4Addr::new(192, 168, 123, 161)
            } else {
                Ipv4Addr::new(192, 168, 123, 164)
            },
            prefix: 24,
            host: Ipv4Addr::new(192, 168, 123, 99),
        }),
        Target::Interface(_) => None,
    };
    let expect = HostExpectations { interface: interface.to_owned(), net, multicast: true, ports: vec![7400..=7700] };
    let mut checks = crate::host::checks(&seen, &expect);
    let found = seen.interfaces.as_ref().ok().and_then(|all| all.iter().find(|i| i.name == interface).cloned());
    if let Some(found) = found {
        match listen(options.domain, interface, options.timeout) {
            Ok(mut heard) => {
                heard.interface = (found.ipv4.clone(), found.loopback);
                checks.extend(dds::checks(&heard));
            }
            Err(e) => checks.push(Check::unknown(
                "DDS participants",
                format!("cannot join domain {} on {interface}: {e}", options.domain),
            )),
        }
    }
    let name = match target {
        Target::Unitree { kind, interface } => format!("{}:{interface}", kind.name()),
        Target::Interface(interface) => format!("interface {interface}"),
    };
    Report { target: name, checks }
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

/// A reader of `rt/lowstate` counting what arrives, made once a writer's type is known.
struct LowStateCount {
    stats: StatsHandle,
    since: Instant,
    _listener: Listener,
}

fn count_lowstate(participant: &Participant, type_name: &str) -> Result<LowStateCount, DdsError> {
    let (stats, listener) = if type_name == HgLowState::DDS_TYPE_NAME {
        let reader = participant.reader::<HgLowState>(LOWSTATE, Qos::READER)?;
        (reader.stats_handle(), reader.listen(|_| {}))
    } else if type_name == LowState::DDS_TYPE_NAME {
        let reader = participant.reader::<LowState>(LOWSTATE, Qos::READER)?;
        (reader.stats_handle(), reader.listen(|_| {}))
    } else {
        let reader = participant.raw_reader(LOWSTATE, type_name, Qos::READER)?;
        (reader.stats_handle(), reader.listen(|_| {}))
    };
    Ok(LowStateCount { stats, since: Instant::now(), _listener: listener })
}

/// What DDS shows on `domain` over `interface` within `timeout`; when nobody is heard there,
/// also who is heard on the other domains of 0–9 within another `timeout`.
fn listen(domain: u16, interface: &str, timeout: Duration) -> Result<DdsObservation, DdsError> {
    const POLL: Duration = Duration::from_millis(50);
    let participant = Participant::new(ParticipantOptions::new(domain, Some(interface)))?;
    let start = Instant::now();
    let mut lowstate = None;
    while start.elapsed() < timeout {
        if lowstate.is_none()
            && let Some(topic) =
                participant.discovered_topics().into_iter().find(|t| t.name == LOWSTATE && t.writers > 0)
        {
            lowstate = Some(count_lowstate(&participant, &topic.type_name)?);
        }
        std::thread::sleep(POLL.min(timeout.saturating_sub(start.elapsed())));
    }
    let seconds = start.elapsed().as_secs_f64();
    let lowstate = lowstate.map(|l| (l.stats.get(), l.since.elapsed().as_secs_f64()));
    let participants = participant.discovered_participants();
    let mut other_domains = Vec::new();
    if participants.is_empty() {
        let others: Vec<(u16, Participant)> = (0..10u16)
            .filter(|d| *d != domain)
            .filter_map(|d| Participant::new(ParticipantOptions::new(d, Some(interface))).ok().map(|p| (d, p)))
            .collect();
        std::thread::sleep(timeout);
        other_domains = others.iter().map(|(d, p)| (*d, p.discovered_participants().len())).collect();
    }
    Ok(DdsObservation {
        domain,
        seconds,
        interface: (Vec::new(), false),
        participants,
        endpoints: participant.discovered_endpoints(),
        other_domains,
        lowstate,
    })
}
