//! `robowire doctor`: one broken setup per test, each asserting its ✗ line and its fix, and the
//! healthy setups exiting 0 (`sim:go2`, `sim:g1`, `sim:zsl1`, `sim:kmc`, a Go2 on a cable).
//!
//! The robot is `robowire sim go2` on `v1`, in a network namespace of its own, cabled by a veth
//! pair to `v0` (192.168.123.99/24) in the test's: every setup but the missing interface runs in a
//! private network namespace (`robowire_dds::netns::with_private_network`; as a normal user, a
//! user and network namespace, so no check here needs root; skipped with a line where none can
//! be made).
//! The doctor's DDS setups that need a simulator's fault or a second writer in-process are
//! `robowire-doctor`'s own tests.

use std::io::{BufRead, BufReader, Write};
use std::process::{Child, ChildStdin, Command, Output, Stdio};
use std::time::Duration;

use super::support::{Running, robowire};

/// How long the doctor listens (discovery on a veth takes milliseconds: a newcomer is answered at
/// once).
const TIMEOUT: &str = "2";

fn ip(args: &[&str]) {
    let out = Command::new("ip").args(args).output().unwrap();
    assert!(out.status.success(), "ip {}: {}", args.join(" "), String::from_utf8_lossy(&out.stderr));
}

/// The simulated Go2 on the far end of a cable: its process and the stdin that keeps it waiting.
struct Robot {
    sim: Child,
    _stdin: ChildStdin,
}

impl Drop for Robot {
    fn drop(&mut self) {
        let _ = self.sim.kill();
        let _ = self.sim.wait();
    }
}

/// `v0` here (192.168.123.99/24, up, multicast routed to it) cabled to `v1` (192.168.123.161/24)
/// in a network namespace of its own, where `robowire sim go2 --interface v1 <sim_args>` runs;
/// returns once the simulator said it runs.
fn cabled_robot(sim_args: &[&str]) -> Robot {
    ip(&["link", "add", "v0", "type", "veth", "peer", "name", "v1"]);
    ip(&["addr", "add", "192.168.123.99/24", "dev", "v0"]);
    ip(&["link", "set", "v0", "up"]);
    ip(&["route", "replace", "224.0.0.0/4", "dev", "v0"]);
    let script = "echo ready; read go; ip link set lo up; ip addr add 192.168.123.161/24 dev v1; \
                  ip link set v1 up; ip route add 224.0.0.0/4 dev v1; \
                  exec \"$0\" sim go2 --interface v1 --report-every-s 0 \"$@\"";
    let mut sim = Command::new("unshare")
        .args(["--net", "sh", "-c", script, env!("CARGO_BIN_EXE_robowire")])
        .args(sim_args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut stdin = sim.stdin.take().unwrap();
    let mut stdout = BufReader::new(sim.stdout.take().unwrap());
    let mut line = String::new();
    stdout.read_line(&mut line).unwrap();
    assert_eq!(line.trim(), "ready", "the robot's namespace");
    ip(&["link", "set", "v1", "netns", &sim.id().to_string()]);
    stdin.write_all(b"go\n").unwrap();
    line.clear();
    stdout.read_line(&mut line).unwrap();
    assert!(line.starts_with("go2 domain "), "the simulator did not start: {line:?}");
    // A link that came up carries nothing until the kernel has activated it (its link watch, up
    // to a second later), which shows as operstate UP: discovery sent before would be lost.
    robowire_fixtures::wait::until(Duration::from_secs(60), "v0 operational", || {
        let out = Command::new("ip").args(["-o", "link", "show", "v0"]).output().unwrap();
        String::from_utf8_lossy(&out.stdout).contains("state UP")
    });
    Robot { sim, _stdin: stdin }
}

fn doctor(args: &[&str]) -> (Output, String) {
    let out = robowire().arg("doctor").args(args).args(["--timeout", TIMEOUT]).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    (out, text)
}

/// The doctor on `v0` failed with `line` and, under it, `fix`.
fn assert_fails_with(args: &[&str], line: &str, fix: &str) {
    let (out, text) = doctor(args);
    assert!(!out.status.success(), "{text}");
    assert!(text.contains(&format!("{line}\n  fix: {fix}\n")), "no {line:?} with its fix in:\n{text}");
}

#[test]
fn an_interface_that_does_not_exist_is_named_with_the_hosts_interfaces() {
    let (out, text) = doctor(&["go2:robowire-none"]);
    assert_eq!(out.status.code(), Some(1), "{text}");
    assert!(text.contains("✗ interface: no interface \"robowire-none\"; this host has lo (127.0.0.1/8)"), "{text}");
    assert!(text.contains("\n  fix: name the interface cabled to the robot"), "{text}");
    assert_eq!(text.lines().filter(|l| l.starts_with(['✓', '✗', '?'])).count(), 1, "no check after it: {text}");
}

#[test]
fn a_go2_on_a_cable_passes_every_check() {
    robowire_dds::netns::with_private_network(|| {
        let _robot = cabled_robot(&[]);
        let (out, text) = doctor(&["go2:v0"]);
        assert!(out.status.success(), "{text}");
        assert!(!text.contains('✗'), "{text}");
        assert!(text.contains("✓ address: 192.168.123.99/24 on the robot's subnet 192.168.123.0/24"), "{text}");
        assert!(text.contains("✓ DDS participants: 1 on domain 0: robowire "), "{text}");
        assert!(text.contains("✓ LowState CRC: 100.0% of "), "{text}");
    });
}

#[test]
fn simulated_go2_and_g1_pass_and_json_says_so() {
    robowire_dds::netns::with_private_network(|| {
        let (out, text) = doctor(&["sim:go2"]);
        assert!(out.status.success(), "{text}");
        assert!(text.starts_with("robowire doctor go2:lo\n"), "{text}");
        let (out, json) = doctor(&["sim:g1", "--json"]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{json}{stderr}");
        let report: serde_json::Value = serde_json::from_str(&json).expect("stdout is only the JSON report");
        assert_eq!(report["target"], "g1:lo");
        let checks = report["checks"].as_array().unwrap();
        assert!(checks.iter().any(|c| c["name"] == "LowState CRC" && c["verdict"] == "pass"), "{report}");
        assert!(checks.iter().all(|c| c["verdict"] != "fail"), "{report}");
        assert!(stderr.contains("✓ rt/lowstate: "), "the checklist goes to stderr: {stderr}");
    });
}

#[test]
fn no_multicast_on_the_interface() {
    robowire_dds::netns::with_private_network(|| {
        let _robot = cabled_robot(&[]);
        ip(&["link", "set", "v0", "multicast", "off"]);
        assert_fails_with(
            &["go2:v0"],
            "✗ multicast: v0 lacks the MULTICAST flag: DDS discovery (SPDP) is multicast and finds nobody",
            "sudo ip link set v0 multicast on",
        );
    });
}

#[test]
fn no_route_for_multicast() {
    robowire_dds::netns::with_private_network(|| {
        let _robot = cabled_robot(&[]);
        ip(&["route", "del", "224.0.0.0/4", "dev", "v0"]);
        assert_fails_with(
            &["go2:v0"],
            "✗ multicast route: no route for 224.0.0.0/4 and no default route",
            "sudo ip route add 224.0.0.0/4 dev v0",
        );
    });
}

#[test]
fn the_simulator_on_domain_1_and_the_doctor_on_0() {
    robowire_dds::netns::with_private_network(|| {
        let _robot = cabled_robot(&["--domain", "1"]);
        assert_fails_with(
            &["go2:v0"],
            "✗ DDS participants: nobody on domain 0; participants on domain 1 (1)",
            "use domain 1 (robowire --domain 1; Unitree's SDK: ChannelFactoryInitialize(1, …))",
        );
    });
}

#[test]
fn two_interfaces_on_one_subnet() {
    robowire_dds::netns::with_private_network(|| {
        let _robot = cabled_robot(&[]);
        ip(&["link", "add", "v2", "type", "veth", "peer", "name", "v3"]);
        ip(&["addr", "add", "192.168.123.50/24", "dev", "v2"]);
        assert_fails_with(
            &["go2:v0"],
            "✗ one interface per subnet: v2 192.168.123.50/24 is on v0's subnet too (192.168.123.99/24): replies may leave by either",
            "take the subnet off one of them: sudo ip addr del 192.168.123.50/24 dev v2",
        );
    });
}

#[test]
fn an_nftables_rule_dropping_the_dds_ports() {
    robowire_dds::netns::with_private_network(|| {
        let _robot = cabled_robot(&[]);
        let script = "add table inet doctor_test\n\
                      add chain inet doctor_test input { type filter hook input priority 0; policy accept; }\n\
                      add rule inet doctor_test input udp dport 7400-7700 drop\n";
        let nft = Command::new("nft").args(["-f", "-"]).stdin(Stdio::piped()).stderr(Stdio::piped()).spawn();
        let Ok(mut nft) = nft else {
            return robowire_fixtures::interop::skip("no nftables' nft: install Debian's nftables");
        };
        nft.stdin.take().unwrap().write_all(script.as_bytes()).unwrap();
        let out = nft.wait_with_output().unwrap();
        if !out.status.success() {
            let why = String::from_utf8_lossy(&out.stderr);
            return robowire_fixtures::interop::skip(format!("nft cannot filter in this private network: {why}"));
        }
        assert_fails_with(
            &["go2:v0"],
            "✗ firewall: UDP 7400–7700 dropped by table inet doctor_test, chain input: udp dport 7400-7700 drop",
            "remove that rule, or accept UDP 7400–7700 before it (sudo nft list ruleset -a shows its handle)",
        );
    });
}

#[test]
fn the_zsl1_simulator_sending_state_to_another_port() {
    // Its own network: the ports 43997 and 43988 are the vendor's, fixed.
    robowire_dds::netns::with_private_network(|| {
        let _sim = Running::start(&["sim", "zsl1", "--client", "127.0.0.1:50000", "--report-every-s", "0"]);
        assert_fails_with(
            &["zsl1:127.0.0.1"],
            "✗ ZSL-1 state: no state datagram from 127.0.0.1 on port 43988 in 2.0 s, nor after one idle HighLevel command to 127.0.0.1:43997",
            "in the robot's sdk_config.yaml set target_ip: 127.0.0.1 and target_port: 43988, then restart its SDK",
        );
    });
}

#[test]
fn simulated_zsl1_and_kmc_pass() {
    robowire_dds::netns::with_private_network(|| {
        let (out, text) = doctor(&["sim:zsl1"]);
        assert!(out.status.success(), "{text}");
        assert!(text.contains("✓ ZSL-1 state: "), "{text}");
    });
    let (out, text) = doctor(&["sim:kmc"]);
    assert!(out.status.success(), "{text}");
    assert!(text.contains("✓ KMC frames: ") && text.contains("✓ battery: 25.2 V"), "{text}");
}

#[test]
fn a_kmc_port_that_is_missing_or_not_ours() {
    assert_fails_with(
        &["kmc:/dev/robowire-none"],
        "✗ serial port: /dev/robowire-none does not exist",
        "plug in the chassis' USB-serial adapter and name its port (ls /dev/ttyUSB* /dev/ttyACM* /dev/serial/by-id/)",
    );
    // Root opens any file: the permission check needs a normal user.
    if rustix::process::geteuid().is_root() {
        // Not a missing prerequisite, so not failed under ROBOWIRE_INTEROP=1.
        eprintln!("skipped the permission case of a_kmc_port_that_is_missing_or_not_ours: as root every port opens");
        return;
    }
    let dir = std::env::temp_dir().join(format!("robowire-doctor-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let port = dir.join("ttyKMC");
    std::fs::write(&port, b"").unwrap();
    std::fs::set_permissions(&port, std::os::unix::fs::PermissionsExt::from_mode(0o000)).unwrap();
    let (out, text) = doctor(&[&format!("kmc:{}", port.display())]);
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(!out.status.success(), "{text}");
    assert!(text.contains(": permission denied (group "), "{text}");
    assert!(text.contains("\n  fix: sudo usermod -aG "), "{text}");
}

#[test]
fn an_interface_without_an_address_names_the_zsl1_it_overhears() {
    robowire_dds::netns::with_private_network(|| {
        let _sim = Running::start(&["sim", "zsl1", "--client", "127.0.0.1:43988", "--report-every-s", "0"]);
        let (out, text) = doctor(&["--interface", "lo"]);
        // Nobody speaks DDS here: that check fails.
        assert!(!out.status.success(), "{text}");
        assert!(text.contains("✗ DDS participants: nobody heard on domain 0"), "{text}");
        assert!(text.contains("✓ ZSL-1: state on port 43988 from 127.0.0.1:43997 ("), "{text}");
        assert!(text.contains("): robowire doctor zsl1:127.0.0.1\n"), "{text}");
    });
}

#[test]
fn a_second_lowcmd_writer_is_named() {
    robowire_dds::netns::with_private_network(|| {
        let _sim = Running::start(&["sim", "go2", "--interface", "lo", "--report-every-s", "0"]);
        // A client of the robot publishes rt/lowcmd from its start: `watch` prints once it has
        // a state.
        let _client = Running::start(&["go2", "--interface", "lo", "watch"]);
        let (out, text) = doctor(&["go2:lo"]);
        assert!(!out.status.success(), "{text}");
        assert!(text.contains("✗ rt/lowcmd writers: already published by 1: "), "{text}");
        assert!(
            text.contains(
                " (robowire)\n  fix: stop that controller before starting yours: two writers of rt/lowcmd fight over the motors\n"
            ),
            "{text}"
        );
    });
}
