//! `robowire sim dog` and `robowire dog …` as separate processes on loopback, the way a user
//! scripts them.

mod support;

use std::process::Output;

use support::{Running, robowire};

/// Starts `robowire sim dog` on free ports; returns it and its HighLevel port.
fn sim(extra: &[&str]) -> (Running, String) {
    let args = ["sim", "dog", "--high-level-port", "0", "--low-level-port", "0", "--report-every-s", "0"];
    let sim = Running::start(&[&args[..], extra].concat());
    let high = sim.first_line.split_whitespace().next().expect("the simulator prints its addresses first");
    let port = high.rsplit(':').next().unwrap().to_string();
    (sim, port)
}

fn dog(port: &str, args: &[&str]) -> Output {
    robowire()
        .args(["dog", "--dog-ip", "127.0.0.1", "--dog-port", port, "--local-ip", "127.0.0.1", "--local-port", "0"])
        .args(args)
        .output()
        .unwrap()
}

/// `robowire dog status --json`, parsed.
fn status(port: &str) -> serde_json::Value {
    let out = dog(port, &["status", "--json"]);
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}: {}", text(&out)))
}

fn text(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[test]
fn stand_move_refuse_status_and_lie_down() {
    let (_sim, port) = sim(&[]);
    let stand = dog(&port, &["stand"]);
    assert!(stand.status.success(), "{}", String::from_utf8_lossy(&stand.stderr));
    assert!(text(&stand).contains("stand_up: 0x0000 queued"), "{}", text(&stand));
    assert!(text(&stand).contains("robot reports mode 1"), "{}", text(&stand));
    // Standing up takes the simulated dog 1.2 s: wait until the body is at its standing height.
    let start = std::time::Instant::now();
    while status(&port)["position_m"][2].as_f64().is_none_or(|z| z < 0.299) {
        assert!(start.elapsed() < std::time::Duration::from_secs(20), "the dog never stood up");
    }

    let walk = dog(&port, &["move", "0.5", "0", "-0.2", "--duration", "0.6"]);
    assert!(walk.status.success(), "{}{}", text(&walk), String::from_utf8_lossy(&walk.stderr));
    assert!(text(&walk).contains("robot reports mode 18"), "{}", text(&walk));

    let refused = dog(&port, &["move", "0.04", "0", "0"]);
    assert!(!refused.status.success(), "an out-of-range speed fails the command");
    assert!(text(&refused).contains("0x3013 refused"), "{}", text(&refused));
    let nan = dog(&port, &["attitude", "NaN", "0", "0", "0"]);
    assert!(!nan.status.success());
    assert!(text(&nan).contains("must be finite"), "{}", text(&nan));

    let json = status(&port);
    assert_eq!(json["mode"], 18);
    assert!(json["position_m"][0].as_f64().unwrap() > 0.1, "{json}");
    // A state without error says so (not "Queued", a call's return code).
    assert_eq!((json["error_word"].as_u64(), json["error_name"].as_str()), (Some(0), Some("none")), "{json}");

    let lie = dog(&port, &["lie"]);
    assert!(text(&lie).contains("robot reports mode 51"), "{}", text(&lie));
}

#[test]
fn a_zsl1_client_on_a_zsl1w_dog_is_told_about_the_mismatch() {
    let (_sim, port) = sim(&["--model", "zsl-1w"]);
    let out = dog(&port, &["stand"]);
    let again = dog(&port, &["status", "--json"]);
    let json: serde_json::Value = serde_json::from_slice(&again.stdout).unwrap();
    assert_eq!(json["sdk_mismatch"], 1, "{}", text(&out));
    let right = dog(&port, &["--model", "zsl-1w", "status"]);
    assert!(right.status.success());
}

#[test]
fn no_robot_is_a_clear_error_not_a_hang() {
    let silent = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let port = silent.local_addr().unwrap().port().to_string();
    let out = dog(&port, &["--connect-timeout-s", "0.3", "status"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no state from 127.0.0.1 within 0.3 s"), "{err}");
}

#[test]
fn a_taken_local_port_names_the_address_and_lists_host_addresses() {
    let taken = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let local = taken.local_addr().unwrap().port().to_string();
    let out = robowire()
        .args(["dog", "--dog-ip", "127.0.0.1", "--local-ip", "127.0.0.1", "--local-port", &local, "status"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(&format!("cannot bind UDP 127.0.0.1:{local}")), "{err}");
    assert!(err.contains("this host's IPv4 addresses: ") && err.contains("127.0.0.1"), "{err}");
}

#[test]
fn demo_drives_the_simulated_dog_and_checks_what_it_saw() {
    let out = robowire().args(["demo", "--only", "dog"]).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("dog: walks a square and returns to the start"), "{stdout}");
    assert!(stdout.contains("demo passed"), "{stdout}");
}
