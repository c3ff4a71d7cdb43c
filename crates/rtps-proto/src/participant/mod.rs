//! One DDS participant as a sans-IO state machine (quinn-proto's shape): datagrams and the
//! caller's time in ([`handle_datagram`](Participant::handle_datagram),
//! [`handle_timeout`](Participant::handle_timeout)), datagrams, a deadline and events out
//! ([`poll_transmit`](Participant::poll_transmit), [`poll_timeout`](Participant::poll_timeout),
//! [`poll_event`](Participant::poll_event)). A [`write`](Participant::write) builds its own
//! datagram at once, so a stream thread can send it with no hop.
//!
//! It discovers other participants (SPDP) and their endpoints (SEDP), matches them with its own
//! writers and readers by topic, type and QoS (reporting why a pair does not match), and runs
//! the reliable and best-effort protocols. Every table is bounded by [`Limits`]; what exceeds a
//! bound is dropped and counted in [`Counters`].
//!
//! ```
//! use rtps_proto::participant::{Destination, Event, Participant, ParticipantConfig};
//! use rtps_proto::discovery::Qos;
//! use rtps_proto::{GuidPrefix, Locator, Time};
//!
//! let config = |n: u8| {
//!     let mut c = ParticipantConfig::new(GuidPrefix([n; 12]), 0);
//!     c.metatraffic_unicast = vec![Locator::udpv4(format!("127.0.0.1:{}", 7410 + u16::from(n)).parse().unwrap())];
//!     c.default_unicast = c.metatraffic_unicast.clone();
//!     c
//! };
//! let now = Time::from_nanos(1_000_000_000);
//! let mut a = Participant::new(config(1), now);
//! let mut b = Participant::new(config(2), now);
//! let w = a.create_writer(now, "rt/lowstate", "unitree_go::msg::dds_::LowState_", Qos::default()).unwrap();
//! let r = b.create_reader(now, "rt/lowstate", "unitree_go::msg::dds_::LowState_", Qos::default()).unwrap();
//! // Carry every datagram from one to the other until both are quiet.
//! let mut buf = [0u8; 1500];
//! let from = "127.0.0.1:7411".parse().unwrap();
//! for _ in 0..20 {
//!     while let Some(t) = a.poll_transmit(now, &mut buf) {
//!         b.handle_datagram(now, from, Destination::Unicast, &buf[..t.len]);
//!     }
//!     while let Some(t) = b.poll_transmit(now, &mut buf) {
//!         a.handle_datagram(now, from, Destination::Unicast, &buf[..t.len]);
//!     }
//! }
//! let sent = a.write(now, w, &[0, 1, 0, 0, 42, 0, 0, 0], &Default::default(), &mut buf).unwrap();
//! let t = sent.transmit.expect("a matched reader");
//! assert_eq!(t.destinations(), &b.config().default_unicast[..]);
//! b.handle_datagram(now, from, Destination::Unicast, &buf[..t.len]);
//! let mut got = None;
//! while let Some(e) = b.poll_event() {
//!     if let Event::Sample(s) = e { got = Some(s.payload); }
//! }
//! assert_eq!(got.as_deref(), Some(&[0, 1, 0, 0, 42, 0, 0, 0][..]));
//! # let _ = r;
//! ```

mod builtin;
mod event;
mod receive;
mod transmit;

use alloc::collections::VecDeque;
use alloc::string::String;
use alloc::vec::Vec;
use core::time::Duration;

use event::push_event;
pub use event::{Counters, CreateError, Event, LostReason, MatchError, Sample, Written};
pub use receive::Destination;
pub use transmit::{MAX_DESTINATIONS, Transmit};

use crate::Time;
use crate::discovery::{EndpointData, ParticipantData, Qos};
use crate::endpoint::{
    ChangeKind, Reader, ReaderCounters, SampleInfo, WriteError, WriteMode, WriteOptions, Writer, WriterCounters,
};
use crate::limits::Limits;
use crate::types::{EntityId, Guid, GuidPrefix, Locator, SequenceNumber};

/// How a participant presents itself and paces its protocols.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct ParticipantConfig {
    /// Its GUID prefix (unique on the network).
    pub guid_prefix: GuidPrefix,
    /// The DDS domain.
    pub domain_id: u32,
    /// The domain tag (empty for none).
    pub domain_tag: String,
    /// Where it receives discovery traffic sent to it alone.
    pub metatraffic_unicast: Vec<Locator>,
    /// The multicast groups it receives discovery traffic on.
    pub metatraffic_multicast: Vec<Locator>,
    /// Where it receives user data sent to it alone.
    pub default_unicast: Vec<Locator>,
    /// Multicast groups for user data.
    pub default_multicast: Vec<Locator>,
    /// Where its SPDP announcements go: the SPDP multicast locator and any initial peers.
    pub spdp_destinations: Vec<Locator>,
    /// Period of the SPDP announcements.
    pub announce_period: Duration,
    /// How long others keep it without hearing from it.
    pub lease_duration: Duration,
    /// Participant USER_DATA (ROS 2: `enclave=/;`).
    pub user_data: Vec<u8>,
    /// An entity name announced in SPDP (PID_ENTITY_NAME), if any.
    pub entity_name: Option<String>,
    /// Period of a reliable writer's heartbeats while anything is unacknowledged.
    pub heartbeat_period: Duration,
    /// How long a writer waits before answering an ACKNACK.
    pub nack_response_delay: Duration,
    /// How long a reader waits before answering a HEARTBEAT.
    pub heartbeat_response_delay: Duration,
    /// Samples longer than this go as DATA_FRAG fragments of this size.
    pub fragment_size: u16,
    /// A datagram carries as many fragments of a sample as fit in this many bytes (at least one).
    pub max_message_size: usize,
    /// The memory bounds.
    pub limits: Limits,
}

impl ParticipantConfig {
    /// Defaults for `domain_id`: 3 s announcements, a 20 s lease, 100 ms heartbeats, immediate
    /// responses, 1344-byte fragments in datagrams of up to 14720 bytes (CycloneDDS's), the
    /// default [`Limits`]. Locators are the
    /// caller's to fill (the transport knows its sockets).
    pub fn new(guid_prefix: GuidPrefix, domain_id: u32) -> Self {
        Self {
            guid_prefix,
            domain_id,
            domain_tag: String::new(),
            metatraffic_unicast: Vec::new(),
            metatraffic_multicast: Vec::new(),
            default_unicast: Vec::new(),
            default_multicast: Vec::new(),
            spdp_destinations: Vec::new(),
            announce_period: Duration::from_secs(3),
            lease_duration: Duration::from_secs(20),
            user_data: Vec::new(),
            entity_name: None,
            heartbeat_period: Duration::from_millis(100),
            nack_response_delay: Duration::ZERO,
            heartbeat_response_delay: Duration::ZERO,
            fragment_size: 1344,
            max_message_size: 14720,
            limits: Limits::default(),
        }
    }
}

/// Bookkeeping of one local endpoint beside its state machine.
#[derive(Debug, Clone)]
struct LocalEndpoint {
    id: EntityId,
    topic: String,
    type_name: String,
    qos: Qos,
}

/// A remote participant and its endpoints.
#[derive(Debug, Clone)]
pub(crate) struct RemoteParticipant {
    pub(crate) data: ParticipantData,
    pub(crate) lease_expires: Time,
    /// When its last datagram came.
    pub(crate) heard_at: Time,
    pub(crate) writers: Vec<EndpointData>,
    pub(crate) readers: Vec<EndpointData>,
    /// The address its last datagram came from.
    pub(crate) last_source: Option<core::net::SocketAddr>,
}

/// One DDS participant; see the [module](self). A clone is an independent participant in the
/// same state (the same GUID prefix: for tests and fuzzing, not for a second one on a network).
#[derive(Debug, Clone)]
pub struct Participant {
    config: ParticipantConfig,
    writers: Vec<Writer>,
    readers: Vec<Reader>,
    local: Vec<LocalEndpoint>,
    remote: Vec<RemoteParticipant>,
    events: VecDeque<Event>,
    spare: Vec<Vec<u8>>,
    next_entity_key: u32,
    spdp_due: Time,
    spdp_sequence: SequenceNumber,
    /// Participants to send our SPDP to at once (just discovered).
    spdp_unicast: Vec<GuidPrefix>,
    /// SEDP samples delivered by the builtin readers, taken after each datagram.
    discovery_inbox: Vec<(SampleInfo, Vec<u8>)>,
    counters: Counters,
}

impl Participant {
    /// A participant that announces itself at once (its first `poll_transmit`).
    pub fn new(config: ParticipantConfig, now: Time) -> Self {
        let mut p = Self {
            writers: Vec::new(),
            readers: Vec::new(),
            local: Vec::new(),
            remote: Vec::new(),
            events: VecDeque::with_capacity(64),
            spare: Vec::new(),
            next_entity_key: 1,
            spdp_due: now,
            spdp_sequence: SequenceNumber::FIRST,
            spdp_unicast: Vec::new(),
            discovery_inbox: Vec::new(),
            counters: Counters::default(),
            config,
        };
        p.create_builtin_endpoints();
        p
    }

    /// The configuration.
    pub fn config(&self) -> &ParticipantConfig {
        &self.config
    }

    /// The participant's GUID prefix.
    pub fn guid_prefix(&self) -> GuidPrefix {
        self.config.guid_prefix
    }

    /// The counters.
    pub fn counters(&self) -> &Counters {
        &self.counters
    }

    /// A local writer's counters.
    pub fn writer_counters(&self, writer: EntityId) -> Option<WriterCounters> {
        self.writers.iter().find(|w| w.id == writer).map(|w| w.counters)
    }

    /// A local reader's counters.
    pub fn reader_counters(&self, reader: EntityId) -> Option<ReaderCounters> {
        self.readers.iter().find(|r| r.id == reader).map(|r| r.counters)
    }

    /// The remote participants known now.
    pub fn remote_participants(&self) -> impl Iterator<Item = &ParticipantData> {
        self.remote.iter().map(|r| &r.data)
    }

    /// The remote endpoints known now (writers, then readers, participant by participant).
    pub fn remote_endpoints(&self) -> impl Iterator<Item = &EndpointData> {
        self.remote.iter().flat_map(|r| r.writers.iter().chain(&r.readers))
    }

    /// A remote writer or reader.
    pub fn remote_endpoint(&self, guid: Guid) -> Option<&EndpointData> {
        self.remote.iter().find(|r| r.data.guid_prefix == guid.prefix)?.endpoint(guid)
    }

    /// Whether every reliable reader matched with local writer `writer` has acknowledged every
    /// sample it wrote (`None`: no such writer).
    pub fn writer_acknowledged(&self, writer: EntityId) -> Option<bool> {
        self.writers.iter().find(|w| w.id == writer).map(|w| !w.has_unacknowledged())
    }

    /// The remote readers matched with local writer `writer`.
    pub fn matched_readers(&self, writer: EntityId) -> impl Iterator<Item = Guid> + '_ {
        self.writers.iter().filter(move |w| w.id == writer).flat_map(|w| w.readers.iter().map(|p| p.guid))
    }

    /// The remote writers matched with local reader `reader`.
    pub fn matched_writers(&self, reader: EntityId) -> impl Iterator<Item = Guid> + '_ {
        self.readers.iter().filter(move |r| r.id == reader).flat_map(|r| r.writers.iter().map(|p| p.guid))
    }

    /// The next event, oldest first.
    pub fn poll_event(&mut self) -> Option<Event> {
        self.events.pop_front()
    }

    /// Gives a sample's payload buffer back for reuse.
    pub fn recycle(&mut self, mut payload: Vec<u8>) {
        if self.spare.len() < 16 {
            payload.clear();
            self.spare.push(payload);
        }
    }

    fn push_event(&mut self, e: Event) {
        push_event(&mut self.events, &mut self.counters, self.config.limits.events, e);
    }

    fn new_entity(&mut self, kind: u8) -> Result<EntityId, CreateError> {
        if self.local.len() >= self.config.limits.local_endpoints {
            return Err(CreateError::TooMany(self.config.limits.local_endpoints));
        }
        let key = self.next_entity_key;
        if key >= 1 << 24 {
            return Err(CreateError::Keys);
        }
        self.next_entity_key += 1;
        Ok(EntityId::user(key, kind))
    }

    fn depth(&self, qos: &Qos) -> Result<usize, CreateError> {
        let limit = self.config.limits.history_depth;
        match qos.history {
            crate::discovery::History::KeepLast { depth } if depth >= 1 && depth as usize <= limit => {
                Ok(depth as usize)
            }
            crate::discovery::History::KeepLast { depth } => Err(CreateError::Depth { depth, limit }),
            crate::discovery::History::KeepAll => Ok(limit),
        }
    }

    /// Creates a writer on `topic` with `type_name` and `qos`; it is announced (SEDP) and
    /// matched with the readers known now and later. A full reliable history replaces its oldest
    /// sample ([`WriteMode::ReplaceOldest`]); see [`create_writer_with`](Self::create_writer_with).
    pub fn create_writer(
        &mut self,
        now: Time,
        topic: &str,
        type_name: &str,
        qos: Qos,
    ) -> Result<EntityId, CreateError> {
        self.create_writer_with(now, topic, type_name, qos, WriteMode::ReplaceOldest)
    }

    /// [`create_writer`](Self::create_writer) with the choice of what a full history does.
    pub fn create_writer_with(
        &mut self,
        now: Time,
        topic: &str,
        type_name: &str,
        qos: Qos,
        mode: WriteMode,
    ) -> Result<EntityId, CreateError> {
        let depth = self.depth(&qos)?;
        let id = self.new_entity(EntityId::KIND_WRITER_NO_KEY)?;
        let config = self.writer_config(&qos, depth, mode);
        self.writers.push(Writer::new(id, config));
        self.local.push(LocalEndpoint { id, topic: topic.into(), type_name: type_name.into(), qos });
        self.announce_local(now, id);
        self.match_local(now, id);
        Ok(id)
    }

    /// Creates a reader on `topic` with `type_name` and `qos`; announced and matched likewise.
    pub fn create_reader(
        &mut self,
        now: Time,
        topic: &str,
        type_name: &str,
        qos: Qos,
    ) -> Result<EntityId, CreateError> {
        let depth = self.depth(&qos)?;
        let id = self.new_entity(EntityId::KIND_READER_NO_KEY)?;
        let config = self.reader_config(depth);
        self.readers.push(Reader::new(id, config));
        self.local.push(LocalEndpoint { id, topic: topic.into(), type_name: type_name.into(), qos });
        self.announce_local(now, id);
        self.match_local(now, id);
        Ok(id)
    }

    /// Deletes a local writer or reader; its removal is announced (SEDP dispose).
    pub fn delete_endpoint(&mut self, now: Time, id: EntityId) -> bool {
        let Some(i) = self.local.iter().position(|l| l.id == id) else { return false };
        self.local.remove(i);
        self.writers.retain(|w| w.id != id);
        self.readers.retain(|r| r.id != id);
        self.announce_removal(now, id);
        true
    }

    /// Writes a sample (already-encoded CDR with its encapsulation header, padded to a multiple
    /// of 4 bytes) and builds the
    /// datagram that carries it to every matched reader into `buf`: send it to
    /// [`Transmit::destinations`] now. Samples longer than the fragment size go as DATA_FRAG
    /// from [`poll_transmit`](Self::poll_transmit).
    pub fn write(
        &mut self,
        now: Time,
        writer: EntityId,
        payload: &[u8],
        options: &WriteOptions,
        buf: &mut [u8],
    ) -> Result<Written, WriteError> {
        if !payload.len().is_multiple_of(4) {
            return Err(WriteError::Unaligned { len: payload.len() });
        }
        if payload.len() > self.config.limits.sample_bytes {
            return Err(WriteError::TooLarge { len: payload.len(), limit: self.config.limits.sample_bytes });
        }
        let w = self.writers.iter().position(|w| w.id == writer).ok_or(WriteError::UnknownWriter(writer))?;
        let sequence = self.writers[w].write(now, ChangeKind::Alive, payload, options)?;
        if payload.len() > usize::from(self.config.fragment_size) {
            return Ok(Written { sequence, transmit: None });
        }
        let transmit = self.build_data_to_all(w, sequence, buf)?;
        Ok(Written { sequence, transmit })
    }

    /// The earliest time [`handle_timeout`](Self::handle_timeout) has work (announcements,
    /// heartbeats, responses, leases, reassembly timeouts); `now` when a datagram is waiting.
    pub fn poll_timeout(&self) -> Option<Time> {
        let writers = self.writers.iter().filter_map(Writer::poll_timeout).min();
        let readers = self.readers.iter().filter_map(Reader::poll_timeout).min();
        let leases = self.remote.iter().map(|r| r.lease_expires).min();
        let spdp = (!self.spdp_unicast.is_empty()).then_some(Time::ZERO);
        [Some(self.spdp_due), writers, readers, leases, spdp].into_iter().flatten().min()
    }

    /// Expires leases and reassemblies due at `now`; what is then due to send comes from
    /// [`poll_transmit`](Self::poll_transmit).
    pub fn handle_timeout(&mut self, now: Time) {
        let expired: Vec<GuidPrefix> =
            self.remote.iter().filter(|r| r.lease_expires <= now).map(|r| r.data.guid_prefix).collect();
        for prefix in expired {
            self.remove_participant(prefix, LostReason::LeaseExpired);
        }
        for r in &mut self.readers {
            r.expire(now);
        }
    }

    fn writer_config(&self, qos: &Qos, depth: usize, mode: WriteMode) -> crate::endpoint::WriterConfig {
        crate::endpoint::WriterConfig {
            transient_local: qos.is_transient_local(),
            depth,
            mode,
            heartbeat_period: self.config.heartbeat_period,
            nack_response_delay: self.config.nack_response_delay,
            max_readers: self.config.limits.endpoints_per_participant,
        }
    }

    fn reader_config(&self, depth: usize) -> crate::endpoint::ReaderConfig {
        let l = &self.config.limits;
        crate::endpoint::ReaderConfig {
            depth,
            heartbeat_response_delay: self.config.heartbeat_response_delay,
            reassemblies: l.reassemblies,
            reassembly_bytes: l.reassembly_bytes,
            reassembly_timeout: l.reassembly_timeout,
            max_writers: l.endpoints_per_participant,
        }
    }
}

impl RemoteParticipant {
    fn endpoint(&self, guid: Guid) -> Option<&EndpointData> {
        self.writers.iter().chain(&self.readers).find(|e| e.guid == guid)
    }
}
