//! [`Participant`]: one DDS domain participant on a named interface, the factory of typed
//! writers and readers.

use std::collections::BTreeMap;
use std::net::{IpAddr, Ipv4Addr};

use robowire_core::cdr::CdrType;
use rustdds::{DomainParticipant, DomainParticipantBuilder, Publisher, RTPSEntity, Subscriber, TopicKind};

use crate::DdsError;
use crate::adapter::CdrAdapter;
use crate::qos::Qos;
use crate::topic::{RawSample, Reader, Writer};

/// Where a participant lives.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ParticipantOptions {
    /// DDS domain (Unitree's robots: 0).
    pub domain: u16,
    /// The network interface by name (`eth0`, `enp3s0`, `lo`), as Unitree's
    /// `ChannelFactoryInitialize(0, iface)`; `None` lets the library choose.
    pub interface: Option<String>,
}

impl ParticipantOptions {
    /// Domain `domain` on `interface`.
    pub fn new(domain: u16, interface: Option<&str>) -> Self {
        Self { domain, interface: interface.map(str::to_owned) }
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

/// A domain participant; see the [crate docs](crate).
pub struct Participant {
    inner: DomainParticipant,
    publisher: Publisher,
    subscriber: Subscriber,
    options: ParticipantOptions,
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

impl Participant {
    /// Joins `options.domain` on `options.interface`.
    pub fn new(options: ParticipantOptions) -> Result<Self, DdsError> {
        let mut builder = DomainParticipantBuilder::new(options.domain);
        if let Some(name) = &options.interface {
            let ips = interface_addresses(name)?;
            builder = builder.with_only_networks(ips.into_iter().map(IpAddr::V4));
        }
        let failed = |source| DdsError::Participant { domain: options.domain, source };
        let inner = builder.build().map_err(failed)?;
        let qos = Qos::WRITER.policies();
        let publisher = inner.create_publisher(&qos).map_err(failed)?;
        let subscriber = inner.create_subscriber(&Qos::READER.policies()).map_err(failed)?;
        Ok(Self { inner, publisher, subscriber, options })
    }

    /// Where it lives.
    pub fn options(&self) -> &ParticipantOptions {
        &self.options
    }

    /// Its RTPS GUID in wire order: the GUID prefix every endpoint of it shares, and the
    /// participant's entity id `00 00 01 c1`.
    pub fn guid(&self) -> [u8; 16] {
        self.inner.guid().to_bytes()
    }

    fn topic(&self, name: &str, type_name: &str, qos: Qos, what: &'static str) -> Result<rustdds::Topic, DdsError> {
        self.inner
            .create_topic(name.into(), type_name.into(), &qos.policies(), TopicKind::NoKey)
            .map_err(|source| DdsError::Create { what, topic: name.into(), source })
    }

    /// A writer of `T` on topic `name`.
    pub fn writer<T: CdrType + 'static>(&self, name: &str, qos: Qos) -> Result<Writer<T>, DdsError> {
        let topic = self.topic(name, T::TYPE_NAME, qos, "writer")?;
        let inner = self
            .publisher
            .create_datawriter_no_key::<T, CdrAdapter<T>>(&topic, Some(qos.policies()))
            .map_err(|source| DdsError::Create { what: "writer", topic: name.into(), source })?;
        Ok(Writer::new(inner, name))
    }

    /// A writer of topic `name` whose samples are given as bytes ([`RawSample`]: an XCDR1 body),
    /// announced with the type name `type_name` (a passthrough of a message robowire does not
    /// decode here).
    pub fn raw_writer(&self, name: &str, type_name: &str, qos: Qos) -> Result<Writer<RawSample>, DdsError> {
        let topic = self.topic(name, type_name, qos, "writer")?;
        let inner = self
            .publisher
            .create_datawriter_no_key::<RawSample, CdrAdapter<RawSample>>(&topic, Some(qos.policies()))
            .map_err(|source| DdsError::Create { what: "writer", topic: name.into(), source })?;
        Ok(Writer::new(inner, name))
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
        let topic = self.topic(name, type_name, qos, "reader")?;
        let inner = self
            .subscriber
            .create_simple_datareader_no_key::<crate::adapter::Decoded<T>, CdrAdapter<T>>(&topic, Some(qos.policies()))
            .map_err(|source| DdsError::Create { what: "reader", topic: name.into(), source })?;
        Ok(Reader::new(inner, name, usize::try_from(qos.depth).unwrap_or(1)))
    }

    /// Other participants' writers and readers seen so far, writers first.
    pub fn discovered_endpoints(&self) -> Vec<DiscoveredEndpoint> {
        let writers = self.inner.discovered_writers().into_iter().map(|w| DiscoveredEndpoint {
            guid: w.writer_proxy.remote_writer_guid.to_bytes(),
            writer: true,
            topic: w.publication_topic_data.topic_name,
            type_name: w.publication_topic_data.type_name,
        });
        let readers = self.inner.discovered_readers().into_iter().map(|r| DiscoveredEndpoint {
            guid: r.reader_proxy.remote_reader_guid.to_bytes(),
            writer: false,
            topic: r.subscription_topic_data.topic_name().clone(),
            type_name: r.subscription_topic_data.type_name().clone(),
        });
        writers.chain(readers).collect()
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
}
