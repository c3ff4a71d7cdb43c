//! What the CLI's integration tests share: the binary under test, a `robowire` process (a
//! simulator, a replay) that ends with its test, one demo at a time, the peers' scripts.

#![allow(dead_code, reason = "`tests/it` and `tests/physics.rs` each use part of it")]

use std::io::{BufRead, BufReader, Read};
use std::path::Path;
use std::process::{Child, ChildStdout, Command, ExitStatus, Stdio};
use std::sync::MutexGuard;

use serde_json::Value;

/// One `robowire demo` of this binary at a time while the guard lives: a demo's scenarios are
/// paced by the wall clock (a phase of motion lasts so long), and two at once on two cores starve
/// each other's streams (the spline daemon's 1 kHz loop first: the demo's PD loop then stops at
/// its stall bound).
pub(crate) fn one_demo_at_a_time() -> MutexGuard<'static, ()> {
    robowire_fixtures::wait::one_at_a_time()
}

/// What the `mcap` Python package (with `python`, the peers' environment) reads in `capture`:
/// robowire-record's independent reader, `robowire-record/tests/interop/read_capture.py`.
pub(crate) fn read_capture(python: &Path, capture: &Path) -> Value {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../robowire-record/tests/interop/read_capture.py");
    let read = Command::new(python).arg(script).arg(capture).output().unwrap();
    assert!(read.status.success(), "{}", String::from_utf8_lossy(&read.stderr));
    serde_json::from_slice(&read.stdout).unwrap()
}

/// Runs `test` with the peers' Python and the directory `examples` gives (one of
/// `robowire_fixtures::peers`' Unitree example directories), in a network namespace where
/// loopback carries multicast; skipped with one line, or failed under `ROBOWIRE_INTEROP=1`, when
/// they are missing (`robowire_fixtures::interop::require`).
pub(crate) fn with_unitree_examples(
    examples: fn() -> Result<std::path::PathBuf, String>,
    test: impl FnOnce(&Path, &Path) + Send,
) {
    let Some(python) = robowire_fixtures::interop::require(robowire_fixtures::peers::unitree_python()) else {
        return;
    };
    let examples = examples().unwrap();
    robowire_dds::netns::with_loopback_multicast(|| test(&python, &examples));
}

/// Unitree's Python example `name` in `dir` with `python`, its Enter prompt answered, on `lo`
/// (domain 0); stdout and stderr piped.
pub(crate) fn start_example(python: &Path, dir: &Path, name: &str) -> Child {
    use std::io::Write;
    let mut example = Command::new(python)
        .arg(name)
        .arg("lo")
        .current_dir(dir)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // "Press Enter to continue..."
    example.stdin.take().unwrap().write_all(b"\n").unwrap();
    example
}

/// An observer script (`script`, relative to this crate) on Unitree's SDK with `python` and
/// `args`, once it printed `ready` (its stdin piped: some end when it closes).
pub(crate) fn start_observer(python: &Path, script: &str, args: &[&str]) -> (Child, BufReader<ChildStdout>) {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join(script);
    let mut child = Command::new(python)
        .arg(script)
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    // Unitree's SDK prints its own lines on stdout: `[Reader] take sample error` when a sample
    // arrives while its reader is still being made (its listener races its constructor, seen on
    // a loaded machine). The observer's `ready` comes once a state was read after all.
    let mut seen = String::new();
    loop {
        let mut line = String::new();
        let read = stdout.read_line(&mut line).unwrap();
        if line.trim() == "ready" {
            break;
        }
        seen.push_str(&line);
        if read == 0 || !line.starts_with("[Reader]") {
            let _ = child.kill();
            let mut err = String::new();
            child.stderr.take().unwrap().read_to_string(&mut err).unwrap();
            panic!("the observer saw no state: {seen:?}\nits stderr: {err}");
        }
    }
    (child, stdout)
}

/// An observer's summary (its last line, one JSON object) once it ended.
pub(crate) fn observer_summary(mut observer: Child, mut stdout: BufReader<ChildStdout>) -> Value {
    let mut out = String::new();
    stdout.read_to_string(&mut out).unwrap();
    let status = observer.wait().unwrap();
    let mut err = String::new();
    observer.stderr.take().unwrap().read_to_string(&mut err).unwrap();
    assert!(status.success(), "observer: {status}\n{out}\n{err}");
    serde_json::from_str(out.lines().last().unwrap_or_default()).unwrap_or_else(|e| panic!("{e}: {out}\n{err}"))
}

/// The `robowire` binary under test.
pub(crate) fn robowire() -> Command {
    Command::new(env!("CARGO_BIN_EXE_robowire"))
}

/// A `robowire` process started by a test, killed when dropped.
pub(crate) struct Running {
    child: Child,
    stdout: BufReader<ChildStdout>,
    /// Its first line on stdout, without the line end: a simulator's ready line (its port or
    /// addresses).
    pub(crate) first_line: String,
}

/// What a [`Running`] process did after its first line.
pub(crate) struct Ended {
    pub(crate) status: ExitStatus,
    /// Its stdout after the first line.
    pub(crate) stdout: String,
    /// Its stderr, when it was piped.
    pub(crate) stderr: String,
}

impl Running {
    /// `robowire ARGS`, its stderr discarded, once it printed its first line.
    pub(crate) fn start(args: &[&str]) -> Self {
        Self::spawn(robowire().args(args).stderr(Stdio::null()))
    }

    /// `command` with its stdout piped, once it printed its first line (it must print one).
    pub(crate) fn spawn(command: &mut Command) -> Self {
        let mut child = command.stdout(Stdio::piped()).spawn().unwrap();
        let mut stdout = BufReader::new(child.stdout.take().unwrap());
        let mut first_line = String::new();
        stdout.read_line(&mut first_line).unwrap();
        assert!(!first_line.is_empty(), "{command:?} ended before its first line: {:?}", child.wait());
        first_line.truncate(first_line.trim_end().len());
        Self { child, stdout, first_line }
    }

    /// Its next line on stdout, without the line end; `None` once it closed stdout.
    pub(crate) fn next_line(&mut self) -> Option<String> {
        let mut line = String::new();
        (self.stdout.read_line(&mut line).unwrap() > 0).then(|| line.trim_end().to_owned())
    }

    /// Ctrl-C; it must exit cleanly.
    pub(crate) fn interrupt(self) -> Ended {
        let pid = rustix::process::Pid::from_child(&self.child);
        rustix::process::kill_process(pid, rustix::process::Signal::INT).unwrap();
        let ended = self.wait();
        assert!(ended.status.success(), "exit after Ctrl-C: {}\n{}", ended.status, ended.stderr);
        ended
    }

    /// Waits until it ends by itself.
    pub(crate) fn wait(mut self) -> Ended {
        let mut stdout = String::new();
        self.stdout.read_to_string(&mut stdout).unwrap();
        let mut stderr = String::new();
        if let Some(mut pipe) = self.child.stderr.take() {
            pipe.read_to_string(&mut stderr).unwrap();
        }
        let status = self.child.wait().unwrap();
        Ended { status, stdout, stderr }
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
