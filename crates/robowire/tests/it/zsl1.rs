//! `robowire sim zsl1` and `robowire zsl1 …` as separate processes on loopback, the way a user
//! scripts them; and `dog`, their old name, still accepted for one release.

use std::process::Output;

use crate::support::{Running, one_demo_at_a_time, robowire};

/// Starts `robowire sim zsl1` on free ports; returns it and its HighLevel port.
fn sim(extra: &[&str]) -> (Running, String) {
    let args = ["sim", "zsl1", "--high-level-port", "0", "--low-level-port", "0", "--report-every-s", "0"];
    let sim = Running::start(&[&args[..], extra].concat());
    let high = sim.first_line.split_whitespace().next().expect("the simulator prints its addresses first");
    let port = high.rsplit(':').next().unwrap().to_string();
    (sim, port)
}

fn zsl1(port: &str, args: &[&str]) -> Output {
    robowire()
        .args(["zsl1", "--dog-ip", "127.0.0.1", "--dog-port", port, "--local-ip", "127.0.0.1", "--local-port", "0"])
        .args(args)
        .output()
        .unwrap()
}

/// `robowire zsl1 status --json`, parsed.
fn status(port: &str) -> serde_json::Value {
    let out = zsl1(port, &["status", "--json"]);
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}: {}", text(&out)))
}

fn text(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[test]
fn stand_move_refuse_status_and_lie_down() {
    let (_sim, port) = sim(&[]);
    let stand = zsl1(&port, &["stand"]);
    assert!(stand.status.success(), "{}", String::from_utf8_lossy(&stand.stderr));
    assert!(text(&stand).contains("stand_up: 0x0000 queued"), "{}", text(&stand));
    assert!(text(&stand).contains("robot reports mode 1"), "{}", text(&stand));
    // Standing up takes the simulated robot 1.2 s: wait until the body is at its standing height.
    let start = std::time::Instant::now();
    while status(&port)["position_m"][2].as_f64().is_none_or(|z| z < 0.299) {
        assert!(start.elapsed() < std::time::Duration::from_secs(20), "the robot never stood up");
    }

    let walk = zsl1(&port, &["move", "0.5", "0", "-0.2", "--duration", "0.6"]);
    assert!(walk.status.success(), "{}{}", text(&walk), String::from_utf8_lossy(&walk.stderr));
    assert!(text(&walk).contains("robot reports mode 18"), "{}", text(&walk));

    let refused = zsl1(&port, &["move", "0.04", "0", "0"]);
    assert!(!refused.status.success(), "an out-of-range speed fails the command");
    assert!(text(&refused).contains("0x3013 refused"), "{}", text(&refused));
    let nan = zsl1(&port, &["attitude", "NaN", "0", "0", "0"]);
    assert!(!nan.status.success());
    assert!(text(&nan).contains("must be finite"), "{}", text(&nan));

    let json = status(&port);
    assert_eq!(json["mode"], 18);
    assert!(json["position_m"][0].as_f64().unwrap() > 0.1, "{json}");
    // A state without error says so (not "Queued", a call's return code).
    assert_eq!((json["error_word"].as_u64(), json["error_name"].as_str()), (Some(0), Some("none")), "{json}");

    let lie = zsl1(&port, &["lie"]);
    assert!(text(&lie).contains("robot reports mode 51"), "{}", text(&lie));
}

#[test]
fn a_zsl1_client_on_a_simulated_zsl1w_is_told_about_the_mismatch() {
    let (_sim, port) = sim(&["--model", "zsl-1w"]);
    let out = zsl1(&port, &["stand"]);
    let again = zsl1(&port, &["status", "--json"]);
    let json: serde_json::Value = serde_json::from_slice(&again.stdout).unwrap();
    assert_eq!(json["sdk_mismatch"], 1, "{}", text(&out));
    let right = zsl1(&port, &["--model", "zsl-1w", "status"]);
    assert!(right.status.success());
}

#[test]
fn no_robot_is_a_clear_error_not_a_hang() {
    let silent = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let port = silent.local_addr().unwrap().port().to_string();
    let out = zsl1(&port, &["--connect-timeout-s", "0.3", "status"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no state from 127.0.0.1 within 0.3 s"), "{err}");
}

#[test]
fn a_taken_local_port_names_the_address_and_lists_host_addresses() {
    let taken = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let local = taken.local_addr().unwrap().port().to_string();
    let out = robowire()
        .args(["zsl1", "--dog-ip", "127.0.0.1", "--local-ip", "127.0.0.1", "--local-port", &local, "status"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(&format!("cannot bind UDP 127.0.0.1:{local}")), "{err}");
    assert!(err.contains("this host's IPv4 addresses: ") && err.contains("127.0.0.1"), "{err}");
}

#[test]
fn demo_drives_the_simulated_zsl1_and_checks_what_it_saw() {
    let turn = one_demo_at_a_time();
    let out = robowire().args(["demo", "--only", "zsl1"]).output().unwrap();
    drop(turn);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("zsl1: walks a square and returns to the start"), "{stdout}");
    assert!(stdout.contains("demo passed"), "{stdout}");
}

/// `dog`, the old name of `robowire zsl1` and `robowire sim zsl1`, is still accepted for one
/// release: the same command, the same help.
#[test]
fn the_old_name_dog_is_an_alias_of_zsl1() {
    let help = |args: &[&str]| {
        let out = robowire().args(args).arg("--help").output().unwrap();
        assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8(out.stdout).unwrap()
    };
    let (old, new) = (help(&["dog"]), help(&["zsl1"]));
    assert!(new.contains("ZSL-1") && new.contains("Usage: robowire zsl1"), "{new}");
    assert_eq!(old, new, "`robowire dog` is `robowire zsl1`");
    assert_eq!(help(&["sim", "dog"]), help(&["sim", "zsl1"]), "`robowire sim dog` is `robowire sim zsl1`");
    // The alias drives the robot as the new name does.
    let (_sim, port) = sim(&[]);
    let out = robowire()
        .args(["dog", "--dog-ip", "127.0.0.1", "--dog-port", &port, "--local-ip", "127.0.0.1", "--local-port", "0"])
        .args(["status", "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // The one name in `robowire --help`.
    let top = help(&[]);
    assert!(top.contains("  zsl1 ") && !top.contains("  dog "), "{top}");
}

/// A capture recorded before the rename names the ZSL-1's links `dog/…`: `robowire plot` still
/// draws it, as the `zsl1` device, asked for under either name.
#[test]
fn a_capture_with_the_old_dog_links_plots_as_zsl1() {
    use robowire_record::{Direction, Recorder};
    use zsl_proto::udp::{HighLevelCommand, Model};
    let dir = std::env::temp_dir().join(format!("robowire-zsl1-old-capture-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let capture = dir.join("old.mcap");
    let recorder = Recorder::create(&capture, "robowire dog").unwrap();
    let link = recorder.link("dog/high_level", &zsl_proto::description::HIGH_LEVEL);
    let state = robowire_sim::zsl1::Zsl1Model::new(Model::Zsl1).high_level_state().encode();
    for _ in 0..20 {
        link.record(Direction::Sent, &HighLevelCommand::stand_up().encode(Model::Zsl1));
        link.record(Direction::Received, &state);
    }
    drop(link);
    recorder.finish().unwrap();
    for device in ["zsl1", "dog"] {
        let svg = dir.join(format!("{device}.svg"));
        let out =
            robowire().arg("plot").arg(&capture).arg("--out").arg(&svg).args(["--device", device]).output().unwrap();
        assert!(out.status.success(), "--device {device}: {}", String::from_utf8_lossy(&out.stderr));
        assert!(text(&out).contains("1 page (zsl1)"), "--device {device}: {}", text(&out));
        let drawn = std::fs::read_to_string(&svg).unwrap();
        assert!(drawn.contains("zsl1 (dog/high_level)"), "--device {device}: the page of the zsl1 device");
    }
    let _ = std::fs::remove_dir_all(dir);
}
