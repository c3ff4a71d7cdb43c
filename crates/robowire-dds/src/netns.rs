//! A network whose loopback carries multicast, for DDS on one machine (feature `netns`).
//!
//! DDS discovery uses multicast; a loopback interface without it (common on CI machines and
//! containers) discovers nothing. Where `lo` lacks it, one of two private networks is made, each
//! with `lo` up, multicast on and `224.0.0.0/4` routed to it (iproute2's `ip`); participants
//! there see each other and nothing else, and nothing leaves the machine:
//!
//! - as root, a thread of its own in a new network namespace ([`in_loopback_namespace`]);
//! - as anyone else, the program (or the one test) runs again under util-linux's
//!   `unshare --user --map-root-user --net`: a user namespace, which unprivileged users may
//!   create on current Linux distributions, owning a new network namespace. [`CHILD_ENV`] marks
//!   the run inside, which sets `lo` up before anything else.
//!
//! [`for_this_process`] does this for a whole program (the CLI's demo, an example, a bench) and
//! gives [`Loopback::Unavailable`] with the reason where neither is possible;
//! `with_loopback_multicast` (feature `test-support`) does it for a test, which is skipped with
//! one line where neither is possible (failed under `ROBOWIRE_INTEROP=1`, see
//! `robowire_fixtures::interop`).

pub mod userns;

use std::process::{Command, ExitStatus};

#[cfg(feature = "test-support")]
use robowire_fixtures::interop;

/// Set in the environment of a run inside its user + network namespace: the test's name, or
/// [`PROCESS`] for a whole program.
pub const CHILD_ENV: &str = "ROBOWIRE_NETNS_CHILD";
/// [`CHILD_ENV`]'s value for a whole program run again by [`for_this_process`].
pub const PROCESS: &str = "process";

/// Why a private network with multicast on loopback could not be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum NetnsError {
    /// `unshare(CLONE_NEWNET)` failed (not root?).
    #[error("cannot create a network namespace (needs root): {0}")]
    Unshare(#[source] std::io::Error),
    /// An `ip` command failed.
    #[error("`ip {args}` failed in the new namespace: {reason}")]
    Ip {
        /// The arguments.
        args: String,
        /// Exit status or spawn error, with stderr.
        reason: String,
    },
    /// `unshare --user --map-root-user --net` cannot make a namespace here.
    #[error("no user + network namespace here: {reason}")]
    UserNamespace {
        /// What failed, with `unshare`'s own words.
        reason: String,
    },
    /// The program could not be started again inside the namespace.
    #[error("cannot run {program} again in a user + network namespace: {source}")]
    Reexec {
        /// The program.
        program: String,
        /// Why.
        #[source]
        source: std::io::Error,
    },
}

fn ip(args: &[&str]) -> Result<String, NetnsError> {
    let fail = |reason: String| NetnsError::Ip { args: args.join(" "), reason };
    let out = Command::new("ip").args(args).output().map_err(|e| fail(format!("{e} (is iproute2 installed?)")))?;
    if out.status.success() {
        Ok(String::from_utf8_lossy(&out.stdout).into_owned())
    } else {
        Err(fail(format!("{}: {}", out.status, String::from_utf8_lossy(&out.stderr).trim())))
    }
}

/// Whether `lo` in the calling thread's namespace is up with multicast on.
pub fn loopback_has_multicast() -> bool {
    ip(&["-o", "link", "show", "lo"]).is_ok_and(|line| line.contains("MULTICAST") && line.contains("UP"))
}

/// `lo` up, multicast on, `224.0.0.0/4` routed to it, in the calling thread's network namespace
/// (which this process must administer: root, or root of the user namespace that owns it).
pub fn setup_loopback() -> Result<(), NetnsError> {
    ip(&["link", "set", "lo", "up"])?;
    ip(&["link", "set", "lo", "multicast", "on"])?;
    ip(&["route", "add", "224.0.0.0/4", "dev", "lo"])?;
    Ok(())
}

/// Moves the calling thread into a new network namespace with multicast on loopback; see the
/// [module](self). Needs root (`CAP_SYS_ADMIN` and `CAP_NET_ADMIN`), or the root of a user
/// namespace (as under `unshare --user --map-root-user`).
pub fn enter_loopback_namespace() -> Result<(), NetnsError> {
    nix::sched::unshare(nix::sched::CloneFlags::CLONE_NEWNET).map_err(|e| NetnsError::Unshare(e.into()))?;
    setup_loopback()
}

/// Runs `f` on a new thread inside a fresh loopback namespace (see
/// [`enter_loopback_namespace`]) and returns its result; the namespace ends with the threads and
/// processes in it.
pub fn in_loopback_namespace<T: Send>(f: impl FnOnce() -> T + Send) -> Result<T, NetnsError> {
    try_in_loopback_namespace(f).map_err(|(e, _)| e)
}

/// [`in_loopback_namespace`], giving `f` back when the namespace cannot be made.
fn try_in_loopback_namespace<T: Send, F: FnOnce() -> T + Send>(f: F) -> Result<T, (NetnsError, F)> {
    std::thread::scope(|scope| {
        scope
            .spawn(move || match enter_loopback_namespace() {
                Ok(()) => Ok(f()),
                Err(e) => Err((e, f)),
            })
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
    })
}

/// Whether this process runs as root.
pub fn is_root() -> bool {
    nix::unistd::geteuid().is_root()
}

/// Runs a test's `body` where `lo` carries multicast (feature `test-support`):
///
/// 1. here, when it already does;
/// 2. as root, on a thread in a new network namespace ([`in_loopback_namespace`]);
/// 3. otherwise, this test binary runs again for just this test (`--exact <test> --nocapture
///    --test-threads=1`) under `unshare --user --map-root-user --net` with [`CHILD_ENV`] set to
///    the test's name; there this function sets `lo` up and runs `body`. The test fails if it
///    fails there; its output is shown here (captured like the test's own);
/// 4. when none is possible: one line on stderr says why and the test returns (fails under
///    `ROBOWIRE_INTEROP=1`).
///
/// Call it from the test's own thread (the harness names it after the test). Everything before
/// the call runs again in case 3.
#[cfg(feature = "test-support")]
pub fn with_loopback_multicast(body: impl FnOnce() + Send) {
    use std::io::Write;

    let test = interop::current_test();
    if std::env::var_os(CHILD_ENV).is_some_and(|v| v == test.as_str()) {
        setup_loopback().unwrap_or_else(|e| panic!("{test}: lo in its user + network namespace: {e}"));
        let line = format!(
            "{test}: in a user + network namespace of its own (uid map {}), multicast on lo\n",
            userns::uid_map()
        );
        let _ = std::io::stderr().write_all(line.as_bytes());
        return body();
    }
    if loopback_has_multicast() {
        return body();
    }
    let mut root_failed = None;
    if is_root() {
        match try_in_loopback_namespace(body) {
            Ok(()) => return,
            Err((e, _)) => root_failed = Some(e),
        }
    }
    let command = std::env::current_exe()
        .map_err(|source| NetnsError::Reexec { program: "this test".into(), source })
        .and_then(|exe| userns::command(exe).map_err(|reason| NetnsError::UserNamespace { reason }));
    let mut command = match (command, root_failed) {
        (Ok(command), _) => command,
        (Err(e), None) => return interop::skip(format!("DDS needs multicast on lo, which it lacks, and {e}")),
        (Err(e), Some(root)) => return interop::skip(format!("DDS needs multicast on lo: {root}; {e}")),
    };
    command.args(["--exact", &test, "--nocapture", "--test-threads=1", "--include-ignored"]).env(CHILD_ENV, &test);
    let out = command.output().unwrap_or_else(|e| panic!("{test}: starting {command:?}: {e}"));
    let stdout = String::from_utf8_lossy(&out.stdout);
    print!("{stdout}");
    eprint!("{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        out.status.success(),
        "{test} failed in its user + network namespace ({}); its output is above",
        out.status
    );
    // The harness's summary, not "test NAME ... ok": a test that prints puts its lines in between.
    assert!(stdout.contains("test result: ok. 1 passed"), "{test} did not run in its user + network namespace");
}

/// [`with_loopback_multicast`] in a network namespace of the test's own only (feature
/// `test-support`), for a test that changes the network (interfaces, routes, firewall): where
/// `lo` already carries multicast, the body would run in this host's namespace, so the test is
/// skipped with a line instead (failed under `ROBOWIRE_INTEROP=1`).
#[cfg(feature = "test-support")]
pub fn with_private_network(body: impl FnOnce() + Send) {
    with_loopback_multicast(|| {
        let ns = |of: &str| std::fs::read_link(format!("/proc/{of}/ns/net")).ok();
        if ns("thread-self") == ns("self") && std::env::var_os(CHILD_ENV).is_none() {
            return interop::skip("lo carries multicast here: the test would change this host's network");
        }
        body();
    });
}

/// Whether DDS on loopback can run here by one of the ways of the [module](self) (for a test
/// that leaves it to a program it starts, like `robowire demo`); the reason when it cannot.
pub fn available() -> Result<(), NetnsError> {
    if loopback_has_multicast() || is_root() {
        return Ok(());
    }
    userns::command("true").map(drop).map_err(|reason| NetnsError::UserNamespace { reason })
}

/// Where a program's DDS on loopback runs; see [`for_this_process`].
#[derive(Debug)]
#[non_exhaustive]
pub enum Loopback {
    /// `lo` carries multicast in this process's namespace: run DDS here.
    Multicast,
    /// This process is the program run again in a user + network namespace of its own, `lo`
    /// set up: run DDS here.
    UserNamespace,
    /// Root, `lo` without multicast: run DDS on a thread in a new network namespace
    /// ([`in_loopback_namespace`]).
    Root,
    /// None of these is possible here.
    Unavailable(NetnsError),
}

impl Loopback {
    /// Runs `f` where `lo` carries multicast: here, or on a thread in a new namespace as root;
    /// the reason when it cannot.
    pub fn run<T: Send>(self, f: impl FnOnce() -> T + Send) -> Result<T, NetnsError> {
        match self {
            Self::Multicast | Self::UserNamespace => Ok(f()),
            Self::Root => in_loopback_namespace(f),
            Self::Unavailable(e) => Err(e),
        }
    }
}

/// Readies this program for DDS on loopback: see [`Loopback`]. When `lo` lacks multicast and
/// this process is not root, the program runs again, from the start with the same arguments,
/// under `unshare --user --map-root-user --net` (marked by [`CHILD_ENV`]), and **this process
/// exits** with its exit code; the run inside gets [`Loopback::UserNamespace`]. So call it at the
/// start of `main`, before the program has done anything it must not do twice.
pub fn for_this_process() -> Loopback {
    if std::env::var_os(CHILD_ENV).is_some_and(|v| v == PROCESS) {
        return match setup_loopback() {
            Ok(()) => Loopback::UserNamespace,
            Err(e) => Loopback::Unavailable(e),
        };
    }
    if loopback_has_multicast() {
        return Loopback::Multicast;
    }
    if is_root() {
        return Loopback::Root;
    }
    let program = match std::env::current_exe() {
        Ok(program) => program,
        Err(source) => return Loopback::Unavailable(NetnsError::Reexec { program: "this program".into(), source }),
    };
    let mut command = match userns::command(&program) {
        Ok(command) => command,
        Err(reason) => return Loopback::Unavailable(NetnsError::UserNamespace { reason }),
    };
    match command.args(std::env::args_os().skip(1)).env(CHILD_ENV, PROCESS).status() {
        Ok(status) => std::process::exit(exit_code(status)),
        Err(source) => Loopback::Unavailable(NetnsError::Reexec { program: program.display().to_string(), source }),
    }
}

/// A child's exit code, as a shell reports it (128 + the signal that ended it).
fn exit_code(status: ExitStatus) -> i32 {
    use std::os::unix::process::ExitStatusExt;
    status.code().or_else(|| status.signal().map(|s| 128 + s)).unwrap_or(1)
}
