//! A participant's UDP sockets, by the RTPS port formula (RTPS 2.5 §9.6.1.1): the domain's SPDP
//! multicast port (shared by every participant on the host, multicast joined on the chosen
//! interfaces only), and the participant's own metatraffic and user-data unicast ports, found by
//! trying participant ids from 0.

use std::io;
use std::net::{Ipv4Addr, SocketAddr, SocketAddrV4, UdpSocket};

use rtps_proto::Locator;
use socket2::{Domain, Protocol, Socket, Type};

/// The SPDP multicast group.
pub(crate) const SPDP_GROUP: Ipv4Addr = Ipv4Addr::new(239, 255, 0, 1);
const PORT_BASE: u16 = 7400;
const DOMAIN_GAIN: u16 = 250;
const PARTICIPANT_GAIN: u16 = 2;
/// Participant ids tried before giving up (ports 7410 + 2 × id and 7411 + 2 × id).
const PARTICIPANT_IDS: u16 = 120;
/// Room for the largest UDP datagram.
pub(crate) const MAX_DATAGRAM: usize = 65_536;

/// The sockets.
#[derive(Debug)]
pub(crate) struct Sockets {
    /// The domain's SPDP port, with the group joined.
    pub(crate) spdp: UdpSocket,
    /// This participant's discovery unicast port.
    pub(crate) meta: UdpSocket,
    /// This participant's user-data unicast port; every datagram is sent from it.
    pub(crate) user: UdpSocket,
    /// The addresses announced (the interface's, or the host's).
    pub(crate) addresses: Vec<Ipv4Addr>,
    pub(crate) participant_id: u16,
    pub(crate) domain: u16,
}

/// The SPDP multicast port of `domain`.
pub(crate) fn spdp_port(domain: u16) -> Option<u16> {
    PORT_BASE.checked_add(DOMAIN_GAIN.checked_mul(domain)?)
}

fn unicast_ports(domain: u16, id: u16) -> Option<(u16, u16)> {
    let meta = spdp_port(domain)?.checked_add(10)?.checked_add(PARTICIPANT_GAIN.checked_mul(id)?)?;
    Some((meta, meta.checked_add(1)?))
}

fn udp(reuse: bool) -> io::Result<Socket> {
    let s = Socket::new(Domain::IPV4, Type::DGRAM, Some(Protocol::UDP))?;
    if reuse {
        s.set_reuse_address(true)?;
    }
    Ok(s)
}

fn bind(port: u16, reuse: bool) -> io::Result<UdpSocket> {
    let s = udp(reuse)?;
    s.bind(&SocketAddr::from((Ipv4Addr::UNSPECIFIED, port)).into())?;
    s.set_nonblocking(true)?;
    // Room for bursts (a discovery exchange, fragments of a large sample).
    let _ = s.set_recv_buffer_size(1 << 20);
    Ok(s.into())
}

impl Sockets {
    /// Opens the sockets of a participant of `domain` announcing `addresses` (non-empty).
    pub(crate) fn open(domain: u16, addresses: Vec<Ipv4Addr>) -> io::Result<Self> {
        let invalid = || io::Error::new(io::ErrorKind::InvalidInput, format!("DDS domain {domain} has no ports"));
        let port = spdp_port(domain).ok_or_else(invalid)?;
        let spdp = bind(port, true)?;
        for a in &addresses {
            spdp.join_multicast_v4(&SPDP_GROUP, a)?;
        }
        let mut last = None;
        for id in 0..PARTICIPANT_IDS {
            let Some((meta_port, user_port)) = unicast_ports(domain, id) else { break };
            let (meta, user) = match (bind(meta_port, false), bind(user_port, false)) {
                (Ok(m), Ok(u)) => (m, u),
                (Err(e), _) | (_, Err(e)) => {
                    last = Some(e);
                    continue;
                }
            };
            let sender = Socket::from(user.try_clone()?);
            if let Some(a) = addresses.first() {
                sender.set_multicast_if_v4(a)?;
            }
            sender.set_multicast_loop_v4(true)?;
            let _ = sender.set_send_buffer_size(1 << 20);
            return Ok(Self { spdp, meta, user, addresses, participant_id: id, domain });
        }
        Err(last.unwrap_or_else(invalid))
    }

    fn ports(&self) -> (u16, u16) {
        unicast_ports(self.domain, self.participant_id).unwrap_or((0, 0))
    }

    /// Where this participant receives discovery traffic sent to it alone.
    pub(crate) fn metatraffic_unicast(&self) -> Vec<Locator> {
        let (meta, _) = self.ports();
        self.addresses.iter().map(|a| Locator::udpv4(SocketAddrV4::new(*a, meta))).collect()
    }

    /// Where it receives user data.
    pub(crate) fn default_unicast(&self) -> Vec<Locator> {
        let (_, user) = self.ports();
        self.addresses.iter().map(|a| Locator::udpv4(SocketAddrV4::new(*a, user))).collect()
    }

    /// The SPDP multicast locator.
    pub(crate) fn spdp_multicast(&self) -> Locator {
        Locator::udpv4(SocketAddrV4::new(SPDP_GROUP, spdp_port(self.domain).unwrap_or(PORT_BASE)))
    }

    /// Sends `bytes` to each UDPv4 destination with one non-blocking `sendto`; the failures
    /// (a full socket buffer, an unreachable network) are returned as a count, never waited on.
    pub(crate) fn send(&self, bytes: &[u8], destinations: &[Locator]) -> u64 {
        let mut failed = 0;
        for l in destinations {
            match l.socket_addr() {
                Some(a @ SocketAddr::V4(_)) => failed += u64::from(self.user.send_to(bytes, a).is_err()),
                _ => failed += 1,
            }
        }
        failed
    }
}
