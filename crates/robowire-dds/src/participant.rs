//! [`Participant`]: one DDS domain participant on a named interface, the factory of typed
//! writers and readers.

use std::collections::BTreeMap;
use std::net::Ipv4Addr;
use std::sync::Arc;
use std::sync::atomic::{AtomicU16, Ordering};
use std::thread::JoinHandle;

use robowire_core::cdr::CdrType;
use rtps_proto::participant::{Participant as Core, ParticipantConfig};
use rtps_proto::{EntityId, Guid, GuidPrefix, VendorId};

use crate::DdsError;
use crate::driver::{self, Shared};
use crate::qos::Qos;
use crate::reader::Reader;
use crate::sample::{Counters, RawSample};
use crate::slot::ReaderSlot;
use crate::sockets::Sockets;
use crate::writer::Writer;

/// Where a participant lives.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ParticipantOptions {
    /// DDS domain (Unitree's robots: 0).
    pub domain: u16,
    /// The network interface by name (`eth0`, `enp3s0`, `lo`), as Unitree's
    /// `ChannelFactoryInitialize(0, iface)`; `None`: every interface with an IPv4 address.
    pub interface: Option<String>,
    /// Participant USER_DATA announced to others (ROS 2's `enclave=/;`).
    pub user_data: Vec<u8>,
}

impl ParticipantOptions {
    /// Domain `domain` on `interface`.
    pub fn new(domain: u16, interface: Option<&str>) -> Self {
        Self { domain, interface: interface.map(str::to_owned), user_data: Vec::new() }
    }
}

/// A topic seen on the network, with its type and how many writers and readers it has.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DiscoveredTopic {
    /// Topic name.
    pub name: String,
    /// DDS type name.
    pub type_name: String,
    /// Remote writers.
    pub writers: usize,
    /// Remote readers.
    pub readers: usize,
}

/// An endpoint of another participant, as DDS discovery (SEDP) reports it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DiscoveredEndpoint {
    /// Its RTPS GUID in wire order (prefix 12 bytes, entity key 3, entity kind 1).
    pub guid: [u8; 16],
    /// A writer (else a reader).
    pub writer: bool,
    /// Topic name.
    pub topic: String,
    /// DDS type name.
    pub type_name: String,
}

/// Another participant, as DDS discovery (SPDP) reports it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DiscoveredParticipant {
    /// Its GUID prefix.
    pub guid_prefix: [u8; 12],
    /// Its implementation (RTPS vendor id, two bytes) and that vendor's name where known.
    pub vendor: ([u8; 2], Option<&'static str>),
    /// Its USER_DATA (ROS 2: `enclave=/;`).
    pub user_data: Vec<u8>,
    /// Where it receives discovery and user data sent to it alone.
    pub unicast: Vec<std::net::SocketAddr>,
}

/// A domain participant; see the [crate docs](crate). Its background thread (discovery,
/// heartbeats, acknowledgements, receiving) ends when it is dropped, after announcing that it
/// leaves.
pub struct Participant {
    shared: Arc<Shared>,
    options: ParticipantOptions,
    thread: Option<JoinHandle<()>>,
}

impl std::fmt::Debug for Participant {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Participant").field("options", &self.options).finish_non_exhaustive()
    }
}

/// The IPv4 addresses of interface `name`.
fn interface_addresses(name: &str) -> Result<Vec<Ipv4Addr>, DdsError> {
    let interfaces = robowire_udp::host_interfaces();
    let ips: Vec<Ipv4Addr> = interfaces.iter().filter(|(n, _)| n == name).map(|(_, ip)| *ip).collect();
    if ips.is_empty() {
        let available = interfaces.iter().map(|(n, ip)| format!("{n} {ip}")).collect::<Vec<_>>().join(", ");
        return Err(DdsError::NoInterface { name: name.into(), available });
    }
    Ok(ips)
}

/// Every IPv4 address of the host, loopback last (or alone).
fn host_addresses() -> Vec<Ipv4Addr> {
    let mut ips = robowire_udp::host_ipv4_addresses();
    ips.sort_by_key(Ipv4Addr::is_loopback);
    if ips.is_empty() {
        ips.push(Ipv4Addr::LOCALHOST);
    }
    ips
}

/// A GUID prefix unique on the network: robowire's vendor id, 4 bytes of the wall clock at
/// creation, the process id, a counter of this process's participants.
fn new_guid_prefix() -> GuidPrefix {
    static COUNTER: AtomicU16 = AtomicU16::new(0);
    let clock = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap_or_default();
    let clock = (clock.as_nanos() as u32) ^ (clock.as_secs() as u32).rotate_left(16);
    let mut p = [0u8; 12];
    p[..2].copy_from_slice(&VendorId::ROBOWIRE.0);
    p[2..6].copy_from_slice(&clock.to_be_bytes());
    p[6..10].copy_from_slice(&std::process::id().to_be_bytes());
    p[10..].copy_from_slice(&COUNTER.fetch_add(1, Ordering::Relaxed).to_be_bytes());
    GuidPrefix(p)
}

impl Participant {
    /// Joins `options.domain` on `options.interface`.
    pub fn new(options: ParticipantOptions) -> Result<Self, DdsError> {
        let addresses = match &options.interface {
            Some(name) => interface_addresses(name)?,
            None => host_addresses(),
        };
        let failed = |source| DdsError::Participant { domain: options.domain, source };
        let sockets = Sockets::open(options.domain, addresses).map_err(failed)?;
        let mut config = ParticipantConfig::new(new_guid_prefix(), u32::from(options.domain));
        config.metatraffic_unicast = sockets.metatraffic_unicast();
        config.default_unicast = sockets.default_unicast();
        config.metatraffic_multicast = vec![sockets.spdp_multicast()];
        config.spdp_destinations = vec![sockets.spdp_multicast()];
        config.user_data = options.user_data.clone();
        let now = robowire_rt::now();
        let shared = Shared::new(Core::new(config, now), sockets).map_err(failed)?;
        let thread = std::thread::Builder::new()
            .name("robowire-dds".into())
            .spawn({
                let shared = shared.clone();
                move || driver::run(shared)
            })
            .map_err(failed)?;
        Ok(Self { shared, options, thread: Some(thread) })
    }

    /// Where it lives.
    pub fn options(&self) -> &ParticipantOptions {
        &self.options
    }

    /// Its RTPS GUID in wire order: the GUID prefix every endpoint of it shares, and the
    /// participant's entity id `00 00 01 c1`.
    pub fn guid(&self) -> [u8; 16] {
        Guid::new(self.prefix(), EntityId::PARTICIPANT).to_bytes()
    }

    fn prefix(&self) -> GuidPrefix {
        self.shared.lock().core.guid_prefix()
    }

    /// A writer of `T` on topic `name`.
    pub fn writer<T: CdrType + 'static>(&self, name: &str, qos: Qos) -> Result<Writer<T>, DdsError> {
        self.writer_of_type(name, T::TYPE_NAME, qos)
    }

    /// A writer of topic `name` whose samples are given as bytes ([`RawSample`]: an XCDR1 body),
    /// announced with the type name `type_name` (a passthrough of a message robowire does not
    /// decode here).
    pub fn raw_writer(&self, name: &str, type_name: &str, qos: Qos) -> Result<Writer<RawSample>, DdsError> {
        self.writer_of_type(name, type_name, qos)
    }

    fn writer_of_type<T: CdrType + 'static>(
        &self,
        name: &str,
        type_name: &str,
        qos: Qos,
    ) -> Result<Writer<T>, DdsError> {
        let now = robowire_rt::now();
        let mut st = self.shared.lock();
        let id = st.core.create_writer(now, name, type_name, qos.to_rtps()).map_err(|source| DdsError::Create {
            what: "writer",
            topic: name.into(),
            source,
        })?;
        let guid = Guid::new(st.core.guid_prefix(), id).to_bytes();
        self.shared.settle(&mut st, now);
        Ok(Writer::new(self.shared.clone(), id, guid, name))
    }

    /// A reader of `T` on topic `name` (any executor).
    pub fn reader<T: CdrType + 'static>(&self, name: &str, qos: Qos) -> Result<Reader<T>, DdsError> {
        self.reader_of_type(name, T::TYPE_NAME, qos)
    }

    /// A reader of topic `name` whose samples are kept as bytes ([`RawSample`]), for a type known
    /// only by the name other participants announce (an inspector).
    pub fn raw_reader(&self, name: &str, type_name: &str, qos: Qos) -> Result<Reader<RawSample>, DdsError> {
        self.reader_of_type(name, type_name, qos)
    }

    fn reader_of_type<T: CdrType + 'static>(
        &self,
        name: &str,
        type_name: &str,
        qos: Qos,
    ) -> Result<Reader<T>, DdsError> {
        let now = robowire_rt::now();
        let counters = Arc::new(Counters::default());
        let slot = Arc::new(ReaderSlot::new(usize::try_from(qos.depth).unwrap_or(1), counters.clone()));
        let mut st = self.shared.lock();
        let id = st.core.create_reader(now, name, type_name, qos.to_rtps()).map_err(|source| DdsError::Create {
            what: "reader",
            topic: name.into(),
            source,
        })?;
        st.readers.insert(id, slot.clone());
        let guid = Guid::new(st.core.guid_prefix(), id).to_bytes();
        self.shared.settle(&mut st, now);
        Ok(Reader::new(self.shared.clone(), slot, id, guid, name, counters))
    }

    /// Other participants' writers and readers seen so far, writers first.
    pub fn discovered_endpoints(&self) -> Vec<DiscoveredEndpoint> {
        let st = self.shared.lock();
        let mut all: Vec<DiscoveredEndpoint> = st
            .core
            .remote_endpoints()
            .map(|e| DiscoveredEndpoint {
                guid: e.guid.to_bytes(),
                writer: e.guid.entity.is_writer(),
                topic: e.topic_name.clone(),
                type_name: e.type_name.clone(),
            })
            .collect();
        all.sort_by_key(|e| !e.writer);
        all
    }

    /// Other participants seen so far.
    pub fn discovered_participants(&self) -> Vec<DiscoveredParticipant> {
        let st = self.shared.lock();
        st.core
            .remote_participants()
            .map(|p| DiscoveredParticipant {
                guid_prefix: p.guid_prefix.0,
                vendor: (p.vendor_id.0, p.vendor_id.name()),
                user_data: p.user_data.clone(),
                unicast: p
                    .metatraffic_unicast_locators
                    .iter()
                    .chain(&p.default_unicast_locators)
                    .filter_map(rtps_proto::Locator::socket_addr)
                    .collect(),
            })
            .collect()
    }

    /// Topics seen from other participants' writers and readers, by name.
    pub fn discovered_topics(&self) -> Vec<DiscoveredTopic> {
        let mut topics: BTreeMap<(String, String), (usize, usize)> = BTreeMap::new();
        for e in self.discovered_endpoints() {
            let counts = topics.entry((e.topic, e.type_name)).or_default();
            if e.writer {
                counts.0 += 1;
            } else {
                counts.1 += 1;
            }
        }
        topics
            .into_iter()
            .map(|((name, type_name), (writers, readers))| DiscoveredTopic { name, type_name, writers, readers })
            .collect()
    }

    /// The participant's protocol counters: refused datagrams by kind, discovery data that did
    /// not parse, what the limits dropped.
    pub fn counters(&self) -> rtps_proto::participant::Counters {
        self.shared.lock().core.counters().clone()
    }

    /// Datagrams whose `sendto` failed.
    pub fn send_failures(&self) -> u64 {
        self.shared.send_failures.load(Ordering::Relaxed)
    }
}

impl Drop for Participant {
    fn drop(&mut self) {
        self.shared.stop();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
