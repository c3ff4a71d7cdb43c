//! Every subcommand given what users get wrong — a bad address, a missing device, a busy port,
//! an unreadable capture, a wrong interface name — exits non-zero with one line that says what
//! to do, and never panics.

use std::net::UdpSocket;

use crate::support::robowire;

/// One case: the arguments, and words the error line must contain (what to do about it).
struct Case {
    args: Vec<String>,
    says: &'static [&'static str],
}

fn case(args: &[&str], says: &'static [&'static str]) -> Case {
    Case { args: args.iter().map(|a| (*a).to_owned()).collect(), says }
}

/// Runs `case`: a failure exit (1, or clap's 2 for a malformed argument), no panic, and the error
/// on one line that names the cause.
fn check(case: &Case) {
    let out = robowire().args(&case.args).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let args = case.args.join(" ");
    assert!(matches!(out.status.code(), Some(1 | 2)), "robowire {args}: exit {:?}\n{stderr}", out.status);
    assert!(!stderr.contains("panicked") && !stderr.contains("RUST_BACKTRACE"), "robowire {args} panicked:\n{stderr}");
    let error: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error")).collect();
    assert_eq!(error.len(), 1, "robowire {args}: one error line, got\n{stderr}");
    for word in case.says {
        assert!(error[0].contains(word), "robowire {args}: {word:?} missing from {:?}", error[0]);
    }
}

#[test]
fn every_subcommand_fails_with_one_line_that_says_what_to_do() {
    let dir = std::env::temp_dir().join(format!("robowire-bad-input-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let garbage = dir.join("garbage.mcap");
    std::fs::write(&garbage, b"not a capture at all").unwrap();
    let garbage = garbage.to_string_lossy().into_owned();
    let missing = dir.join("missing.mcap").to_string_lossy().into_owned();
    let busy = UdpSocket::bind("127.0.0.33:0").unwrap();
    let busy_port = busy.local_addr().unwrap().port().to_string();

    let cases = [
        // Bad addresses.
        case(&["status", "tank:1"], &["unknown kind", "kmc:/dev/ttyUSB0"]),
        case(&["watch", "zsl1:robot"], &["not an IP address"]),
        case(&["ros2", "--device", "sim:tank", "--duration", "1"], &["no such simulator"]),
        // Missing devices.
        case(&["status", "kmc:/dev/robowire-no-such-port"], &["cannot open serial port", "/dev/robowire-no-such-port"]),
        case(&["kmc", "--port", "/dev/robowire-no-such-port", "speed"], &["cannot open serial port"]),
        case(
            &["kmc", "--port", "/dev/robowire-no-such-port", "drive", "--velocity", "0.1"],
            &["cannot open serial port"],
        ),
        case(
            &[
                "zsl1",
                "--dog-ip",
                "127.0.0.34",
                "--local-ip",
                "127.0.0.34",
                "--local-port",
                "0",
                "--connect-timeout-s",
                "0.3",
                "status",
            ],
            &["no state from 127.0.0.34", "target_ip"],
        ),
        case(&["status", "zsl1:127.0.0.34", "--local", "127.0.0.34:0", "--connect-timeout-s", "0.3"], &["no state"]),
        case(&["shm", "status", "--name", "/robowire-no-such-object"], &["not running"]),
        case(&["ros2", "--device", "kmc:/dev/robowire-no-such-port", "--duration", "1"], &["cannot open serial port"]),
        // Busy ports.
        case(
            &["zsl1", "--dog-ip", "127.0.0.33", "--local-ip", "127.0.0.33", "--local-port", &busy_port, "status"],
            &["cannot bind", "127.0.0.33"],
        ),
        case(&["sim", "zsl1", "--bind", "127.0.0.33", "--high-level-port", &busy_port], &["cannot bind"]),
        // Unreadable captures.
        case(&["decode", "--mcap", &missing], &["missing.mcap"]),
        case(&["replay", &missing], &["missing.mcap"]),
        case(&["decode", "--mcap", &garbage], &["garbage.mcap"]),
        case(&["replay", "--fast", &garbage], &["garbage.mcap"]),
        case(&["replay", "--as-device", &garbage], &["garbage.mcap"]),
        // Wrong interface names.
        case(&["go2", "--interface", "robowire0", "status"], &["no network interface \"robowire0\"", "this host has"]),
        case(&["dds", "--interface", "robowire0", "topics"], &["no network interface \"robowire0\""]),
        case(&["sim", "go2", "--interface", "robowire0"], &["no network interface \"robowire0\""]),
        case(&["status", "go2:robowire0"], &["no network interface \"robowire0\""]),
        case(&["ros2", "--device", "go2:robowire0", "--duration", "1"], &["no network interface \"robowire0\""]),
        // Malformed arguments.
        case(&["demo", "--duration", "NaN"], &["--duration"]),
        case(&["kmc", "--port", "/dev/null", "drive", "--velocity", "inf"], &["velocity_mps must be finite"]),
        case(&["decode", "kmc", "a5 0"], &["odd number of hex digits"]),
    ];
    for case in &cases {
        check(case);
    }
    drop(busy);
    let _ = std::fs::remove_dir_all(dir);
}
