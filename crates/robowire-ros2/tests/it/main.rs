//! The bridge's integration tests, one binary. The bridge runs in this process
//! (`robowire_ros2::run` on a thread of its own, the `sim:` devices' simulators in-process, as
//! `robowire ros2` runs it) where loopback carries multicast (`robowire_dds::netns`), against its
//! peers: a ROS 2 peer on CycloneDDS (the `cyclonedds` Python binding 0.10.2 with the ROS 2
//! message types declared under their ROS 2 DDS names, `tests/interop/`), ros2-client (an
//! independent ROS 2 client library, no Python) and robowire's own DDS.
//!
//! - [`devices`]: the peer drives a simulated chassis and dog through `cmd_vel`, sees them move
//!   on `odom` and stop after the deadman time, reads `joint_states`, `imu`, `battery_state` and
//!   `tf` field for field, calls `stand_up` in rmw_cyclonedds' request/reply format; unarmed, the
//!   same `cmd_vel` moves nothing. A Go2's and a G1's topics and their vendor's state passed
//!   through, read by the peer (Unitree's classes) and by robowire's own DDS readers.
//! - [`graph`]: the bridge's nodes on `ros_discovery_info` (Jazzy's and Humble's GID sizes), read
//!   by the peer and by robowire's own DDS, each GID matched to the GUID DDS discovery reports for
//!   the bridge's endpoint.
//! - [`services`]: ros2-client calls `stand_up` in rmw_fastrtps' and rmw_cyclonedds' service
//!   mappings; a request of neither shape is counted and not answered.
//! - [`record`]: the bridge's capture of its ROS 2 topics read whole by two independent ROS 2
//!   readers, the devices' own links beside it.
//!
//! What only the command line does (its flags, its `ready` line, its counters as JSON, what it
//! says on stderr) is tested with the `robowire` crate (`tests/it/ros2.rs` there).

mod devices;
mod graph;
mod record;
mod services;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::thread::JoinHandle;
use std::time::Duration;

use robowire_ros2::{BridgeError, BridgeOptions, BridgedDevice};
use serde_json::Value;
use tokio::sync::watch;

/// Generous: a sample, an answer or a topic not there after this long is a failure, not slowness.
const WAIT: Duration = Duration::from_secs(20);

/// A bridge of `devices` (addresses) with the defaults of `robowire ros2`: domain 0, unarmed,
/// deadman 0.5 s, native rates, Jazzy's `ros_discovery_info`.
fn options(devices: &[&str]) -> BridgeOptions {
    BridgeOptions::new(devices.iter().map(|d| d.parse().unwrap_or_else(|e| panic!("{d}: {e}"))).collect())
}

/// A bridge running in this process, on a thread of its own, until [`Bridge::stop`] (or drop).
struct Bridge {
    stop: watch::Sender<bool>,
    run: Option<JoinHandle<Result<Vec<BridgedDevice>, BridgeError>>>,
}

impl Bridge {
    /// Runs the bridge of `options` on a runtime of two workers (as `robowire ros2` does); returns
    /// once every device is open and the bridge runs.
    fn start(options: BridgeOptions) -> Self {
        let (stop, stopped) = watch::channel(false);
        let (started, ready) = std::sync::mpsc::channel();
        let run = std::thread::spawn(move || {
            robowire_fixtures::wait::runtime_two_workers().block_on(robowire_ros2::run(options, stopped, |_| {
                let _ = started.send(());
            }))
        });
        let mut bridge = Self { stop, run: Some(run) };
        if ready.recv().is_err() {
            match bridge.run.take().map(JoinHandle::join) {
                Some(Ok(Err(e))) => panic!("the bridge did not start: {e:?}"),
                Some(Err(panic)) => std::panic::resume_unwind(panic),
                other => panic!("the bridge ended before it was ready: {other:?}"),
            }
        }
        bridge
    }

    /// Tells it to stop (what Ctrl-C does to `robowire ros2`), without waiting.
    fn interrupt(&self) {
        let _ = self.stop.send(true);
    }

    /// Stops it and waits until it has (its devices closed, its nodes gone from the graph): its
    /// devices, in the order given, with their counters.
    fn stop(mut self) -> Vec<BridgedDevice> {
        self.interrupt();
        match self.run.take().map(JoinHandle::join) {
            Some(Ok(Ok(devices))) => devices,
            Some(Ok(Err(e))) => panic!("the bridge failed: {e:?}"),
            Some(Err(panic)) => std::panic::resume_unwind(panic),
            None => unreachable!("a bridge is stopped once"),
        }
    }
}

impl Drop for Bridge {
    /// A test that failed stops its bridge too, its devices closed.
    fn drop(&mut self) {
        self.interrupt();
        if let Some(run) = self.run.take() {
            let _ = run.join();
        }
    }
}

/// The peers' Python, made (with the network) before entering a namespace; `None`: skipped.
fn interop_python() -> Option<PathBuf> {
    robowire_fixtures::interop::require(robowire_fixtures::peers::unitree_python())
}

/// The Python peers' directory.
fn interop_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/interop")
}

/// Runs the ROS 2 peer's `scenario` on `namespace`; its JSON.
fn peer(python: &Path, scenario: &str, namespace: &str) -> Value {
    let out = Command::new(python)
        .arg("ros2_peer.py")
        .args([scenario, namespace])
        .current_dir(interop_dir())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{scenario}: {}\n{stdout}\n{}", out.status, String::from_utf8_lossy(&out.stderr));
    serde_json::from_str(stdout.lines().last().unwrap_or_default()).unwrap_or_else(|e| panic!("{e}: {stdout}"))
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}
