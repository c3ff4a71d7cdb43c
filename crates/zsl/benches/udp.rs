//! The ZSL-1 UDP stack on loopback.
//!
//! - `zsl_udp_codec/*`: encode and decode of each datagram, beside a memcpy of its size.
//! - Latency percentiles, measured in interleaved rounds so that a slow spell of the host hits
//!   every variant alike:
//!   - *raw echo*: a 40-byte datagram to an echo thread that answers with 560 bytes, plain
//!     blocking std sockets (the baseline), sample by sample alternating with the round trip;
//!   - *call to wire*: from `HighLevel::move_velocity()` being called to the datagram read by
//!     a socket standing in for the dog (the vendor client needs about 1.8 ms: it waits for
//!     its next 2 ms tick);
//!   - *round trip*: from a HighLevel call to the client holding the simulator's state that
//!     reports the new mode (`passive()` and `lie_down()` alternately).
//!
//! The percentiles go to `$ROBOWIRE_BENCH_META_ZSL_UDP` for `cargo xtask bench`.

// `criterion_group!`-style functions are undocumented by nature.
#![allow(missing_docs)]

use std::hint::black_box;
use std::net::UdpSocket;
use std::time::{Duration, Instant};

use criterion::Criterion;
use robowire_sim::zsl1::{Zsl1Sim, Zsl1SimConfig};
use zsl::udp::{ClientOptions, ControlMode, HighLevel};
use zsl_proto::udp::{
    HIGH_LEVEL_STATE_HEADER, HighLevelCommand, HighLevelState, LowLevelCommand, LowLevelState, MAGIC_ZSL1, Model,
    MotorCommand,
};

#[path = "../../../benches/timing.rs"]
mod timing;
use timing::{percentiles, pin};

fn codec(criterion: &mut Criterion) {
    let mut group = criterion.benchmark_group("zsl_udp_codec");
    let hl = HighLevelCommand::move_velocity(0.5, -0.25, 1.5);
    let hl_bytes = hl.encode(Model::Zsl1);
    let state = HighLevelState { header: HIGH_LEVEL_STATE_HEADER, control_mode: 1.into(), ..Default::default() };
    let state_bytes = state.encode();
    let ll = LowLevelCommand::new(MotorCommand::pd_hold([[0.0; 4], [0.8; 4], [-1.5; 4]], [80.0; 3], [1.0; 3]));
    let ll_bytes = ll.encode(Model::Zsl1);
    let ll_state = LowLevelState { magic: MAGIC_ZSL1.into(), ..Default::default() };
    let ll_state_bytes = ll_state.encode();
    group.bench_function("hl_command_encode_40B", |b| b.iter(|| black_box(black_box(&hl).encode(Model::Zsl1))));
    group.bench_function("hl_command_decode_40B", |b| b.iter(|| HighLevelCommand::decode(black_box(&hl_bytes))));
    group.bench_function("hl_state_decode_strict_560B", |b| {
        b.iter(|| HighLevelState::decode_strict(black_box(&state_bytes)))
    });
    let mut merged = HighLevelState::default();
    group.bench_function("hl_state_update_lenient_560B", |b| {
        b.iter(|| black_box(&mut merged).update_lenient(black_box(&state_bytes)))
    });
    group.bench_function("ll_command_encode_248B", |b| b.iter(|| black_box(black_box(&ll).encode(Model::Zsl1))));
    group.bench_function("ll_command_decode_248B", |b| b.iter(|| LowLevelCommand::decode(black_box(&ll_bytes))));
    group.bench_function("ll_state_decode_strict_272B", |b| {
        b.iter(|| LowLevelState::decode_strict(black_box(&ll_state_bytes)))
    });
    for (name, len) in [("memcpy_40B", 40usize), ("memcpy_248B", 248), ("memcpy_272B", 272), ("memcpy_560B", 560)] {
        let src = vec![0xA5u8; len];
        let mut dst = vec![0u8; len];
        group.bench_function(name, |b| b.iter(|| black_box(&mut dst).copy_from_slice(black_box(&src))));
    }
    group.finish();
}

/// The CPUs the two sides run on: the client side (this thread, the runtime's workers) on one,
/// the peer (echo thread, simulator) on the other, as between a computer and its robot. Without
/// pinning, whether two threads share a vCPU decides a loopback round trip on this VM (~10 µs
/// shared, ~40 µs apart) and the comparison would measure the scheduler's luck.
const CLIENT_CPU: usize = 0;
const PEER_CPU: usize = 1;

/// The baseline: 40 bytes out, 560 back, through an echo thread on plain blocking sockets.
struct RawEcho {
    socket: UdpSocket,
    _echo: std::thread::JoinHandle<()>,
}

impl RawEcho {
    fn start() -> Self {
        let echo = UdpSocket::bind("127.0.0.1:0").unwrap();
        let socket = UdpSocket::bind("127.0.0.1:0").unwrap();
        socket.connect(echo.local_addr().unwrap()).unwrap();
        let handle = std::thread::spawn(move || {
            pin(PEER_CPU);
            let mut buf = [0u8; 600];
            let reply = [0u8; 560];
            while let Ok((n, from)) = echo.recv_from(&mut buf) {
                if n == 0 {
                    return;
                }
                let _ = echo.send_to(&reply, from);
            }
        });
        Self { socket, _echo: handle }
    }

    fn round_trip(&self, out: &[u8; 40], buf: &mut [u8; 600]) {
        self.socket.send(out).unwrap();
        black_box(self.socket.recv(buf).unwrap());
    }
}

impl Drop for RawEcho {
    fn drop(&mut self) {
        let _ = self.socket.send(&[]);
    }
}

fn loopback_options(dog: std::net::SocketAddr) -> ClientOptions {
    ClientOptions { dog, ..ClientOptions::high_level([127, 0, 0, 1].into(), 0, dog.ip()) }
}

/// Call to wire: `move_velocity()` → the datagram read by the dog's socket.
fn call_to_wire(runtime: &tokio::runtime::Runtime, samples: &mut Vec<u64>, n: usize) {
    let wire = UdpSocket::bind("127.0.0.1:0").unwrap();
    runtime.block_on(async {
        let options = loopback_options(wire.local_addr().unwrap()).with_watchdog(Duration::from_secs(3600));
        let dog = HighLevel::open(options).unwrap();
        // The robot walks (mode 18): `move` passes the mode gate and is acknowledged.
        let walking = HighLevelState { header: HIGH_LEVEL_STATE_HEADER, control_mode: 18.into(), ..Default::default() };
        wire.send_to(&walking.encode(), dog.local_addr()).unwrap();
        assert!(dog.wait_for_mode(ControlMode::Move, Duration::from_secs(2)).await.is_some());
        let mut buf = [0u8; 64];
        for i in 0..n + 200 {
            let vx = if i % 2 == 0 { 0.5 } else { 0.6 };
            let start = Instant::now();
            dog.move_velocity(vx, 0.0, 0.0).unwrap();
            // Skip the 2 ms stream's repeats of the previous command.
            loop {
                let len = wire.recv(&mut buf).unwrap();
                if len == 40 && buf[4..8] == vx.to_le_bytes() {
                    break;
                }
            }
            if i >= 200 {
                samples.push(start.elapsed().as_nanos() as u64);
            }
        }
    });
}

/// Round trip through the simulator (a call → the state that reports the new mode), sample by
/// sample alternating with a raw echo round trip, so that both see the same state of the host
/// (on this VM a sleeping vCPU's wake-up alone swings a round trip between ~10 and ~40 µs).
/// Measured in a task on the runtime, where a user's control loop runs.
fn round_trips(runtime: &tokio::runtime::Runtime, raw: &mut Vec<u64>, trip: &mut Vec<u64>, n: usize) {
    let sim = Zsl1Sim::spawn(Zsl1SimConfig { cpu: Some(PEER_CPU), ..Zsl1SimConfig::loopback() }).unwrap();
    let addr = sim.high_level_addr();
    let (raw_samples, trip_samples) = runtime
        .block_on(runtime.spawn(async move {
            let echo = RawEcho::start();
            let out = HighLevelCommand::stand_up().encode(Model::Zsl1);
            let mut buf = [0u8; 600];
            let (mut raw, mut trip) = (Vec::with_capacity(n), Vec::with_capacity(n));
            let dog = HighLevel::open(loopback_options(addr)).unwrap();
            assert!(dog.wait_connected(Duration::from_secs(2)).await);
            for i in 0..n + 200 {
                let start = Instant::now();
                echo.round_trip(&out, &mut buf);
                let raw_ns = start.elapsed().as_nanos() as u64;
                let target = if i % 2 == 0 { ControlMode::Passive } else { ControlMode::LieDown };
                let start = Instant::now();
                // The 11th call in a row made while the robot still reports the other mode carries
                // the vendor's 0x3007 (it was sent all the same): the result does not matter here.
                let _ = if i % 2 == 0 { dog.passive() } else { dog.lie_down() };
                assert!(dog.wait_for_mode(target, Duration::from_secs(1)).await.is_some());
                if i >= 200 {
                    trip.push(start.elapsed().as_nanos() as u64);
                    raw.push(raw_ns);
                }
            }
            (raw, trip)
        }))
        .unwrap();
    raw.extend(raw_samples);
    trip.extend(trip_samples);
    drop(sim);
}

fn main() {
    let mut criterion = Criterion::default().configure_from_args();
    codec(&mut criterion);
    criterion.final_summary();

    let quick = std::env::var_os("ROBOWIRE_BENCH_QUICK").is_some();
    let (rounds, per_round) = if quick { (3, 500) } else { (10, 1000) };
    pin(CLIENT_CPU);
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .on_thread_start(|| pin(CLIENT_CPU))
        .enable_all()
        .build()
        .unwrap();
    let (mut raw, mut wire, mut trip) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..rounds {
        call_to_wire(&runtime, &mut wire, per_round);
        round_trips(&runtime, &mut raw, &mut trip, per_round);
    }
    let (raw, wire, trip) = (percentiles(raw), percentiles(wire), percentiles(trip));
    let json = format!(
        "{{\"raw_echo_p50_ns\":{},\"raw_echo_p99_ns\":{},\"call_to_wire_p50_ns\":{},\"call_to_wire_p99_ns\":{},\"round_trip_p50_ns\":{},\"round_trip_p99_ns\":{}}}",
        raw.0, raw.1, wire.0, wire.1, trip.0, trip.1
    );
    println!("zsl udp latency: {json}");
    if let Ok(path) = std::env::var("ROBOWIRE_BENCH_META_ZSL_UDP") {
        std::fs::write(path, json).unwrap();
    }
}
