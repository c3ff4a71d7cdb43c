//! The DDS checks of a Unitree robot: pure functions of a [`DdsObservation`].

use std::net::{IpAddr, Ipv4Addr, SocketAddr};

use robowire_dds::{DiscoveredEndpoint, DiscoveredParticipant, TopicStats};

use crate::check::Check;
use crate::host::on_subnet;

/// The robot's state topic.
pub const LOWSTATE: &str = "rt/lowstate";
/// The robot's command topic.
pub const LOWCMD: &str = "rt/lowcmd";

/// What was heard on DDS during the listening time (`diagnose` listens with a participant).
#[derive(Debug, Clone, Default)]
pub struct DdsObservation {
    /// The domain listened on.
    pub domain: u16,
    /// How long it listened, seconds.
    pub seconds: f64,
    /// The interface's IPv4 addresses and prefixes.
    pub interface_ipv4: Vec<(Ipv4Addr, u8)>,
    /// Whether the interface is loopback.
    pub loopback: bool,
    /// The participants heard on `domain`.
    pub participants: Vec<DiscoveredParticipant>,
    /// Their endpoints (SEDP).
    pub endpoints: Vec<DiscoveredEndpoint>,
    /// When nobody was heard on `domain`: each other domain of 0–9 listened on, with the
    /// participants heard there.
    pub other_domains: Vec<(u16, usize)>,
    /// What `rt/lowstate`'s reader counted since it matched a writer, and over how many seconds.
    pub lowstate: Option<(TopicStats, f64)>,
    /// The last HG LowState's `mode_machine`.
    pub mode_machine: Option<u8>,
    /// The services discovered ([`services`]), each with its API version or why it did not
    /// answer (`None`: a service robowire does not ask).
    pub services: Vec<(String, Option<Result<String, String>>)>,
    /// The sport mode owning the motors as motion_switcher's CheckMode named it ("": none), or
    /// why it did not answer (`None`: not asked, no motion_switcher discovered).
    pub motors_owner: Option<Result<String, String>>,
}

/// The services whose request topic (`rt/api/NAME/request`) has a reader: those that answer.
pub fn services(endpoints: &[DiscoveredEndpoint]) -> Vec<String> {
    let mut names: Vec<String> = endpoints
        .iter()
        .filter(|e| !e.writer)
        .filter_map(|e| e.topic.strip_prefix("rt/api/")?.strip_suffix("/request").map(str::to_owned))
        .collect();
    names.sort();
    names.dedup();
    names
}

fn vendor(p: &DiscoveredParticipant) -> String {
    match p.vendor.1 {
        Some(name) => name.to_owned(),
        None => format!("vendor {:02x}{:02x}", p.vendor.0[0], p.vendor.0[1]),
    }
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn locators(p: &DiscoveredParticipant) -> String {
    let mut all: Vec<String> = p.unicast.iter().map(SocketAddr::to_string).collect();
    all.dedup();
    if all.is_empty() { "no unicast locator".into() } else { all.join(" ") }
}

/// Whether the interface reaches `address`: on one of its subnets, or loopback from loopback.
fn reachable(seen: &DdsObservation, address: &SocketAddr) -> bool {
    match address.ip() {
        IpAddr::V4(ip) if ip.is_loopback() => seen.loopback,
        IpAddr::V4(ip) => seen.interface_ipv4.iter().any(|&(own, prefix)| on_subnet(ip, own, prefix)),
        IpAddr::V6(_) => false,
    }
}

/// The DDS checks, in order.
pub fn checks(seen: &DdsObservation) -> Vec<Check> {
    let domain = seen.domain;
    if seen.participants.is_empty() {
        let heard: Vec<String> =
            seen.other_domains.iter().filter(|(_, n)| *n > 0).map(|(d, n)| format!("domain {d} ({n})")).collect();
        let check = if heard.is_empty() {
            Check::fail(
                "DDS participants",
                format!("nobody heard on domain {domain} nor on domains 0–9 in {:.1} s", seen.seconds),
                "check the checks above, that the robot is on and booted, and that this is the interface cabled to it",
            )
        } else {
            let first = seen.other_domains.iter().find(|(_, n)| *n > 0).map_or(0, |(d, _)| *d);
            Check::fail(
                "DDS participants",
                format!("nobody on domain {domain}; participants on {}", heard.join(", ")),
                format!(
                    "use domain {first} (robowire --domain {first}; Unitree's SDK: ChannelFactoryInitialize({first}, …))"
                ),
            )
        };
        return vec![check];
    }
    let listed: Vec<String> =
        seen.participants.iter().map(|p| format!("{} {} at {}", vendor(p), hex(&p.guid_prefix), locators(p))).collect();
    let mut out = vec![Check::pass(
        "DDS participants",
        format!("{} on domain {domain}: {}", seen.participants.len(), listed.join("; ")),
    )];
    out.push(locator_check(seen));
    out.extend(lowstate_checks(seen));
    out.push(lowcmd_writers(seen));
    if let Some(mode_machine) = seen.mode_machine {
        out.push(mode_machine_check(mode_machine));
    }
    out.push(services_check(&seen.services));
    if let Some(owner) = &seen.motors_owner {
        out.push(match owner {
            Ok(mode) if mode.is_empty() => Check::pass("motors", "no sport mode owns them: rt/lowcmd drives them"),
            Ok(mode) => Check::pass(
                "motors",
                format!("sport mode {mode:?} owns them: release it before sending rt/lowcmd (robowire go2|g1 release)"),
            ),
            Err(why) => Check::unknown("motors", format!("motion_switcher's CheckMode did not answer: {why}")),
        });
    }
    out
}

fn services_check(services: &[(String, Option<Result<String, String>>)]) -> Check {
    if services.is_empty() {
        return Check::unknown("services", "no service's request reader discovered (rt/api/*/request)");
    }
    let silent: Vec<String> = services
        .iter()
        .filter_map(|(name, version)| match version {
            Some(Err(why)) => Some(format!("{name} ({why})")),
            _ => None,
        })
        .collect();
    if !silent.is_empty() {
        return Check::fail(
            "services",
            format!("discovered but not answering: {}", silent.join(", ")),
            "requests reach the robot but no answer comes back (Unitree's \"send request error\"): see the DDS locators and firewall checks",
        );
    }
    let listed: Vec<String> = services
        .iter()
        .map(|(name, version)| match version {
            Some(Ok(version)) => format!("{name} {version}"),
            _ => format!("{name} (not asked)"),
        })
        .collect();
    Check::pass("services", listed.join(", "))
}

fn mode_machine_check(mode_machine: u8) -> Check {
    use unitree_proto::g1::G1Variant;
    let name = "HG mode_machine";
    match G1Variant::of_mode_machine(mode_machine) {
        Some(variant) => Check::pass(name, format!("{mode_machine}: a G1 {variant:?}; LowCmds must carry it")),
        None if mode_machine == 0 => Check::pass(name, "0: a simulator's (LowCmds must carry it)"),
        None => Check::unknown(name, format!("{mode_machine}: in no G1 table (an H1-2, or a newer revision)")),
    }
}

fn locator_check(seen: &DdsObservation) -> Check {
    let unreachable: Vec<String> = seen
        .participants
        .iter()
        .filter(|p| !p.unicast.iter().any(|a| reachable(seen, a)))
        .map(|p| format!("{} {} announces {}", vendor(p), hex(&p.guid_prefix), locators(p)))
        .collect();
    if unreachable.is_empty() {
        return Check::pass("DDS locators", "every participant announces a unicast locator on this interface's subnet");
    }
    let own: Vec<String> = seen.interface_ipv4.iter().map(|(ip, p)| format!("{ip}/{p}")).collect();
    Check::fail(
        "DDS locators",
        format!(
            "{}: not reachable from {} (topics are listed but no data comes)",
            unreachable.join("; "),
            own.join(", ")
        ),
        "make that side use the interface cabled to this one (Unitree's SDK: ChannelFactoryInitialize(0, \"eth0\"); CycloneDDS: <NetworkInterfaceAddress>)",
    )
}

fn lowstate_checks(seen: &DdsObservation) -> Vec<Check> {
    let writers = seen.endpoints.iter().filter(|e| e.writer && e.topic == LOWSTATE).count();
    let Some((stats, seconds)) = seen.lowstate.as_ref().filter(|_| writers > 0) else {
        return vec![Check::fail(
            LOWSTATE,
            "no participant publishes rt/lowstate",
            "start the robot's low-level service (a robot booted normally publishes it), or the simulator",
        )];
    };
    let arrived = stats.samples + stats.checksum_errors + stats.decode_errors;
    if arrived == 0 {
        return vec![Check::fail(
            LOWSTATE,
            format!("{writers} writer(s) discovered, no sample arrived in {seconds:.1} s"),
            "the data is lost on the way back: see the firewall, reverse-path filter and DDS locators checks",
        )];
    }
    let rate = arrived as f64 / seconds.max(1e-3);
    let mut out = vec![Check::pass(LOWSTATE, format!("{arrived} samples in {seconds:.1} s ({rate:.0} Hz)"))];
    let good = 100.0 * stats.samples as f64 / arrived as f64;
    let saw = format!(
        "{good:.1}% of {arrived} with a good CRC ({} bad CRC, {} undecodable)",
        stats.checksum_errors, stats.decode_errors
    );
    out.push(if stats.samples == arrived {
        Check::pass("LowState CRC", saw)
    } else {
        Check::fail(
            "LowState CRC",
            saw,
            "the LowStates are corrupted by their sender or on the way: check the cable and switch, and that a bridge or simulator in between computes Unitree's CRC",
        )
    });
    out
}

fn lowcmd_writers(seen: &DdsObservation) -> Check {
    let writers: Vec<String> = seen
        .endpoints
        .iter()
        .filter(|e| e.writer && e.topic == LOWCMD)
        .map(|e| {
            let vendor = seen.participants.iter().find(|p| p.guid_prefix[..] == e.guid[..12]).map(vendor);
            format!("{} ({})", hex(&e.guid), vendor.unwrap_or_else(|| "unknown participant".into()))
        })
        .collect();
    if writers.is_empty() {
        return Check::pass("rt/lowcmd writers", "nobody else publishes rt/lowcmd");
    }
    Check::fail(
        "rt/lowcmd writers",
        format!("already published by {}: {}", writers.len(), writers.join(", ")),
        "stop that controller before starting yours: two writers of rt/lowcmd fight over the motors",
    )
}

#[cfg(test)]
#[path = "dds_tests.rs"]
mod tests;
