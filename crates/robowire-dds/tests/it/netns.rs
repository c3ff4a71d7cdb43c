//! `with_loopback_multicast` itself: the body runs where `lo` carries multicast, and a body that
//! fails there fails the test (also when it ran in a re-executed test binary).

use std::process::Command;

use robowire_dds::netns::{available, loopback_has_multicast, with_loopback_multicast};

#[test]
fn the_body_runs_where_loopback_carries_multicast() {
    with_loopback_multicast(|| assert!(loopback_has_multicast(), "lo without multicast where the body runs"));
}

/// [`fails_on_purpose`]'s name in the test binary (`tests/it`), for `--exact`.
const FAILS_ON_PURPOSE: &str = "netns::fails_on_purpose";

#[test]
#[ignore = "fails on purpose: run by a_body_that_fails_in_its_namespace_fails_the_test"]
fn fails_on_purpose() {
    with_loopback_multicast(|| panic!("failing on purpose in the namespace"));
}

#[test]
fn a_body_that_fails_in_its_namespace_fails_the_test() {
    let Some(()) = robowire_fixtures::interop::require(available()) else { return };
    let out = Command::new(std::env::current_exe().unwrap())
        .args(["--exact", FAILS_ON_PURPOSE, "--include-ignored", "--test-threads=1"])
        .output()
        .unwrap();
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(!out.status.success(), "{stdout}{stderr}");
    assert!(stdout.contains(&format!("test {FAILS_ON_PURPOSE} ... FAILED")), "{stdout}{stderr}");
    assert!(stdout.contains("failing on purpose in the namespace"), "the body's panic is shown: {stdout}{stderr}");
}
