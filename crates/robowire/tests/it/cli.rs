//! The `robowire` binary as users script it.

use std::process::Output;

use crate::support::{Running, one_demo_at_a_time, robowire};

/// `robowire demo …`, one at a time ([`one_demo_at_a_time`]).
fn demo(args: &[&str]) -> Output {
    let _turn = one_demo_at_a_time();
    robowire().arg("demo").args(args).output().unwrap()
}

fn fixtures() -> Vec<serde_json::Value> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/kmc/frames.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn decode_json_prints_every_fixture_as_its_fields() {
    for fixture in fixtures() {
        let direction = if fixture["direction"] == "host->chassis" { "host" } else { "device" };
        let out = robowire()
            .args(["decode", "kmc", fixture["hex"].as_str().unwrap(), "--direction", direction, "--json"])
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let stdout = String::from_utf8(out.stdout).unwrap();
        let lines: Vec<&str> = stdout.lines().collect();
        assert_eq!(lines.len(), 1, "one object per frame: {stdout}");
        let printed: serde_json::Value = serde_json::from_str(lines[0]).unwrap();
        assert_eq!(printed, fixture["fields"], "{}", fixture["name"]);
        assert!(String::from_utf8_lossy(&out.stderr).contains("frames=1 skipped_bytes=0"));
    }
}

#[test]
fn decode_matches_the_documented_example_exactly() {
    let out = robowire().args(["decode", "kmc", "a5 00 00 00 3f cd cc cc 3e", "--json"]).output().unwrap();
    assert_eq!(
        String::from_utf8(out.stdout).unwrap(),
        "{\"frame\":\"pc_control\",\"velocity_mps\":0.5,\"curvature_per_m\":0.4}\n"
    );
}

#[test]
fn decode_reports_noise_and_fails_without_frames() {
    let out = robowire().args(["decode", "kmc", "--direction", "device", "00 b3 00 00 a0 3f af"]).output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("vehicle_speed speed_mps=1.25"), "{text}");
    assert!(text.contains("frames=1 skipped_bytes=1 rejected_candidates=0 pending_bytes=1"), "{text}");

    let none = robowire().args(["decode", "kmc", "00 01 02"]).output().unwrap();
    assert_eq!(none.status.code(), Some(1));
    let bad = robowire().args(["decode", "kmc", "a5 0"]).output().unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("odd number of hex digits"));
}

#[test]
fn demo_drives_the_simulated_chassis_and_checks_what_it_saw() {
    let out = demo(&["--only", "kmc", "--duration", "1.5"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("demo passed"), "{stdout}");
    for phase in ["straight", "turn", "reverse", "timeout", "stop"] {
        assert!(stdout.contains(phase), "{phase} missing from {stdout}");
    }
    // The summary table: a column for the chassis, its rates, timings, counters and faults.
    let table = stdout.split("\nsummary\n").nth(1).expect("a summary table");
    for row in ["result", "commanded", "observed", "rates", "p50/p99/max µs", "counters", "faults"] {
        assert!(table.lines().any(|l| l.trim_start().starts_with(row)), "row {row} missing from {table}");
    }
    assert!(table.contains("noise 64 B -> skipped 64 B"), "{table}");
    // Not a terminal: the progress line is printed once a second as a plain line.
    assert!(stdout.lines().any(|l| l.starts_with("  > kmc ") && l.contains(" Hz")), "{stdout}");
}

#[test]
fn demo_refuses_a_nonsense_duration() {
    let out = demo(&["--duration", "NaN"]);
    assert!(!out.status.success());
}

/// `--only` takes each device's name, and for one release the old names too (`dog` for `zsl1`,
/// `lowcmd` for `go2`); only the current names are listed.
#[test]
fn demo_only_takes_every_device_and_the_old_names() {
    for only in ["kmc", "zsl1", "dog", "spline", "go2", "lowcmd", "g1"] {
        // Parsed, then refused for the duration, before any scenario runs.
        let out = robowire().args(["demo", "--only", only, "--duration", "0"]).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && stderr.contains("--duration must be between"), "--only {only}: {stderr}");
    }
    let out = robowire().args(["demo", "--only", "cat"]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("[possible values: kmc, zsl1, spline, go2, g1]"), "{stderr}");
}

#[test]
fn sim_and_device_commands_as_two_processes() {
    let sim = Running::start(&["sim", "kmc", "--report-every-s", "0"]);
    let port = sim.first_line.clone();
    assert!(port.starts_with("/dev/pts/"), "{port}");

    let speed = robowire().args(["kmc", "--port", &port, "speed"]).output().unwrap();
    let battery = robowire().args(["kmc", "--port", &port, "battery", "--motor", "1"]).output().unwrap();
    let drive = robowire()
        .args([
            "kmc",
            "--port",
            &port,
            "drive",
            "--velocity",
            "0.4",
            "--yaw-rate",
            "-0.1",
            "--duration",
            "0.5",
            "--no-polls",
        ])
        .output()
        .unwrap();
    let refused = robowire().args(["kmc", "--port", &port, "drive", "--velocity", "inf"]).output().unwrap();
    drop(sim);

    assert!(speed.status.success(), "{}", String::from_utf8_lossy(&speed.stderr));
    assert!(String::from_utf8_lossy(&speed.stdout).starts_with("speed"));
    assert!(String::from_utf8_lossy(&battery.stdout).contains("battery    motor 1"));
    let drive_out = String::from_utf8_lossy(&drive.stdout);
    assert!(drive.status.success(), "{drive_out}{}", String::from_utf8_lossy(&drive.stderr));
    assert!(drive_out.contains("stopped."), "{drive_out}");
    assert!(drive_out.contains("stop burst 3"), "{drive_out}");
    assert!(!refused.status.success());
    assert!(String::from_utf8_lossy(&refused.stderr).contains("velocity_mps must be finite"));
}

#[test]
fn demo_go2_loop_and_json_output() {
    // The demo makes its own DDS network (as a normal user: a user + network namespace).
    let Some(()) = robowire_fixtures::interop::require(robowire_dds::netns::available()) else { return };
    let out = demo(&["--only", "go2", "--duration", "1", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout is only the JSON report");
    assert_eq!(report["passed"], true, "{report}");
    let checks = report["checks"].as_array().unwrap();
    let kind = |k: &str| checks.iter().filter(|c| c["kind"] == k).count();
    assert_eq!((kind("functional"), kind("timing")), (4, 2), "{report}");
    // Timing figures are reported with their kind and never decide the result.
    let lateness = checks.iter().find(|c| c["check"].as_str().unwrap().contains("send lateness p50")).unwrap();
    assert_eq!(lateness["kind"], "timing", "{report}");
    let device = &report["devices"][0];
    assert_eq!(device["device"], "lowcmd", "{report}");
    let rate_hz = device["rates_hz"]["LowCmd"].as_f64().unwrap();
    assert!(rate_hz > 0.0, "{report}");
    assert!(device["timings_us"]["send lateness"]["p99"].as_u64().is_some(), "{report}");
    let flips: u64 = device["faults"][0]["injected"].as_str().unwrap().split(' ').next().unwrap().parse().unwrap();
    let caught = device["counters"]["CRC errors"].as_u64().unwrap();
    assert!(caught > 0 && caught <= flips, "bit flips caught by the CRC: {report}");
    assert_eq!(device["faults"][0]["detected"], true, "{report}");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("caught by the CRC") && stderr.contains("\nsummary\n"), "the report goes to stderr");
}

#[test]
fn demo_g1_refuses_what_the_robot_ignores_and_the_robot_counts_it() {
    let Some(()) = robowire_fixtures::interop::require(robowire_dds::netns::available()) else { return };
    let out = demo(&["--only", "g1", "--duration", "1", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout is only the JSON report");
    assert_eq!(report["passed"], true, "{report}");
    let checks = report["checks"].as_array().unwrap();
    let kind = |k: &str| checks.iter().filter(|c| c["kind"] == k).count();
    assert_eq!((kind("functional"), kind("timing")), (7, 3), "{report}");
    let device = &report["devices"][0];
    assert_eq!(device["device"], "g1", "{report}");
    let counter = |name: &str| device["counters"][name].as_u64().unwrap();
    assert!(counter("bad mode_machine") >= 1 && counter("disabled motors") >= 1, "{report}");
    assert!(counter("LowCmd ignored") >= 1 && counter("arm_sdk frames") > 0, "{report}");
    assert_eq!(counter("CRC errors"), 0, "{report}");
}

#[test]
fn error_messages_say_each_cause_once_and_what_was_expected() {
    let missing = robowire().args(["kmc", "--port", "/dev/robowire-nonexistent", "speed"]).output().unwrap();
    let err = String::from_utf8_lossy(&missing.stderr);
    assert!(!missing.status.success());
    assert_eq!(err.matches("No such file or directory").count(), 1, "the cause once: {err}");
    assert!(err.contains("/dev/robowire-nonexistent"), "{err}");

    let short = robowire().args(["decode", "lowstate", "--cdr", "0001"]).output().unwrap();
    let err = String::from_utf8_lossy(&short.stderr);
    assert!(!short.status.success());
    assert!(err.contains("4-byte encapsulation header") && err.contains("2 bytes given"), "{err}");
    assert!(!err.contains("1180"), "not the struct image's length: {err}");
}

#[test]
#[cfg(not(feature = "mujoco"))]
fn physics_in_a_build_without_mujoco_says_how_to_get_it() {
    for robot in ["go2", "g1"] {
        let out = robowire().args(["sim", robot, "--physics", "--interface", "lo"]).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{stderr}");
        assert!(stderr.contains("built without physics") && stderr.contains("--features mujoco"), "{stderr}");
    }
}

#[test]
fn a_speed_out_of_range_and_a_model_without_physics_are_refused() {
    let out = robowire().args(["sim", "go2", "--speed", "0", "--interface", "lo"]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && stderr.contains("speed 0 is outside"), "{stderr}");
    let out = robowire().args(["sim", "go2", "--model", "go2.xml"]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && stderr.contains("--physics"), "{stderr}");
}
