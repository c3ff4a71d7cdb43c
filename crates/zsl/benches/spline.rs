//! Spline shared memory across two processes, busy-spinning on both sides.
//!
//! - `spline_roundtrip/facade`: `SplineClient::write_command` → the echo process's
//!   `SplineDaemon` takes it and publishes state → `SplineClient::try_read_state` sees it.
//! - `spline_roundtrip/raw_c_like`: the same protocol written as a C program would: block copies
//!   and release/acquire flags straight on the region, no validation, no bookkeeping.
//! - `spline_roundtrip/flags_only`: the flag ping-pong alone.
//!
//! After criterion, each variant's p50/p99 over individually timed round trips (10 interleaved
//! rounds of 2000 per variant, so that a slow spell of the host hits all alike), go to
//! `$ROBOWIRE_BENCH_META_SPLINE` for `cargo xtask bench`. The daemon simulator's 1 kHz loop is
//! measured with every other periodic stream by the `robowire` package's `streams` bench.

// `criterion_group!`-style functions are undocumented by nature.
#![allow(missing_docs)]

use std::hint::black_box;
use std::process::{Child, Command};
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use criterion::Criterion;

#[path = "../../../benches/timing.rs"]
mod timing;
use robowire_shm::{CreateOptions, MappedRegion, SharedRegion};
use robowire_sim::spline::{CommandUpdate, SplineDaemon};
use timing::{percentiles, time_each};
use zsl::{JointControl, JointIndex, Leg, SplineClient, SplineCommandBlock, SplineStateBlock};
use zsl_proto::zerocopy::IntoBytes;

const ECHO_ENV: &str = "ROBOWIRE_SPLINE_ECHO";
const READY_OFFSET: usize = 1024;
const CMD_FLAG: usize = 336;
const STATE_FLAG: usize = 600;

fn command() -> SplineCommandBlock {
    let mut cmd = SplineCommandBlock::default();
    for leg in Leg::ALL {
        for joint in JointIndex::ALL {
            *cmd.joint_mut(leg, joint) = JointControl::new(0.5, 0.0, 40.0, 1.0, 0.0);
        }
    }
    cmd
}

/// The echo process: answers every command with a state, spinning, until killed.
fn echo(spec: &str) {
    let (mode, name) = spec.split_once(':').expect("mode:name");
    let region = MappedRegion::open(name, 2048).expect("the bench created the object");
    region.store_u32(READY_OFFSET, 1, Ordering::Release).unwrap();
    let state = SplineStateBlock::default();
    match mode {
        "facade" => {
            let mut daemon = SplineDaemon::new(&region).unwrap();
            loop {
                if daemon.take_command().unwrap() == CommandUpdate::Fresh {
                    daemon.publish_state(&state).unwrap();
                }
            }
        }
        "raw" => {
            let mut cmd = [0u8; 336];
            loop {
                if region.load_u32(CMD_FLAG, Ordering::Acquire).unwrap() != 0 {
                    region.read(0, &mut cmd).unwrap();
                    region.store_u32(CMD_FLAG, 0, Ordering::Release).unwrap();
                    region.write(344, &state.as_bytes()[..256]).unwrap();
                    // Both readers' flags, as the protocol requires.
                    region.store_u32(STATE_FLAG, 1, Ordering::Release).unwrap();
                    region.store_u32(STATE_FLAG + 4, 1, Ordering::Release).unwrap();
                }
            }
        }
        _ => loop {
            if region.load_u32(CMD_FLAG, Ordering::Acquire).unwrap() != 0 {
                region.store_u32(CMD_FLAG, 0, Ordering::Relaxed).unwrap();
                region.store_u32(STATE_FLAG, 1, Ordering::Release).unwrap();
            }
        },
    }
}

struct Peer {
    region: MappedRegion,
    child: Child,
}

impl Peer {
    fn start(mode: &str) -> Self {
        let name = format!("/robowire-bench-{mode}-{}", std::process::id());
        let region = MappedRegion::create(&name, 10240, &CreateOptions::default()).unwrap();
        let child =
            Command::new(std::env::current_exe().unwrap()).env(ECHO_ENV, format!("{mode}:{name}")).spawn().unwrap();
        let deadline = Instant::now() + Duration::from_secs(10);
        while region.load_u32(READY_OFFSET, Ordering::Acquire).unwrap() == 0 {
            assert!(Instant::now() < deadline, "echo process did not start");
            std::thread::yield_now();
        }
        Self { region, child }
    }
}

impl Drop for Peer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn raw_roundtrip(region: &MappedRegion, cmd: &[u8], state: &mut [u8; 256]) {
    region.write(0, cmd).unwrap();
    region.store_u32(CMD_FLAG, 1, Ordering::Release).unwrap();
    while region.load_u32(STATE_FLAG, Ordering::Acquire).unwrap() == 0 {
        std::hint::spin_loop();
    }
    region.read(344, state).unwrap();
    region.store_u32(STATE_FLAG, 0, Ordering::Release).unwrap();
}

fn flags_roundtrip(region: &MappedRegion) {
    region.store_u32(CMD_FLAG, 1, Ordering::Release).unwrap();
    while region.load_u32(STATE_FLAG, Ordering::Acquire).unwrap() == 0 {
        std::hint::spin_loop();
    }
    region.store_u32(STATE_FLAG, 0, Ordering::Relaxed).unwrap();
}

fn facade_roundtrip(client: &mut SplineClient<&MappedRegion>, cmd: &SplineCommandBlock) {
    client.write_command(cmd).unwrap();
    loop {
        if let Some(state) = client.try_read_state().unwrap() {
            black_box(state);
            return;
        }
        std::hint::spin_loop();
    }
}

/// Per-round-trip percentiles of the three variants, measured in interleaved rounds so that a
/// slow spell of the host (this is a VM) hits every variant alike.
fn interleaved_percentiles(cmd: &SplineCommandBlock, cmd_bytes: &[u8]) -> [(u64, u64); 3] {
    let (mut facade, mut raw, mut flags) = (Vec::new(), Vec::new(), Vec::new());
    let mut state = [0u8; 256];
    for _ in 0..10 {
        let peer = Peer::start("facade");
        let mut client = SplineClient::new(&peer.region).unwrap();
        time_each(&mut facade, 2000, || facade_roundtrip(&mut client, cmd));
        drop(peer);
        let peer = Peer::start("raw");
        time_each(&mut raw, 2000, || raw_roundtrip(&peer.region, cmd_bytes, &mut state));
        drop(peer);
        let peer = Peer::start("flags");
        time_each(&mut flags, 2000, || flags_roundtrip(&peer.region));
    }
    [percentiles(facade), percentiles(raw), percentiles(flags)]
}

fn main() {
    if let Ok(spec) = std::env::var(ECHO_ENV) {
        echo(&spec);
        return;
    }
    let cmd = command();
    let cmd_bytes = cmd.as_bytes()[..336].to_vec();
    let mut criterion = Criterion::default().configure_from_args();
    let mut meta = Vec::new();
    {
        let mut group = criterion.benchmark_group("spline_roundtrip");
        let facade = Peer::start("facade");
        let mut client = SplineClient::new(&facade.region).unwrap();
        group.bench_function("facade", |b| b.iter(|| facade_roundtrip(&mut client, &cmd)));
        drop(facade);

        let raw = Peer::start("raw");
        let mut state = [0u8; 256];
        group.bench_function("raw_c_like", |b| b.iter(|| raw_roundtrip(&raw.region, &cmd_bytes, &mut state)));
        drop(raw);

        let flags = Peer::start("flags");
        group.bench_function("flags_only", |b| b.iter(|| flags_roundtrip(&flags.region)));
        drop(flags);
        group.finish();
    }
    criterion.final_summary();
    let [facade, raw, flags] = interleaved_percentiles(&cmd, &cmd_bytes);
    for (name, (p50, p99)) in [("facade", facade), ("raw", raw), ("flags", flags)] {
        meta.push(format!("\"{name}_p50_ns\":{p50},\"{name}_p99_ns\":{p99}"));
    }

    let json = format!("{{\"spline_roundtrip\":{{{}}}}}", meta.join(","));
    println!("{json}");
    if let Ok(path) = std::env::var("ROBOWIRE_BENCH_META_SPLINE") {
        std::fs::write(path, json).unwrap();
    }
}
