//! `robowire sim go2` driven by Unitree's own software: the Go2 low-level stand example of
//! `unitree_sdk2_python`, unchanged, on CycloneDDS (see `robowire_fixtures::peers`); and
//! `robowire go2 …` against the same simulator. Each where loopback carries multicast
//! (`robowire_dds::netns`).

use std::io::{BufRead, BufReader};
use std::process::Stdio;

use robowire_dds::netns::with_loopback_multicast;

use crate::support::{Running, robowire, start_example, with_unitree_examples};

/// `robowire sim go2 --interface lo`, started and waited for.
fn start_sim() -> Running {
    let sim = Running::start(&["sim", "go2", "--interface", "lo", "--report-every-s", "0"]);
    assert!(sim.first_line.starts_with("go2 domain 0 lo"), "{}", sim.first_line);
    sim
}

#[test]
fn unitree_go2_stand_example_runs_unchanged_against_the_simulator() {
    with_unitree_examples(robowire_fixtures::peers::unitree_go2_examples, |python, examples| {
        let sim = start_sim();
        let example = start_example(python, examples, "go2_stand_example.py");
        let out = example.wait_with_output().unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        // The example ends with sys.exit(-1) after printing "Done!".
        assert!(stdout.contains("Done!"), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
        let log = sim.interrupt().stdout;
        assert!(log.contains("ReleaseMode: sport mode \"normal\" released"), "{log}");
        let last = log.lines().last().unwrap_or_default();
        let accepted: u64 = last.split_whitespace().nth(2).and_then(|n| n.parse().ok()).unwrap_or(0);
        assert!(accepted > 2000, "the example's 500 Hz LowCmds were accepted: {last}");
        assert!(last.contains("bad CRC 0 bad head 0"), "every LowCmd had Unitree's CRC: {last}");
        // Its last phase moves the legs to the wide pose: hips ±0.35 front, ±0.5 rear.
        let q: Vec<f32> = last
            .split('[')
            .nth(1)
            .and_then(|s| s.split(']').next())
            .map(|s| s.split(", ").filter_map(|v| v.parse().ok()).collect())
            .unwrap_or_default();
        let wide = [-0.35, 1.36, -2.65, 0.35, 1.36, -2.65, -0.5, 1.36, -2.65, 0.5, 1.36, -2.65];
        assert_eq!(q.len(), 12, "{last}");
        assert!(q.iter().zip(wide).all(|(q, w)| (q - w).abs() < 0.05), "final joints {q:?}");
    });
}

#[test]
fn robowire_go2_status_release_stand_and_the_dds_inspector() {
    with_loopback_multicast(|| {
        let sim = start_sim();
        let go2 = |args: &[&str]| robowire().args(["go2", "--interface", "lo"]).args(args).output().unwrap();
        let status = go2(&["status", "--json"]);
        assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
        let json: serde_json::Value = serde_json::from_slice(&status.stdout).unwrap();
        assert_eq!(json["motor_state"][2]["q"], -2.65, "lying: {json}");
        assert_eq!(json["head"], serde_json::json!([254, 239]));

        let stand = go2(&["stand", "--duration", "0.5", "--hold", "0.5"]);
        let text = String::from_utf8_lossy(&stand.stdout);
        assert!(stand.status.success(), "{text}{}", String::from_utf8_lossy(&stand.stderr));
        assert!(text.contains("sport mode released (1 ReleaseMode call)"), "{text}");
        assert!(text.contains("held the stand pose") && text.contains("damped; done"), "{text}");
        let release = go2(&["release"]);
        assert!(String::from_utf8_lossy(&release.stdout).contains("no sport mode owns the motors"));

        let topics = robowire().args(["dds", "--interface", "lo", "topics", "--wait", "1"]).output().unwrap();
        let topics = String::from_utf8_lossy(&topics.stdout);
        assert!(topics.contains("rt/lowstate") && topics.contains("unitree_go::msg::dds_::LowState_"), "{topics}");
        assert!(topics.contains("rt/api/motion_switcher/request"), "{topics}");
        let echo =
            robowire().args(["dds", "--interface", "lo", "echo", "rt/lowstate", "--count", "2"]).output().unwrap();
        let echo = String::from_utf8_lossy(&echo.stdout);
        assert_eq!(echo.lines().count(), 2, "{echo}");
        assert!(echo.lines().all(|l| serde_json::from_str::<serde_json::Value>(l).is_ok_and(|v| v["tick"].is_u64())));

        let log = sim.interrupt().stdout;
        assert!(log.contains("sport StandDown") && log.contains("ReleaseMode"), "{log}");
    });
}

#[test]
fn no_robot_on_the_network_is_a_clear_error() {
    with_loopback_multicast(|| {
        let out =
            robowire().args(["go2", "--interface", "lo", "--connect-timeout-s", "0.5", "status"]).output().unwrap();
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("no rt/lowstate within 0.5 s on domain 0 (interface lo)"), "{err}");
        let bad = robowire().args(["go2", "--interface", "no-such-if0", "status"]).output().unwrap();
        let err = String::from_utf8_lossy(&bad.stderr);
        assert!(err.contains("no network interface \"no-such-if0\""), "{err}");
    });
}

#[test]
fn status_and_watch_of_a_go2_by_address() {
    with_loopback_multicast(|| {
        let sim = start_sim();
        let out = robowire().args(["status", "go2:lo", "--json"]).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let state: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(state["head"], serde_json::json!([254, 239]), "a Go2 LowState with the IDL's names: {state}");
        assert_eq!(state["motor_state"].as_array().map(Vec::len), Some(20));
        let mut watch =
            robowire().args(["watch", "go2:lo"]).stdout(Stdio::piped()).stderr(Stdio::null()).spawn().unwrap();
        let mut lines = BufReader::new(watch.stdout.take().unwrap()).lines();
        let line = lines.find(|l| l.as_ref().is_ok_and(|l| l.starts_with("tick "))).expect("a state line").unwrap();
        assert!(line.contains("| age "), "{line}");
        rustix::process::kill_process(rustix::process::Pid::from_child(&watch), rustix::process::Signal::INT).unwrap();
        assert!(watch.wait().unwrap().success());
        drop(sim);
        // The simulator and its client in one process, by address.
        let out = robowire().args(["status", "sim:go2"]).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert!(String::from_utf8_lossy(&out.stdout).starts_with("tick "), "{}", String::from_utf8_lossy(&out.stdout));
    });
}
