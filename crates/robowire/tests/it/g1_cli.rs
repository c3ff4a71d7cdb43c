//! `robowire g1 …`, `robowire status g1:IFACE` and `robowire watch g1:IFACE` against
//! `robowire sim g1 --interface lo`, each where loopback carries multicast
//! (`robowire_dds::netns`): what the commands print, and what the simulator says it received.

use std::io::{BufRead, BufReader};
use std::process::{Output, Stdio};

use robowire_dds::netns::with_loopback_multicast;

use crate::support::{Running, robowire};

/// `robowire sim g1 --interface lo ARGS`, started and waited for.
fn start_sim(args: &[&str]) -> Running {
    let sim = Running::start(&[&["sim", "g1", "--interface", "lo", "--report-every-s", "0"], args].concat());
    assert!(sim.first_line.starts_with("g1 domain 0 lo"), "{}", sim.first_line);
    sim
}

/// `robowire g1 --interface lo ARGS`; it must succeed.
fn g1(args: &[&str]) -> Output {
    let out = robowire().args(["g1", "--interface", "lo"]).args(args).output().unwrap();
    assert!(out.status.success(), "g1 {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    out
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// What the simulator said on Ctrl-C: its log and the last line (the counters, `final q [..]`).
struct SimReport {
    log: String,
    last: String,
}

impl SimReport {
    fn of(sim: Running) -> Self {
        let log = sim.interrupt().stdout;
        let last = log.lines().last().unwrap_or_default().to_owned();
        Self { log, last }
    }

    /// The number after `label` on the last line.
    fn count(&self, label: &str) -> u64 {
        let rest = self.last.split(label).nth(1).unwrap_or_else(|| panic!("no {label:?} in {}", self.last));
        rest.split_whitespace().next().and_then(|n| n.trim_end_matches(';').parse().ok()).unwrap()
    }

    /// The final joint positions, rad, by slot.
    fn final_q(&self) -> Vec<f32> {
        let list = self.last.split("final q [").nth(1).and_then(|s| s.split(']').next()).unwrap_or_default();
        list.split(", ").map(|v| v.parse().unwrap()).collect()
    }
}

#[test]
fn status_damp_and_zero_of_a_simulated_g1() {
    with_loopback_multicast(|| {
        let sim = start_sim(&[]);
        let json: serde_json::Value = serde_json::from_slice(&g1(&["status", "--json"]).stdout).unwrap();
        assert_eq!(json["mode_machine"], 5, "{json}");
        assert_eq!(json["motor_state"].as_array().map(Vec::len), Some(35));
        assert!(json["motor_state"][3]["q"].as_f64().unwrap() > 0.1, "standing, a bent knee: {json}");

        let text = stdout(&g1(&["status"]));
        assert!(text.starts_with("tick ") && text.contains("mode_machine 5 (Dof29) mode_pr 0"), "{text}");
        assert!(text.contains("\n  left_knee_joint ") && text.contains("\n  right_wrist_yaw_joint "), "{text}");
        assert!(text.contains("\n  battery: soc 90 %"), "rt/lf/bmsstate: {text}");

        // Damping while the robot's controller owns the motors: sent, said, ignored by the robot.
        let damp = g1(&["damp"]);
        assert!(stdout(&damp).contains("damped for 0.5 s"));
        let warning = String::from_utf8_lossy(&damp.stderr);
        assert!(warning.contains("warning: mode \"ai\" owns the motors"), "{warning}");

        let zero = stdout(&g1(&["zero", "--duration", "0.5", "--hold", "0.5"]));
        assert!(zero.contains("mode \"ai\" released (1 ReleaseMode call)"), "{zero}");
        assert!(zero.contains("moving the 29 joints of a Dof29 G1 to 0 rad over 0.5 s"), "{zero}");
        assert!(zero.contains("held 0 rad 0.5 s") && zero.ends_with("damped; done\n"), "{zero}");
        // Released now: nothing owns the motors.
        assert!(stdout(&g1(&["release"])).contains("no mode owns the motors"));

        let report = SimReport::of(sim);
        assert!(report.log.contains("ReleaseMode: sport mode \"ai\" released"), "{}", report.log);
        assert!(report.count("ignored") > 0, "the damping sent while the controller owned the motors");
        assert!(report.count("lowcmd accepted") > 100, "{}", report.last);
        for label in ["bad CRC", "bad mode_machine", "disabled motors"] {
            assert_eq!(report.count(label), 0, "{label}: {}", report.last);
        }
        let q = report.final_q();
        assert_eq!(q.len(), 29, "{}", report.last);
        assert!(q.iter().all(|q| q.abs() < 0.05), "every joint at 0 rad: {q:?}");
    });
}

#[test]
fn zero_on_a_23_joint_g1_commands_its_23_joints() {
    with_loopback_multicast(|| {
        let sim = start_sim(&["--dof", "23"]);
        let capture = std::env::temp_dir().join(format!("robowire-g1-zero-{}.mcap", std::process::id()));
        let capture_arg = capture.to_str().unwrap();
        let zero = stdout(&g1(&["--record", capture_arg, "zero", "--duration", "0.3", "--hold", "0.3"]));
        assert!(zero.contains("moving the 23 joints of a Dof23 G1"), "{zero}");
        // Every link the G1 client has is recorded: its low level, its services, rt/arm_sdk.
        let summary = stdout(&robowire().args(["decode", "--mcap", capture_arg]).output().unwrap());
        for link in ["g1/low_level: unitree_hg.low_level", "g1/api: unitree_api.client", "g1/arm_sdk: unitree_hg"] {
            assert!(summary.contains(&format!("link:{link}")), "{link} in {summary}");
        }
        std::fs::remove_file(&capture).unwrap();
        let report = SimReport::of(sim);
        assert!(report.count("lowcmd accepted") > 100, "{}", report.last);
        assert_eq!(report.count("bad mode_machine"), 0, "mode_machine 4, the robot's: {}", report.last);
        assert_eq!(report.count("disabled motors"), 0, "{}", report.last);
        assert!(report.final_q().iter().all(|q| q.abs() < 0.05), "{}", report.last);
    });
}

#[test]
fn status_watch_and_recording_of_a_g1_by_address() {
    with_loopback_multicast(|| {
        let sim = start_sim(&[]);
        let capture = std::env::temp_dir().join(format!("robowire-g1-status-{}.mcap", std::process::id()));
        let capture_arg = capture.to_str().unwrap();
        let out = robowire().args(["status", "g1:lo", "--record", capture_arg]).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let text = stdout(&out);
        assert!(text.contains("mode_machine 5 (Dof29)") && text.contains("  left_hip_pitch_joint "), "{text}");
        let summary = robowire().args(["decode", "--mcap", capture_arg]).output().unwrap();
        let summary = stdout(&summary);
        assert!(summary.contains("link:g1/low_level: unitree_hg.low_level"), "{summary}");
        assert!(summary.contains("link:g1/api: unitree_api.client"), "{summary}");
        assert!(summary.contains("/g1/low_level/received"), "the LowStates taken: {summary}");
        std::fs::remove_file(&capture).unwrap();

        let mut watch =
            robowire().args(["watch", "g1:lo"]).stdout(Stdio::piped()).stderr(Stdio::null()).spawn().unwrap();
        let mut lines = BufReader::new(watch.stdout.take().unwrap()).lines();
        let line = lines.find(|l| l.as_ref().is_ok_and(|l| l.starts_with("tick "))).expect("a state line").unwrap();
        assert!(line.contains("mode_machine 5 (Dof29) mode_pr 0") && line.contains("| age "), "{line}");
        rustix::process::kill_process(rustix::process::Pid::from_child(&watch), rustix::process::Signal::INT).unwrap();
        assert!(watch.wait().unwrap().success());
        drop(sim);

        // The simulator and its client in one process, by address.
        let out = robowire().args(["status", "sim:g1", "--json"]).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(json["mode_machine"], 5, "{json}");
    });
}

#[test]
fn no_g1_on_the_network_is_a_clear_error() {
    with_loopback_multicast(|| {
        let out = robowire().args(["g1", "--interface", "lo", "--connect-timeout-s", "0.5", "zero"]).output().unwrap();
        assert_eq!(out.status.code(), Some(1));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("no rt/lowstate within 0.5 s on domain 0 (interface lo)"), "{err}");
        let out = robowire().args(["status", "g1:lo", "--connect-timeout-s", "0.5"]).output().unwrap();
        assert_eq!(out.status.code(), Some(1));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("no state from g1:lo within 0.5 s") && err.contains("192.168.123.x"), "{err}");
        let bad = robowire().args(["g1", "--interface", "no-such-if0", "status"]).output().unwrap();
        let err = String::from_utf8_lossy(&bad.stderr);
        assert!(err.contains("no network interface \"no-such-if0\""), "{err}");
        assert!(!err.contains("panicked"), "{err}");
    });
}
