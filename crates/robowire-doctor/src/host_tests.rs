use robowire_udp::host::Route;

use super::*;
use crate::check::Verdict;

fn eth0() -> InterfaceInfo {
    InterfaceInfo {
        name: "eth0".into(),
        up: true,
        carrier: true,
        multicast: true,
        loopback: false,
        ipv4: vec![(Ipv4Addr::new(192, 168, 123, 99), 24)],
        mtu: Some(1500),
    }
}

fn route(interface: &str, destination: [u8; 4], prefix: u8) -> InterfaceRoute {
    InterfaceRoute {
        interface: interface.into(),
        route: Route { destination: destination.into(), prefix, gateway: None, up: true },
    }
}

fn healthy() -> HostObservation {
    HostObservation {
        interfaces: Ok(vec![eth0()]),
        routes: Ok(vec![route("eth0", [192, 168, 123, 0], 24), route("eth0", [224, 0, 0, 0], 4)]),
        rp_filter: Some(1),
        firewall: Ok(String::new()),
    }
}

fn go2() -> HostExpectations {
    HostExpectations {
        interface: "eth0".into(),
        net: Some(RobotNet { robot: [192, 168, 123, 161].into(), prefix: 24, host: [192, 168, 123, 99].into() }),
        multicast: true,
        ports: vec![7400..=7700],
    }
}

/// The one failed check of `checks`, asserting there is exactly one.
fn the_failure(checks: &[Check]) -> &Check {
    let failed: Vec<&Check> = checks.iter().filter(|c| c.verdict == Verdict::Fail).collect();
    assert_eq!(failed.len(), 1, "{checks:#?}");
    failed[0]
}

#[test]
fn a_healthy_wired_go2_passes_every_check() {
    let checks = checks(&healthy(), &go2());
    assert!(checks.iter().all(|c| c.verdict == Verdict::Pass), "{checks:#?}");
    assert_eq!(checks.len(), 9);
}

#[test]
fn a_missing_interface_lists_the_hosts() {
    let mut seen = healthy();
    seen.interfaces = Ok(vec![InterfaceInfo { name: "wlan0".into(), ..eth0() }]);
    let checks = checks(&seen, &go2());
    assert_eq!(checks.len(), 1);
    assert!(checks[0].saw.contains("no interface \"eth0\"; this host has wlan0 (192.168.123.99/24)"), "{}", checks[0]);
}

#[test]
fn down_no_carrier_no_address_and_a_small_mtu_each_say_their_fix() {
    let with = |change: fn(&mut InterfaceInfo)| {
        let mut i = eth0();
        change(&mut i);
        checks(&HostObservation { interfaces: Ok(vec![i]), ..healthy() }, &go2())
    };
    assert_eq!(the_failure(&with(|i| i.up = false)).fix.as_deref(), Some("sudo ip link set eth0 up"));
    assert!(the_failure(&with(|i| i.carrier = false)).saw.contains("without carrier"));
    let address = with(|i| i.ipv4 = vec![([10, 0, 0, 5].into(), 24)]);
    // The route back to the robot still goes out eth0 in `healthy`: only the address fails.
    assert_eq!(the_failure(&address).fix.as_deref(), Some("sudo ip addr add 192.168.123.99/24 dev eth0"));
    assert_eq!(the_failure(&with(|i| i.mtu = Some(1280))).fix.as_deref(), Some("sudo ip link set eth0 mtu 1500"));
    let unknown = with(|i| i.mtu = None);
    assert!(unknown.iter().any(|c| c.name == "MTU" && c.verdict == Verdict::Unknown));
}

#[test]
fn no_multicast_flag_or_route_fails() {
    let mut i = eth0();
    i.multicast = false;
    let checks_ = checks(&HostObservation { interfaces: Ok(vec![i]), ..healthy() }, &go2());
    assert_eq!(the_failure(&checks_).fix.as_deref(), Some("sudo ip link set eth0 multicast on"));

    let mut seen = healthy();
    seen.routes = Ok(vec![route("eth0", [192, 168, 123, 0], 24)]);
    let failure = the_failure(&checks(&seen, &go2())).clone();
    assert_eq!(failure.saw, "no route for 224.0.0.0/4 and no default route");
    assert_eq!(failure.fix.as_deref(), Some("sudo ip route add 224.0.0.0/4 dev eth0"));

    seen.routes = Ok(vec![route("eth0", [192, 168, 123, 0], 24), route("wlan0", [0, 0, 0, 0], 0)]);
    assert!(the_failure(&checks(&seen, &go2())).saw.contains("goes out wlan0"));
    seen.routes = Ok(vec![route("eth0", [192, 168, 123, 0], 24), route("eth0", [0, 0, 0, 0], 0)]);
    assert!(checks(&seen, &go2()).iter().all(|c| c.verdict == Verdict::Pass));
}

#[test]
fn wifi_on_the_robots_subnet_and_strict_rp_filter_fail() {
    let wlan0 = InterfaceInfo { name: "wlan0".into(), ipv4: vec![([192, 168, 123, 50].into(), 24)], ..eth0() };
    let mut seen = HostObservation { interfaces: Ok(vec![eth0(), wlan0]), ..healthy() };
    let failure = the_failure(&checks(&seen, &go2())).clone();
    assert_eq!(failure.name, "one interface per subnet");
    assert_eq!(
        failure.fix.as_deref(),
        Some("take the subnet off one of them: sudo ip addr del 192.168.123.50/24 dev wlan0")
    );

    // The subnet's route through wlan0 (its metric won): strict rp_filter drops eth0's datagrams.
    seen.routes = Ok(vec![route("wlan0", [192, 168, 123, 0], 24), route("eth0", [224, 0, 0, 0], 4)]);
    let failed: Vec<String> =
        checks(&seen, &go2()).into_iter().filter(|c| c.verdict == Verdict::Fail).map(|c| c.name).collect();
    assert_eq!(failed, ["one interface per subnet", "reverse-path filter"]);
    seen.rp_filter = Some(2);
    assert_eq!(the_failure(&checks(&seen, &go2())).name, "one interface per subnet");
}

#[test]
fn a_firewall_rule_is_named_and_an_unreadable_ruleset_is_unknown() {
    let mut seen = healthy();
    seen.firewall = Ok("table inet f {\n chain input {\n  type filter hook input priority 0; policy accept;\n  udp dport 7400-7700 drop\n }\n}\n".into());
    let failure = the_failure(&checks(&seen, &go2())).clone();
    assert_eq!(failure.saw, "UDP 7400–7700 dropped by table inet f, chain input: udp dport 7400-7700 drop");
    seen.firewall = Err("Operation not permitted".into());
    let firewall = checks(&seen, &go2()).into_iter().find(|c| c.name == "firewall").unwrap();
    assert_eq!(firewall.verdict, Verdict::Unknown);
    assert!(firewall.saw.contains("not readable (Operation not permitted)"));
}
