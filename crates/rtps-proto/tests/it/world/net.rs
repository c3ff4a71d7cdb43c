//! An in-memory network of participants on a fake clock (quinn-proto's `Pair`, for N): every
//! datagram a participant emits is carried to the participants listening at its destinations,
//! with seeded loss, duplication and reordering.

use std::collections::VecDeque;
use std::net::{Ipv4Addr, SocketAddr, SocketAddrV4};
use std::time::Duration;

use rtps_proto::participant::{Destination, Event, Participant, ParticipantConfig};
use rtps_proto::{GuidPrefix, Locator, Time};

/// The SPDP multicast locator of domain 0.
pub(crate) const SPDP_GROUP: SocketAddrV4 = SocketAddrV4::new(Ipv4Addr::new(239, 255, 0, 1), 7400);

/// A small deterministic generator (xorshift64*), so that faults are seeded.
#[derive(Debug, Clone)]
pub(crate) struct Rng(u64);

impl Rng {
    pub(crate) fn new(seed: u64) -> Self {
        Self(seed.max(1))
    }
    pub(crate) fn next(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    /// True with probability `p`.
    pub(crate) fn chance(&mut self, p: f64) -> bool {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64 <= p && p > 0.0
    }
}

/// How the network misbehaves.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Faults {
    /// Probability a datagram is lost.
    pub(crate) loss: f64,
    /// Probability a datagram arrives twice.
    pub(crate) duplicate: f64,
    /// Probability a datagram is held back by up to `max_delay`.
    pub(crate) reorder: f64,
    pub(crate) max_delay: Duration,
}

pub(crate) struct Node {
    pub(crate) participant: Participant,
    pub(crate) events: Vec<Event>,
    /// Drops everything this node sends (a silent peer) when set.
    pub(crate) muted: bool,
    /// Drops everything this node receives when set.
    pub(crate) deaf: bool,
    pub(crate) unicast: [SocketAddr; 2],
}

struct InFlight {
    at: Time,
    to: usize,
    from: SocketAddr,
    multicast: bool,
    bytes: Vec<u8>,
}

pub(crate) struct World {
    pub(crate) now: Time,
    pub(crate) nodes: Vec<Node>,
    pub(crate) faults: Faults,
    pub(crate) rng: Rng,
    queue: VecDeque<InFlight>,
    pub(crate) delivered: u64,
    /// Every datagram sent, for inspection.
    pub(crate) sent: u64,
    buf: Vec<u8>,
}

/// A participant's configuration in the world: node `i` listens on 127.0.0.1:(7410+2i) for
/// discovery and 7411+2i for data, announces to the SPDP group.
pub(crate) fn config(i: usize) -> ParticipantConfig {
    let mut c = ParticipantConfig::new(GuidPrefix([i as u8 + 1; 12]), 0);
    let meta = SocketAddrV4::new(Ipv4Addr::LOCALHOST, 7410 + 2 * i as u16);
    let data = SocketAddrV4::new(Ipv4Addr::LOCALHOST, 7411 + 2 * i as u16);
    c.metatraffic_unicast = vec![Locator::udpv4(meta)];
    c.default_unicast = vec![Locator::udpv4(data)];
    c.metatraffic_multicast = vec![Locator::udpv4(SPDP_GROUP)];
    c.spdp_destinations = vec![Locator::udpv4(SPDP_GROUP)];
    c
}

impl World {
    pub(crate) fn new(n: usize, seed: u64) -> Self {
        Self::configured(n, seed, |_| {})
    }

    /// As [`new`](Self::new), each participant's configuration changed by `change`.
    pub(crate) fn configured(n: usize, seed: u64, change: impl Fn(&mut ParticipantConfig)) -> Self {
        let mut w = Self {
            now: Time::from_nanos(1_000_000_000),
            nodes: Vec::new(),
            faults: Faults::default(),
            rng: Rng::new(seed),
            queue: VecDeque::new(),
            delivered: 0,
            sent: 0,
            buf: vec![0; 65_536],
        };
        for i in 0..n {
            let mut c = config(i);
            change(&mut c);
            w.add(c);
        }
        w
    }

    /// Adds a participant; its index.
    pub(crate) fn add(&mut self, config: ParticipantConfig) -> usize {
        let unicast = [
            config.metatraffic_unicast[0].socket_addr().expect("udp"),
            config.default_unicast[0].socket_addr().expect("udp"),
        ];
        let participant = Participant::new(config, self.now);
        self.nodes.push(Node { participant, events: Vec::new(), muted: false, deaf: false, unicast });
        self.nodes.len() - 1
    }

    fn listeners(&self, to: SocketAddr, from: usize) -> Vec<(usize, bool)> {
        if to.ip().is_multicast() {
            return (0..self.nodes.len()).filter(|&j| j != from).map(|j| (j, true)).collect();
        }
        (0..self.nodes.len()).filter(|&j| self.nodes[j].unicast.contains(&to)).map(|j| (j, false)).collect()
    }

    /// Sends everything every participant has to send now.
    fn flush(&mut self) {
        for i in 0..self.nodes.len() {
            while let Some(t) = self.nodes[i].participant.poll_transmit(self.now, &mut self.buf) {
                self.sent += 1;
                if self.nodes[i].muted {
                    continue;
                }
                let bytes = self.buf[..t.len].to_vec();
                for l in t.destinations() {
                    let Some(to) = l.socket_addr() else { continue };
                    for (j, multicast) in self.listeners(to, i) {
                        if self.rng.chance(self.faults.loss) {
                            continue;
                        }
                        let copies = if self.rng.chance(self.faults.duplicate) { 2 } else { 1 };
                        for _ in 0..copies {
                            let delay = if self.rng.chance(self.faults.reorder) {
                                let max = self.faults.max_delay.as_nanos().max(1) as u64;
                                Duration::from_nanos(self.rng.next() % max)
                            } else {
                                Duration::ZERO
                            };
                            let from = self.nodes[i].unicast[0];
                            self.queue.push_back(InFlight {
                                at: self.now + delay,
                                to: j,
                                from,
                                multicast,
                                bytes: bytes.clone(),
                            });
                        }
                    }
                }
            }
        }
    }

    fn deliver_due(&mut self) -> bool {
        let mut any = false;
        let mut i = 0;
        while i < self.queue.len() {
            if self.queue[i].at <= self.now {
                let d = self.queue.remove(i).expect("index in range");
                if self.nodes[d.to].deaf {
                    continue;
                }
                let dest = if d.multicast { Destination::Multicast } else { Destination::Unicast };
                self.nodes[d.to].participant.handle_datagram(self.now, d.from, dest, &d.bytes);
                self.delivered += 1;
                any = true;
            } else {
                i += 1;
            }
        }
        any
    }

    fn collect_events(&mut self) {
        for n in &mut self.nodes {
            while let Some(e) = n.participant.poll_event() {
                n.events.push(e);
            }
        }
    }

    /// Carries a datagram node `from` built itself (a write's own transmit).
    pub(crate) fn inject(&mut self, from: usize, bytes: &[u8], destinations: &[Locator]) {
        self.sent += 1;
        if self.nodes[from].muted {
            return;
        }
        for l in destinations {
            let Some(to) = l.socket_addr() else { continue };
            for (j, multicast) in self.listeners(to, from) {
                if self.rng.chance(self.faults.loss) {
                    continue;
                }
                let copies = if self.rng.chance(self.faults.duplicate) { 2 } else { 1 };
                for _ in 0..copies {
                    let from_addr = self.nodes[from].unicast[0];
                    self.queue.push_back(InFlight {
                        at: self.now,
                        to: j,
                        from: from_addr,
                        multicast,
                        bytes: bytes.to_vec(),
                    });
                }
            }
        }
    }

    /// Runs until nothing is in flight and nothing is due before `now + horizon`, or `until`
    /// holds; advances the fake clock to each next deadline. Returns whether `until` held.
    pub(crate) fn run(&mut self, horizon: Duration, mut until: impl FnMut(&World) -> bool) -> bool {
        let end = self.now + horizon;
        loop {
            for n in &mut self.nodes {
                n.participant.handle_timeout(self.now);
            }
            self.flush();
            while self.deliver_due() {
                self.flush();
            }
            self.collect_events();
            if until(self) {
                return true;
            }
            let next_timer = self.nodes.iter().filter_map(|n| n.participant.poll_timeout()).min();
            let next_arrival = self.queue.iter().map(|d| d.at).min();
            let Some(next) = [next_timer, next_arrival].into_iter().flatten().min() else { return false };
            let next = next.max(self.now + Duration::from_micros(1)).min(end);
            if next >= end && self.now >= end {
                return false;
            }
            self.now = next;
        }
    }

    /// Runs for `d` of fake time.
    pub(crate) fn advance(&mut self, d: Duration) {
        self.run(d, |_| false);
    }

    /// Whether every node has discovered every other.
    pub(crate) fn all_discovered(&self) -> bool {
        self.nodes.iter().all(|n| n.participant.remote_participants().count() == self.nodes.len() - 1)
    }
}
