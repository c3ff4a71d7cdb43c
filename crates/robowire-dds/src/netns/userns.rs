//! A program as the root of a new user namespace that owns a new network namespace, through
//! util-linux's `unshare --user --map-root-user --net`: how a normal user gets a private network
//! (DDS tests, the Python suite) on current Linux distributions, which let unprivileged users
//! create user namespaces. The network namespace's `lo` is down until the program sets it up
//! (`ip`, as its root).

use std::ffi::OsStr;
use std::process::Command;
use std::sync::OnceLock;

const UNSHARE: [&str; 4] = ["--user", "--map-root-user", "--net", "--"];

/// `unshare --user --map-root-user --net -- program`. Checked once per process by making one
/// and setting its `lo` up; the error says why there is none (no `unshare` or `ip`, user
/// namespaces disabled for this user).
pub fn command(program: impl AsRef<OsStr>) -> Result<Command, String> {
    static PROBE: OnceLock<Result<(), String>> = OnceLock::new();
    PROBE.get_or_init(probe).clone()?;
    let mut command = Command::new("unshare");
    command.args(UNSHARE).arg(program);
    Ok(command)
}

fn probe() -> Result<(), String> {
    let shown = format!("`unshare {} ip link set lo up`", UNSHARE.join(" "));
    match Command::new("unshare").args(UNSHARE).args(["ip", "link", "set", "lo", "up"]).output() {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Err("util-linux's `unshare` is not installed".into()),
        Err(e) => Err(format!("{shown}: {e}")),
        Ok(out) if out.status.success() => Ok(()),
        Ok(out) => Err(format!(
            "{shown} failed ({}): {} (user namespaces disabled for this user? iproute2 missing?)",
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        )),
    }
}

/// This process's uid map on one line (`0 1000 1`: root inside for uid 1000 outside), the
/// evidence that it runs in a user namespace.
pub fn uid_map() -> String {
    let map = std::fs::read_to_string("/proc/self/uid_map").unwrap_or_default();
    map.split_whitespace().collect::<Vec<_>>().join(" ")
}
