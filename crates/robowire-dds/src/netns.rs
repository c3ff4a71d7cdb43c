//! A private network namespace whose loopback carries multicast, for DDS on one machine.
//!
//! DDS discovery uses multicast; a loopback interface without it (common on CI machines and
//! containers) discovers nothing. [`enter_loopback_namespace`] moves the calling thread into a
//! new network namespace with `lo` up, multicast on and `224.0.0.0/4` routed to it. Threads and
//! processes started from that thread afterwards live there too: DDS participants created there
//! see each other and nothing else; nothing leaves the machine. Needs root (`CAP_SYS_ADMIN` and
//! `CAP_NET_ADMIN`) and iproute2's `ip`.

use std::process::Command;

/// Why the namespace could not be set up.
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

/// Moves the calling thread into a new network namespace with multicast on loopback; see the
/// [module](self).
pub fn enter_loopback_namespace() -> Result<(), NetnsError> {
    nix::sched::unshare(nix::sched::CloneFlags::CLONE_NEWNET).map_err(|e| NetnsError::Unshare(e.into()))?;
    ip(&["link", "set", "lo", "up"])?;
    ip(&["link", "set", "lo", "multicast", "on"])?;
    ip(&["route", "add", "224.0.0.0/4", "dev", "lo"])?;
    Ok(())
}

/// Runs `f` on a new thread inside a fresh loopback namespace (see
/// [`enter_loopback_namespace`]) and returns its result; the namespace ends with the threads and
/// processes in it.
pub fn in_loopback_namespace<T: Send>(f: impl FnOnce() -> T + Send) -> Result<T, NetnsError> {
    std::thread::scope(|scope| {
        scope
            .spawn(|| {
                enter_loopback_namespace()?;
                Ok(f())
            })
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
    })
}
