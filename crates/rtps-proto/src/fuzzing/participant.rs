//! The participant target: a whole [`Participant`] with one reliable writer and one reader,
//! prepared once by a discovery exchange with a peer ([`ParticipantSetup`]), then driven by a
//! fuzzed sequence of [`Step`]s ([`participant_steps`]).

use alloc::vec;
use alloc::vec::Vec;
use core::net::{IpAddr, Ipv4Addr, SocketAddr};
use core::time::Duration;

use super::datagram::{Ids, fill, header, templated_datagram};
use super::step::Step;
use super::world::{LOCAL_PREFIX, MAX_PAYLOAD, PEER_PREFIX, T0, TOPIC, TYPE_NAME};
use crate::discovery::Qos;
use crate::participant::{Destination, Event, Participant, ParticipantConfig};
use crate::{EntityId, GuidPrefix, Locator};

pub(super) fn address(prefix: GuidPrefix) -> SocketAddr {
    SocketAddr::new(IpAddr::V4(Ipv4Addr::new(127, 0, 0, 1)), 7400 + u16::from(prefix.0[0]))
}

pub(super) fn fuzz_config(prefix: GuidPrefix) -> ParticipantConfig {
    let mut c = ParticipantConfig::new(prefix, 0);
    c.metatraffic_unicast = alloc::vec![Locator::udp(address(prefix))];
    c.default_unicast = c.metatraffic_unicast.clone();
    c
}

/// What every run of [`participant_steps`] starts from, built once: the discovery datagrams of a
/// real peer participant (SPDP, SEDP for one reliable writer and one reader on [`TOPIC`]), as it
/// sent them to the fuzzed participant during a complete exchange, and the peer's endpoint ids.
#[derive(Debug, Clone)]
pub struct ParticipantSetup {
    /// The peer's datagrams, in the order it sent them.
    pub discovery: Vec<Vec<u8>>,
    /// The peer's writer.
    pub peer_writer: EntityId,
    /// The peer's reader.
    pub peer_reader: EntityId,
    /// The fuzzed participant as each setup byte's two bits leave it before the first step
    /// (discovery fed or not; endpoints created before or after it): cloned per run, so a run
    /// costs no discovery exchange.
    prepared: [Option<(Participant, EntityId, EntityId)>; 4],
}

impl Default for ParticipantSetup {
    fn default() -> Self {
        Self::new()
    }
}

impl ParticipantSetup {
    /// Runs the fuzzed participant and a peer to quiet and keeps what the peer sent.
    pub fn new() -> Self {
        let mut ours = Participant::new(fuzz_config(LOCAL_PREFIX), T0);
        let mut peer = Participant::new(fuzz_config(PEER_PREFIX), T0);
        let (mut discovery, mut buf) = (Vec::new(), vec![0u8; 65_536]);
        let endpoints = |p: &mut Participant| {
            let w = p.create_writer(T0, TOPIC, TYPE_NAME, Qos::default()).expect("a writer");
            let r = p.create_reader(T0, TOPIC, TYPE_NAME, Qos::default()).expect("a reader");
            (w, r)
        };
        endpoints(&mut ours);
        let (peer_writer, peer_reader) = endpoints(&mut peer);
        for _ in 0..20 {
            while let Some(t) = ours.poll_transmit(T0, &mut buf) {
                peer.handle_datagram(T0, address(LOCAL_PREFIX), Destination::Unicast, &buf[..t.len]);
            }
            while let Some(t) = peer.poll_transmit(T0, &mut buf) {
                discovery.push(buf[..t.len].to_vec());
                ours.handle_datagram(T0, address(PEER_PREFIX), Destination::Unicast, &buf[..t.len]);
            }
        }
        let mut setup = Self { discovery, peer_writer, peer_reader, prepared: [None, None, None, None] };
        let prepared = core::array::from_fn(|flags| Some(setup.prepare(flags as u8)));
        setup.prepared = prepared;
        setup
    }

    /// The fuzzed participant before the first step, for the setup byte `flags`: endpoints
    /// created before discovery unless bit 1, the peer's discovery fed unless bit 0.
    fn prepare(&self, flags: u8) -> (Participant, EntityId, EntityId) {
        let now = T0;
        let mut p = Participant::new(fuzz_config(LOCAL_PREFIX), now);
        let endpoints = |p: &mut Participant| {
            let w = p.create_writer(now, TOPIC, TYPE_NAME, Qos::default()).expect("a writer");
            let r = p.create_reader(now, TOPIC, TYPE_NAME, Qos::default()).expect("a reader");
            (w, r)
        };
        let early = (flags & 2 == 0).then(|| endpoints(&mut p));
        if flags & 1 == 0 {
            for d in &self.discovery {
                p.handle_datagram(now, address(PEER_PREFIX), Destination::Unicast, d);
            }
        }
        let (w, r) = early.unwrap_or_else(|| endpoints(&mut p));
        (p, w, r)
    }
}

/// [`participant_steps`] with a setup built for this input alone (the corpus replay's check).
pub fn participant(input: &[u8]) {
    participant_steps(&ParticipantSetup::new(), input);
}

/// Our participant with one reliable writer and one reader on [`TOPIC`], the peer's discovery
/// fed to it (unless the setup byte says not), then `input`'s steps. Nothing is asserted but
/// that nothing panics; the fuzz target adds a bound on the heap.
pub fn participant_steps(setup: &ParticipantSetup, input: &[u8]) {
    let Some((&flags, mut rest)) = input.split_first() else { return };
    let mut now = T0;
    let (mut p, writer, reader) = match &setup.prepared[usize::from(flags & 3)] {
        Some(prepared) => prepared.clone(),
        None => setup.prepare(flags & 3),
    };
    let ids = Ids { writer, reader, peer_writer: setup.peer_writer, peer_reader: setup.peer_reader };
    let mut buf = vec![0u8; 65_536];
    let mut datagram = Vec::with_capacity(65_536);
    let mut payload = Vec::with_capacity(MAX_PAYLOAD + 4);
    while let Some(step) = Step::decode(&mut rest) {
        let destination = |wrap: u8| if wrap & 16 != 0 { Destination::Multicast } else { Destination::Unicast };
        let mut wrap_byte = 0;
        datagram.clear();
        match step {
            Step::Raw(b) => datagram.extend_from_slice(b),
            Step::FromPeer(b) => {
                header(&mut datagram);
                datagram.extend_from_slice(b);
            }
            Step::Discovery { index, patches } => {
                let Some(d) = setup.discovery.get(usize::from(index) % setup.discovery.len().max(1)) else {
                    continue;
                };
                datagram.extend_from_slice(d);
                for (at, value) in patches {
                    if at != 0 && !datagram.is_empty() {
                        let i = usize::from(at - 1) % datagram.len();
                        datagram[i] = value;
                    }
                }
            }
            Step::Clock { ms } => {
                now = now + Duration::from_millis(u64::from(ms % 10_001));
                p.handle_timeout(now);
                continue;
            }
            Step::Poll => {
                while p.poll_transmit(now, &mut buf).is_some() {}
                while let Some(e) = p.poll_event() {
                    if let Event::Sample(s) = e {
                        p.recycle(s.payload);
                    }
                }
                continue;
            }
            Step::Write { len } => {
                fill(&mut payload, usize::from(len) % (MAX_PAYLOAD + 1), 0x5a);
                let _ = p.write(now, writer, &payload, &Default::default(), &mut buf);
                continue;
            }
            templated => {
                wrap_byte = templated_datagram(&mut datagram, &templated, &ids, &mut payload);
            }
        }
        p.handle_datagram(now, address(PEER_PREFIX), destination(wrap_byte), &datagram);
    }
}
