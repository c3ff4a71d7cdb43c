//! What this host's network looks like from the calling thread's network namespace, read
//! without changing anything: interfaces with their flags, IPv4 addresses and MTU
//! (`getifaddrs`), the IPv4 routes of the main table (`/proc/thread-self/net/route`), reverse-path filtering
//! (`/proc/sys/net/ipv4/conf`) and the nftables ruleset (`nft list ruleset`).

use std::io;
use std::net::{Ipv4Addr, SocketAddrV4, UdpSocket};
use std::process::Command;

use nix::net::if_::InterfaceFlags;
use nix::sys::socket::sockopt;

/// One network interface.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct InterfaceInfo {
    /// Its name (`eth0`).
    pub name: String,
    /// Administratively up (`IFF_UP`).
    pub up: bool,
    /// The link has carrier (`IFF_LOWER_UP`).
    pub carrier: bool,
    /// Takes multicast (`IFF_MULTICAST`).
    pub multicast: bool,
    /// The loopback interface (`IFF_LOOPBACK`).
    pub loopback: bool,
    /// Its IPv4 addresses with their prefix lengths.
    pub ipv4: Vec<(Ipv4Addr, u8)>,
    /// The MTU of its route to a neighbour on its first subnet (`IP_MTU`), when it has one.
    pub mtu: Option<u32>,
}

/// One IPv4 route of the main table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Route {
    /// The destination network.
    pub destination: Ipv4Addr,
    /// Its prefix length.
    pub prefix: u8,
    /// The gateway, `None` for a directly connected route.
    pub gateway: Option<Ipv4Addr>,
    /// The route is up (`RTF_UP`).
    pub up: bool,
}

/// A route and the interface it goes out of.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InterfaceRoute {
    /// The interface's name.
    pub interface: String,
    /// The route.
    pub route: Route,
}

/// The host's interfaces, in the order `getifaddrs` lists them.
pub fn interfaces() -> io::Result<Vec<InterfaceInfo>> {
    let mut all: Vec<InterfaceInfo> = Vec::new();
    for entry in nix::ifaddrs::getifaddrs().map_err(io::Error::from)? {
        let index = match all.iter().position(|i| i.name == entry.interface_name) {
            Some(index) => index,
            None => {
                let f = entry.flags;
                all.push(InterfaceInfo {
                    name: entry.interface_name.clone(),
                    up: f.contains(InterfaceFlags::IFF_UP),
                    carrier: f.contains(InterfaceFlags::IFF_LOWER_UP),
                    multicast: f.contains(InterfaceFlags::IFF_MULTICAST),
                    loopback: f.contains(InterfaceFlags::IFF_LOOPBACK),
                    ..InterfaceInfo::default()
                });
                all.len() - 1
            }
        };
        let ip = entry.address.as_ref().and_then(|a| a.as_sockaddr_in()).map(|a| a.ip());
        let mask = entry.netmask.as_ref().and_then(|a| a.as_sockaddr_in()).map(|a| a.ip());
        if let (Some(ip), Some(mask)) = (ip, mask) {
            all[index].ipv4.push((ip, u32::from(mask).leading_ones() as u8));
        }
    }
    let own: Vec<Ipv4Addr> = all.iter().flat_map(|i| i.ipv4.iter().map(|(ip, _)| *ip)).collect();
    for interface in &mut all {
        interface.mtu = interface.ipv4.first().and_then(|&(ip, prefix)| route_mtu(&interface.name, ip, prefix, &own));
    }
    Ok(all)
}

/// The MTU of the route from `ip` to a neighbour on its subnet that is none of `own`: a UDP
/// socket bound there (and to `interface` where allowed) is connected, which sends nothing.
fn route_mtu(interface: &str, ip: Ipv4Addr, prefix: u8, own: &[Ipv4Addr]) -> Option<u32> {
    let neighbour = neighbour(ip, prefix, own)?;
    let socket = UdpSocket::bind(SocketAddrV4::new(ip, 0)).ok()?;
    // Unprivileged: refused, and the route lookup alone picks the interface.
    let _ = nix::sys::socket::setsockopt(&socket, sockopt::BindToDevice, &std::ffi::OsString::from(interface));
    socket.connect(SocketAddrV4::new(neighbour, 9)).ok()?;
    nix::sys::socket::getsockopt(&socket, sockopt::IpMtu).ok().and_then(|mtu| u32::try_from(mtu).ok())
}

/// An address on `ip`'s subnet that is neither its network nor broadcast address nor one of `own`.
fn neighbour(ip: Ipv4Addr, prefix: u8, own: &[Ipv4Addr]) -> Option<Ipv4Addr> {
    if prefix == 0 || prefix >= 31 {
        return None;
    }
    let mask = u32::MAX << (32 - u32::from(prefix));
    let network = u32::from(ip) & mask;
    (1..=8u32)
        .filter(|host| host & mask == 0)
        .map(|host| Ipv4Addr::from(network | host))
        .find(|candidate| u32::from(*candidate) & !mask != !mask && !own.contains(candidate))
}

/// The IPv4 routes of the main table in the calling thread's network namespace
/// (`/proc/thread-self/net/route`; `/proc/net/route` is the process's).
pub fn ipv4_routes() -> io::Result<Vec<InterfaceRoute>> {
    let text = std::fs::read_to_string("/proc/thread-self/net/route")
        .or_else(|_| std::fs::read_to_string("/proc/net/route"))?;
    Ok(parse_proc_net_route(&text))
}

/// The routes of a `/proc/net/route` text; lines that do not parse are left out.
pub fn parse_proc_net_route(text: &str) -> Vec<InterfaceRoute> {
    const RTF_UP: u16 = 0x1;
    const RTF_GATEWAY: u16 = 0x2;
    let hex_ip = |field: &str| u32::from_str_radix(field, 16).ok().map(|v| Ipv4Addr::from(v.swap_bytes()));
    text.lines()
        .skip(1)
        .filter_map(|line| {
            let fields: Vec<&str> = line.split_whitespace().collect();
            let (interface, destination, gateway, flags, mask) =
                (fields.first()?, hex_ip(fields.get(1)?)?, hex_ip(fields.get(2)?)?, fields.get(3)?, fields.get(7)?);
            let flags = u16::from_str_radix(flags, 16).ok()?;
            let mask = hex_ip(mask)?;
            Some(InterfaceRoute {
                interface: (*interface).to_owned(),
                route: Route {
                    destination,
                    prefix: u32::from(mask).leading_ones() as u8,
                    gateway: (flags & RTF_GATEWAY != 0).then_some(gateway),
                    up: flags & RTF_UP != 0,
                },
            })
        })
        .collect()
}

/// Reverse-path filtering in effect on `interface`: the larger of its own and `all`'s setting
/// (0 off, 1 strict, 2 loose), as the kernel applies it; `None` when not readable.
pub fn rp_filter(interface: &str) -> Option<u8> {
    let read = |name: &str| -> Option<u8> {
        std::fs::read_to_string(format!("/proc/sys/net/ipv4/conf/{name}/rp_filter")).ok()?.trim().parse().ok()
    };
    let own = read(interface)?;
    Some(own.max(read("all").unwrap_or(0)))
}

/// Why the firewall's rules could not be read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FirewallError {
    /// `nft` could not be run.
    #[error("cannot run nft (nftables' command): {0}")]
    NoNft(#[source] io::Error),
    /// `nft` refused (without the rights to read the ruleset, usually): the first line it said.
    #[error("nft list ruleset: {0}")]
    Refused(String),
}

/// The nftables ruleset as `nft list ruleset` prints it (read only; iptables-nft rules appear
/// there too).
pub fn nft_ruleset() -> Result<String, FirewallError> {
    let out = Command::new("nft").args(["list", "ruleset"]).output().map_err(FirewallError::NoNft)?;
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        return Err(FirewallError::Refused(stderr.lines().next().unwrap_or_default().trim().to_owned()));
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn proc_net_route_lines_become_routes() {
        let text = "Iface\tDestination\tGateway \tFlags\tRefCnt\tUse\tMetric\tMask\t\tMTU\tWindow\tIRTT\n\
                    eth0\t00000000\t0101A8C0\t0003\t0\t0\t100\t00000000\t0\t0\t0\n\
                    eth0\t007BA8C0\t00000000\t0001\t0\t0\t100\t00FFFFFF\t0\t0\t0\n\
                    lo\t000000E0\t00000000\t0001\t0\t0\t0\t000000F0\t0\t0\t0\n\
                    bad line\n";
        let routes = parse_proc_net_route(text);
        assert_eq!(routes.len(), 3);
        assert_eq!(routes[0].route.gateway, Some(Ipv4Addr::new(192, 168, 1, 1)));
        assert_eq!((routes[0].route.destination, routes[0].route.prefix), (Ipv4Addr::UNSPECIFIED, 0));
        assert_eq!((routes[1].route.destination, routes[1].route.prefix), (Ipv4Addr::new(192, 168, 123, 0), 24));
        assert_eq!(routes[1].route.gateway, None);
        assert_eq!((routes[2].interface.as_str(), routes[2].route.prefix), ("lo", 4));
        assert_eq!(routes[2].route.destination, Ipv4Addr::new(224, 0, 0, 0));
    }

    #[test]
    fn a_neighbour_is_on_the_subnet_and_not_ours() {
        let ip = Ipv4Addr::new(192, 168, 123, 1);
        assert_eq!(neighbour(ip, 24, &[ip]), Some(Ipv4Addr::new(192, 168, 123, 2)));
        assert_eq!(neighbour(ip, 32, &[ip]), None);
        assert_eq!(neighbour(ip, 0, &[ip]), None);
        assert_eq!(
            neighbour(Ipv4Addr::new(10, 0, 0, 1), 30, &[Ipv4Addr::new(10, 0, 0, 1)]),
            Some([10, 0, 0, 2].into())
        );
    }

    #[test]
    fn the_host_has_an_interface_and_loopback_is_one() {
        let all = interfaces().unwrap();
        assert!(all.iter().any(|i| i.loopback), "{all:?}");
    }
}
