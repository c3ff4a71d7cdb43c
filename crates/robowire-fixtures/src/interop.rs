//! The one gate of tests that need what a machine may lack: the vendors' software
//! (`../shared/peers`), a specific CPython, PyPI, a network namespace for DDS.
//!
//! A test asks for its prerequisite with [`require`]: when it is there the test runs; when it is
//! missing the test prints one line to stderr (past the test harness's capture) and returns:
//!
//! ```text
//! skipped go2_cyclone::the_test: no CPython 3.10 (…): install one with pyenv; ROBOWIRE_INTEROP=1 makes this a failure
//! ```
//!
//! With `ROBOWIRE_INTEROP=1` ([`VARIABLE`]) in the environment a missing prerequisite fails the
//! test with the same reason instead: CI sets it, so every interop test runs there or the run
//! fails. (serialport-rs gates its hardware tests the same way.)

use std::fmt::Display;
use std::io::Write;

/// The environment variable that asks for every interop test: `1` (anything but empty or `0`).
pub const VARIABLE: &str = "ROBOWIRE_INTEROP";

/// Whether every interop test is asked for (`ROBOWIRE_INTEROP=1`).
pub fn asked() -> bool {
    std::env::var_os(VARIABLE).is_some_and(|v| !v.is_empty() && v != "0")
}

/// The name of the running test: the test harness names each test's thread after it
/// (`module::test_name`); `"this test"` on another thread.
pub fn current_test() -> String {
    match std::thread::current().name() {
        Some(name) if name != "main" => name.to_owned(),
        _ => "this test".to_owned(),
    }
}

/// `what` cannot run because `missing` (what is missing and how to get it). Not asked for: prints
/// `skipped <what>: <missing>; ROBOWIRE_INTEROP=1 makes this a failure` to stderr and returns
/// `Ok`. Asked for: returns the failure's message.
pub fn missing(what: &str, missing: impl Display) -> Result<(), String> {
    let line = gate(asked(), what, missing)?;
    // Straight to the stream: the harness captures `eprintln!` of a passing test.
    let _ = std::io::stderr().write_all(line.as_bytes());
    Ok(())
}

/// The skip line, or (asked for) the failure's message.
fn gate(asked: bool, what: &str, missing: impl Display) -> Result<String, String> {
    if asked {
        Err(format!("{what}: {missing} ({VARIABLE}=1 asks for every interop test)"))
    } else {
        Ok(format!("skipped {what}: {missing}; {VARIABLE}=1 makes this a failure\n"))
    }
}

/// The calling test's prerequisite: `Some` when it is there; `None` after the skip line when it
/// is missing (the test returns); a panic with the reason under `ROBOWIRE_INTEROP=1`.
///
/// ```no_run
/// # fn test() {
/// let Some(python) = robowire_fixtures::interop::require(robowire_fixtures::peers::unitree_python()) else {
///     return;
/// };
/// # let _ = python; }
/// ```
pub fn require<T, E: Display>(prerequisite: Result<T, E>) -> Option<T> {
    match prerequisite {
        Ok(value) => Some(value),
        Err(reason) => {
            skip(reason);
            None
        }
    }
}

/// [`require`] for one part of the calling test (`"MCAP reader"`): `None` skips that part,
/// and the line names it (`skipped <test> (its MCAP reader): …`); the rest of the test runs.
pub fn require_part<T, E: Display>(part: &str, prerequisite: Result<T, E>) -> Option<T> {
    prerequisite.map_err(|reason| fail_if_asked(missing(&format!("{} (its {part})", current_test()), reason))).ok()
}

/// Skips the calling test because `reason` (one line on stderr), or panics with it under
/// `ROBOWIRE_INTEROP=1`.
pub fn skip(reason: impl Display) {
    fail_if_asked(missing(&current_test(), reason));
}

fn fail_if_asked(outcome: Result<(), String>) {
    if let Err(failure) = outcome {
        panic!("{failure}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_prerequisite_that_is_there_runs_the_test() {
        assert_eq!(require(Ok::<_, String>(7)), Some(7));
    }

    #[test]
    fn the_test_is_named_after_its_thread() {
        assert_eq!(current_test(), "interop::tests::the_test_is_named_after_its_thread");
        let other = std::thread::Builder::new().name("main".into()).spawn(current_test).unwrap();
        assert_eq!(other.join().unwrap(), "this test");
    }

    #[test]
    fn a_missing_prerequisite_skips_unless_asked_for_then_fails_with_the_reason() {
        assert_eq!(
            gate(false, "t", "no CPython 3.10"),
            Ok("skipped t: no CPython 3.10; ROBOWIRE_INTEROP=1 makes this a failure\n".into())
        );
        assert_eq!(
            gate(true, "t", "no CPython 3.10"),
            Err("t: no CPython 3.10 (ROBOWIRE_INTEROP=1 asks for every interop test)".into())
        );
    }
}
