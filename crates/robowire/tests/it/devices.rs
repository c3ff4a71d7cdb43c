//! `robowire status ADDRESS` and `robowire watch ADDRESS` for every kind of address, against
//! the simulators: a chassis on a pseudo-terminal, a ZSL-1 on loopback UDP, and the `sim:`
//! addresses; physics asked of a device without a simulated body. (The Go2 on DDS is in
//! `tests/go2.rs`, in a private network.)

use std::process::Stdio;

use robowire_sim::kmc::{ChassisSim, ChassisSimConfig};
use serde_json::Value;

use crate::support::{Running, robowire};

/// `robowire status ARGS --json`: its JSON.
fn status_json(args: &[&str]) -> Value {
    let out = robowire().arg("status").args(args).arg("--json").output().unwrap();
    assert!(out.status.success(), "status {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stdout)))
}

/// `robowire watch ARGS` until it printed `lines` state lines, then Ctrl-C: the lines.
fn watch(args: &[&str], lines: usize) -> Vec<String> {
    let mut watch = Running::spawn(robowire().arg("watch").args(args).stderr(Stdio::null()));
    let mut line = watch.first_line.clone();
    let mut seen = Vec::new();
    loop {
        if !line.starts_with("connection:") {
            seen.push(line);
        }
        if seen.len() == lines {
            break;
        }
        line = watch.next_line().unwrap_or_else(|| panic!("watch {args:?} ended after {seen:?}"));
    }
    watch.interrupt();
    seen
}

#[test]
fn a_chassis_on_a_serial_port() {
    let chassis = ChassisSim::spawn(ChassisSimConfig::default()).unwrap();
    let address = format!("kmc:{}", chassis.path().display());
    let status = status_json(&[&address]);
    assert_eq!(status["port"], chassis.path().display().to_string());
    assert_eq!(status["link"], "Connected");
    assert_eq!(status["speed_mps"], 0.0, "a chassis at rest: {status}");
    assert_eq!(status["odometry"]["x_m"], 0.0, "{status}");
    let lines = watch(&[&address], 3);
    assert!(lines.iter().all(|l| l.starts_with("speed ")), "{lines:?}");
}

#[test]
fn a_zsl1_on_loopback_udp() {
    let _sim = Running::start(&["sim", "zsl1", "--bind", "127.0.0.31", "--report-every-s", "0"]);
    let status = status_json(&["zsl1:127.0.0.31", "--local", "127.0.0.31:0"]);
    assert_eq!(status["datagram"], "high_level_state", "{status}");
    assert!(status["mode"].is_u64() && status["battery_percent"].is_u64(), "{status}");
    let lines = watch(&["zsl1:127.0.0.31", "--local", "127.0.0.31:0"], 3);
    assert!(lines.iter().all(|l| l.starts_with("mode ")), "{lines:?}");
}

#[test]
fn simulated_devices_by_address() {
    let chassis = status_json(&["sim:kmc"]);
    assert_eq!(chassis["link"], "Connected", "{chassis}");
    let dog = status_json(&["sim:zsl1w"]);
    assert_eq!(dog["datagram"], "high_level_state", "{dog}");
    let lines = watch(&["sim:zsl1"], 2);
    assert!(lines.iter().all(|l| l.contains("age")), "{lines:?}");
}

#[test]
fn a_silent_device_and_a_bad_address_are_one_clear_line_each() {
    let out = robowire()
        .args(["status", "zsl1:127.0.0.32", "--local", "127.0.0.32:0", "--connect-timeout-s", "0.3"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no state from zsl1:127.0.0.32") && err.contains("target_ip"), "{err}");
    let out = robowire().args(["status", "tank:1"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "a usage error");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("unknown kind") && err.contains("kmc:/dev/ttyUSB0"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let out = robowire().args(["status", "kmc:/dev/robowire-no-such-port"]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("kmc:/dev/robowire-no-such-port") && err.contains("cannot open serial port"), "{err}");
}

#[test]
fn physics_is_for_sim_go2_and_sim_g1_and_asks_for_the_mujoco_build() {
    let refused = |args: &[&str], code: i32| {
        let out = robowire().args(args).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        assert_eq!(out.status.code(), Some(code), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        err
    };
    let no_body = ["status", "sim:kmc", "--physics"];
    let no_body_either = ["ros2", "--device", "sim:zsl1", "--physics", "--duration", "0"];
    for args in [&no_body[..], &["watch", "sim:zsl1", "--physics"], &no_body_either] {
        let err = refused(args, 1);
        assert!(err.contains("has no physics: MuJoCo simulates the bodies of sim:go2 and sim:g1 only"), "{err}");
    }
    for args in [&["status", "sim:go2", "--model", "scene.xml"][..], &["watch", "sim:g1", "--free-base"]] {
        assert!(refused(args, 2).contains("--physics"), "a usage error: {args:?}");
    }
    #[cfg(not(feature = "mujoco"))]
    {
        let err = refused(&["status", "sim:go2", "--physics"], 1);
        assert!(err.contains("without physics") && err.contains("--features mujoco"), "{err}");
    }
}
