#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

pub mod host;
mod link;
mod stats;

use std::fmt;
use std::io;
use std::net::{IpAddr, Ipv4Addr, SocketAddr};

pub use link::{Peer, UdpLink, UdpReceiver, UdpSender};
pub use stats::{LinkStats, StatsHandle};

/// What went wrong on a link. `E` is the codec's error.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum UdpError<E> {
    /// The socket could not be bound.
    #[error("cannot bind UDP {addr} (this host's IPv4 addresses: {})", HostAddresses(.host_ipv4))]
    Bind {
        /// The address asked for.
        addr: SocketAddr,
        /// Why.
        source: io::Error,
        /// The host's IPv4 addresses, to pick a `local_ip` from.
        host_ipv4: Vec<Ipv4Addr>,
    },
    /// A socket error while sending or receiving (counted in [`LinkStats`]).
    #[error("UDP I/O")]
    Io(#[from] io::Error),
    /// The message could not be encoded (nothing was sent; counted as a send error).
    #[error("cannot encode the message: {0}")]
    Encode(E),
    /// A datagram from the peer could not be decoded (it is counted and dropped).
    #[error("datagram from the peer does not decode: {0}")]
    Decode(E),
    /// A [`Peer::Any`] link has nobody to send to yet: no datagram has arrived and no
    /// `reply_to` was given.
    #[error("no peer to send to yet (nothing has been received)")]
    NoPeer,
}

struct HostAddresses<'a>(&'a [Ipv4Addr]);

impl fmt::Display for HostAddresses<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0.is_empty() {
            return f.write_str("none found");
        }
        for (i, ip) in self.0.iter().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            write!(f, "{ip}")?;
        }
        Ok(())
    }
}

/// The host's network interfaces with their IPv4 addresses (name, address), or none if they
/// cannot be listed. An interface with several addresses appears once per address.
pub fn host_interfaces() -> Vec<(String, Ipv4Addr)> {
    if_addrs::get_if_addrs()
        .map(|ifs| {
            ifs.into_iter()
                .filter_map(|i| match i.ip() {
                    IpAddr::V4(v4) => Some((i.name, v4)),
                    IpAddr::V6(_) => None,
                })
                .collect()
        })
        .unwrap_or_default()
}

/// The host's IPv4 addresses (loopback included), or none if the interfaces cannot be listed.
pub fn host_ipv4_addresses() -> Vec<Ipv4Addr> {
    let mut ips: Vec<Ipv4Addr> = host_interfaces().into_iter().map(|(_, ip)| ip).collect();
    ips.sort();
    ips.dedup();
    ips
}
