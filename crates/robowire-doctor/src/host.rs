//! The host and interface checks: pure functions of a [`HostObservation`].

use std::net::Ipv4Addr;
use std::ops::RangeInclusive;

use robowire_udp::host::{InterfaceInfo, InterfaceRoute};

use crate::check::Check;
use crate::firewall;

/// What was read of the host (`diagnose` reads it through `robowire_udp::host`).
#[derive(Debug, Clone)]
pub struct HostObservation {
    /// Its interfaces, or why they could not be listed.
    pub interfaces: Result<Vec<InterfaceInfo>, String>,
    /// Its IPv4 routes (main table), or why they could not be read.
    pub routes: Result<Vec<InterfaceRoute>, String>,
    /// Reverse-path filtering on the interface (0 off, 1 strict, 2 loose), if readable.
    pub rp_filter: Option<u8>,
    /// The nftables ruleset, or why it could not be read.
    pub firewall: Result<String, String>,
}

/// A robot's subnet and its address there.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RobotNet {
    /// The robot's address (Go2 192.168.123.161, G1 192.168.123.164, ZSL-1 192.168.234.1).
    pub robot: Ipv4Addr,
    /// The subnet's prefix length (24).
    pub prefix: u8,
    /// An address for this host there (`192.168.123.99`).
    pub host: Ipv4Addr,
}

/// What the interface must offer.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HostExpectations {
    /// The interface the robot is on.
    pub interface: String,
    /// The robot's subnet, when known.
    pub net: Option<RobotNet>,
    /// DDS: multicast must reach the interface.
    pub multicast: bool,
    /// UDP ports the robot's traffic arrives on (DDS 7400–7700, ZSL-1 43988).
    pub ports: Vec<RangeInclusive<u16>>,
}

/// Whether `ip` is on `subnet`/`prefix`.
pub fn on_subnet(ip: Ipv4Addr, subnet: Ipv4Addr, prefix: u8) -> bool {
    network(ip, prefix) == network(subnet, prefix)
}

/// The network of `ip`/`prefix`.
fn network(ip: Ipv4Addr, prefix: u8) -> Ipv4Addr {
    let mask = if prefix == 0 { 0 } else { u32::MAX << (32 - u32::from(prefix.min(32))) };
    Ipv4Addr::from(u32::from(ip) & mask)
}

fn addresses(i: &InterfaceInfo) -> String {
    if i.ipv4.is_empty() {
        return "no IPv4 address".into();
    }
    i.ipv4.iter().map(|(ip, p)| format!("{ip}/{p}")).collect::<Vec<_>>().join(", ")
}

/// The route `ip` takes: the longest prefix that holds it.
pub fn route_to(routes: &[InterfaceRoute], ip: Ipv4Addr) -> Option<&InterfaceRoute> {
    routes
        .iter()
        .filter(|r| r.route.up && on_subnet(ip, r.route.destination, r.route.prefix))
        .max_by_key(|r| r.route.prefix)
}

/// The host and interface checks, in order; after a missing interface, no other.
pub fn checks(seen: &HostObservation, expect: &HostExpectations) -> Vec<Check> {
    let name = expect.interface.as_str();
    let interfaces = match &seen.interfaces {
        Ok(all) => all,
        Err(why) => return vec![Check::unknown("interface", format!("cannot list the interfaces: {why}"))],
    };
    let Some(interface) = interfaces.iter().find(|i| i.name == name) else {
        let listed = interfaces.iter().map(|i| format!("{} ({})", i.name, addresses(i))).collect::<Vec<_>>();
        return vec![Check::fail(
            "interface",
            format!("no interface {name:?}; this host has {}", listed.join(", ")),
            "name the interface cabled to the robot (one of those): robowire doctor go2:IFACE or --interface IFACE",
        )];
    };
    let mut out = vec![Check::pass("interface", format!("{name} ({})", addresses(interface)))];
    out.push(link(interface));
    out.push(address(interface, expect.net));
    out.push(mtu(interface));
    if expect.multicast {
        out.push(multicast_flag(interface));
        out.push(multicast_route(name, &seen.routes));
    }
    out.push(shared_subnet(interface, interfaces));
    out.push(rp_filter(seen, interface, expect));
    for ports in &expect.ports {
        out.push(firewall_check(&seen.firewall, ports));
    }
    out
}

fn link(i: &InterfaceInfo) -> Check {
    let name = &i.name;
    if !i.up {
        Check::fail("link", format!("{name} is down"), format!("sudo ip link set {name} up"))
    } else if !i.carrier {
        Check::fail(
            "link",
            format!("{name} is up without carrier"),
            "plug the cable into the robot (or its switch) and check that the robot is on",
        )
    } else {
        Check::pass("link", format!("{name} is up with carrier"))
    }
}

fn address(i: &InterfaceInfo, net: Option<RobotNet>) -> Check {
    let name = &i.name;
    if i.loopback {
        return Check::pass("address", format!("{name} is loopback ({}): a simulator on this machine", addresses(i)));
    }
    match net {
        Some(net) if i.ipv4.iter().any(|&(ip, _)| on_subnet(ip, net.robot, net.prefix)) => Check::pass(
            "address",
            format!("{} on the robot's subnet {}/{}", addresses(i), network(net.robot, net.prefix), net.prefix),
        ),
        Some(net) => Check::fail(
            "address",
            format!(
                "{name} has {}, not on the robot's subnet {}/{} (the robot is {})",
                addresses(i),
                network(net.robot, net.prefix),
                net.prefix,
                net.robot
            ),
            format!("sudo ip addr add {}/{} dev {name}", net.host, net.prefix),
        ),
        None if i.ipv4.is_empty() => Check::fail(
            "address",
            format!("{name} has no IPv4 address"),
            format!(
                "give {name} an address on the robot's subnet: sudo ip addr add 192.168.123.99/24 dev {name} (Go2, G1) or 192.168.234.99/24 (ZSL-1)"
            ),
        ),
        None => Check::pass("address", addresses(i)),
    }
}

fn mtu(i: &InterfaceInfo) -> Check {
    match i.mtu {
        Some(mtu) if mtu >= 1500 => Check::pass("MTU", format!("{mtu}")),
        Some(mtu) => Check::fail(
            "MTU",
            format!("{mtu}: the robots' datagrams of up to 1500 bytes are dropped or fragmented"),
            format!("sudo ip link set {} mtu 1500", i.name),
        ),
        None => Check::unknown("MTU", "not measurable (no IPv4 neighbour on the interface's subnet)"),
    }
}

fn multicast_flag(i: &InterfaceInfo) -> Check {
    let name = &i.name;
    if i.multicast {
        Check::pass("multicast", format!("{name} has the MULTICAST flag"))
    } else {
        Check::fail(
            "multicast",
            format!("{name} lacks the MULTICAST flag: DDS discovery (SPDP) is multicast and finds nobody"),
            format!("sudo ip link set {name} multicast on"),
        )
    }
}

fn multicast_route(name: &str, routes: &Result<Vec<InterfaceRoute>, String>) -> Check {
    const SPDP: Ipv4Addr = Ipv4Addr::new(239, 255, 0, 1);
    let fix = format!("sudo ip route add 224.0.0.0/4 dev {name}");
    let routes = match routes {
        Ok(routes) => routes,
        Err(why) => return Check::unknown("multicast route", format!("cannot read the routes: {why}")),
    };
    match route_to(routes, SPDP) {
        Some(r) if r.interface == name => {
            let what = if r.route.prefix == 0 { "the default route" } else { "a route" };
            Check::pass(
                "multicast route",
                format!("{SPDP} goes out {name} ({what} {}/{})", r.route.destination, r.route.prefix),
            )
        }
        Some(r) => Check::fail(
            "multicast route",
            format!(
                "multicast to {SPDP} goes out {} ({}/{}), not {name}",
                r.interface, r.route.destination, r.route.prefix
            ),
            fix,
        ),
        None => Check::fail("multicast route", "no route for 224.0.0.0/4 and no default route", fix),
    }
}

fn shared_subnet(i: &InterfaceInfo, all: &[InterfaceInfo]) -> Check {
    if i.loopback {
        return Check::pass("one interface per subnet", "loopback");
    }
    for &(ip, prefix) in &i.ipv4 {
        for other in all.iter().filter(|o| o.name != i.name && !o.loopback) {
            if let Some(&(theirs, their_prefix)) = other.ipv4.iter().find(|(o, _)| on_subnet(*o, ip, prefix)) {
                return Check::fail(
                    "one interface per subnet",
                    format!(
                        "{} {theirs}/{their_prefix} is on {}'s subnet too ({ip}/{prefix}): replies may leave by either",
                        other.name, i.name
                    ),
                    format!(
                        "take the subnet off one of them: sudo ip addr del {theirs}/{their_prefix} dev {}",
                        other.name
                    ),
                );
            }
        }
    }
    Check::pass("one interface per subnet", format!("no other interface on {}'s subnet", i.name))
}

fn rp_filter(seen: &HostObservation, i: &InterfaceInfo, expect: &HostExpectations) -> Check {
    let Some(mode) = seen.rp_filter else {
        return Check::unknown("reverse-path filter", "rp_filter not readable");
    };
    let label = match mode {
        0 => "off",
        1 => "strict",
        _ => "loose",
    };
    if mode != 1 || i.loopback {
        return Check::pass("reverse-path filter", format!("rp_filter {mode} ({label})"));
    }
    let robot = expect.net.map(|n| n.robot).or_else(|| i.ipv4.first().map(|(ip, _)| *ip));
    let back = match (&seen.routes, robot) {
        (Ok(routes), Some(robot)) => route_to(routes, robot).map(|r| r.interface.clone()),
        _ => None,
    };
    match back {
        Some(out) if out != i.name => Check::fail(
            "reverse-path filter",
            format!(
                "rp_filter 1 (strict) and the route back to the robot goes out {out}: its datagrams on {} are dropped",
                i.name
            ),
            format!("sudo sysctl net.ipv4.conf.{}.rp_filter=2 net.ipv4.conf.all.rp_filter=2", i.name),
        ),
        Some(_) => {
            Check::pass("reverse-path filter", format!("rp_filter 1 (strict); the route back goes out {}", i.name))
        }
        None => Check::fail(
            "reverse-path filter",
            format!("rp_filter 1 (strict) and no route back to the robot through {}", i.name),
            format!("sudo sysctl net.ipv4.conf.{}.rp_filter=2 net.ipv4.conf.all.rp_filter=2", i.name),
        ),
    }
}

fn firewall_check(ruleset: &Result<String, String>, ports: &RangeInclusive<u16>) -> Check {
    let name = "firewall";
    let shown = if ports.start() == ports.end() {
        format!("{}", ports.start())
    } else {
        format!("{}–{}", ports.start(), ports.end())
    };
    match ruleset {
        Err(why) => Check::unknown(name, format!("rules not readable ({why}); run as root to read them")),
        Ok(rules) => match firewall::udp_drop(rules, ports) {
            Some(rule) => Check::fail(
                name,
                format!("UDP {shown} dropped by {rule}"),
                format!(
                    "remove that rule, or accept UDP {shown} before it (sudo nft list ruleset -a shows its handle)"
                ),
            ),
            None => Check::pass(name, format!("no nftables rule drops UDP {shown}")),
        },
    }
}

#[cfg(test)]
#[path = "host_tests.rs"]
mod tests;
