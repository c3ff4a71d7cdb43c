//! Two participants in memory, for the tests that need a discovered, matched peer without a
//! network: each's configuration, and carrying datagrams between them until both are quiet.

use std::net::SocketAddr;

use rtps_proto::participant::{Destination, Participant, ParticipantConfig};
use rtps_proto::{GuidPrefix, Locator, Time};

/// Participant `n`: GUID prefix `[n; 12]`, unicast on 127.0.0.1:(7400 + 10n).
pub(crate) fn config(n: u8) -> ParticipantConfig {
    config_at([n; 12], 7400 + 10 * u16::from(n))
}

/// A participant of GUID prefix `prefix`, unicast on 127.0.0.1:`port`.
pub(crate) fn config_at(prefix: [u8; 12], port: u16) -> ParticipantConfig {
    let mut c = ParticipantConfig::new(GuidPrefix(prefix), 0);
    let addr: SocketAddr = format!("127.0.0.1:{port}").parse().unwrap();
    c.metatraffic_unicast = vec![Locator::udp(addr)];
    c.default_unicast = c.metatraffic_unicast.clone();
    c
}

/// Carries datagrams both ways until both are quiet.
pub(crate) fn exchange(now: Time, a: &mut Participant, b: &mut Participant) {
    let mut buf = vec![0u8; 65_536];
    let from: SocketAddr = "127.0.0.1:7400".parse().unwrap();
    for _ in 0..20 {
        while let Some(t) = a.poll_transmit(now, &mut buf) {
            b.handle_datagram(now, from, Destination::Unicast, &buf[..t.len]);
        }
        while let Some(t) = b.poll_transmit(now, &mut buf) {
            a.handle_datagram(now, from, Destination::Unicast, &buf[..t.len]);
        }
    }
}
