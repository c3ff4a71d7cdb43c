//! The KMC stack on a pseudo-terminal, against baselines measured in the same run.
//!
//! - *Request → response*: `UartClient::request_vehicle_speed()` until the decoded `0xB3`
//!   speed frame comes back from the chassis simulator (1 byte out, 5 back), sample by sample
//!   alternating with the baseline, a *raw pty echo*: the same 1 byte written and 5 bytes read
//!   back on plain blocking file descriptors, answered by a thread that does nothing else.
//!   The client side runs on CPU 0, the peers on CPU 1.
//!
//! The `Driver`'s 100 Hz stream is measured with every other periodic stream by the
//! `robowire` package's `streams` bench.
//!
//! The figures go to `$ROBOWIRE_BENCH_META_KMC` for `cargo xtask bench`.

#![allow(missing_docs)]

use std::io::{Read, Write};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use kmc::{ChassisFrame, SerialPortOptions, UartClient};
use robowire_serial::Pty;
use robowire_sim::kmc::{ChassisSim, ChassisSimConfig};

#[path = "../../../benches/timing.rs"]
mod timing;
use timing::{on_cpu, percentiles, pin};

const CLIENT_CPU: usize = 0;
const PEER_CPU: usize = 1;
const RESPONSE_LEN: usize = 5;
const WAIT: Duration = Duration::from_secs(1);

/// The baseline peer: reads 1 byte, answers 5, on the master side of its own pty.
struct RawEcho {
    port: std::fs::File,
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl RawEcho {
    fn start() -> Self {
        let stop = Arc::new(AtomicBool::new(false));
        let (pty, thread) = on_cpu(PEER_CPU, || {
            let pty = Arc::new(Pty::open().expect("opening a pty"));
            let (peer, stop) = (pty.clone(), stop.clone());
            let thread = std::thread::spawn(move || {
                let mut buf = [0u8; 64];
                let reply = [0xB3, 0, 0, 0, 0];
                while !stop.load(Ordering::Relaxed) {
                    let Ok(n) = peer.read_timeout(&mut buf, Duration::from_millis(5)) else { return };
                    for _ in 0..n {
                        if peer.write_all(&reply, WAIT).is_err() {
                            return;
                        }
                    }
                }
            });
            (pty, thread)
        });
        let port =
            std::fs::OpenOptions::new().read(true).write(true).open(pty.slave_path()).expect("opening the slave");
        Self { port, stop, thread: Some(thread) }
    }

    fn round_trip(&mut self, buf: &mut [u8; RESPONSE_LEN]) {
        self.port.write_all(&[0xB3]).unwrap();
        self.port.read_exact(buf).unwrap();
    }
}

impl Drop for RawEcho {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// Request → response through `UartClient` and the simulator, alternating with the raw echo.
fn round_trips(n: usize) -> (Vec<u64>, Vec<u64>) {
    let sim = on_cpu(PEER_CPU, || ChassisSim::spawn(ChassisSimConfig::default()).expect("chassis simulator"));
    let mut echo = RawEcho::start();
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    let (mut raw, mut trip) = (Vec::with_capacity(n), Vec::with_capacity(n));
    runtime.block_on(async {
        let mut client = UartClient::open(sim.path(), &SerialPortOptions::default()).unwrap();
        let mut buf = [0u8; RESPONSE_LEN];
        for i in 0..n + 200 {
            let start = Instant::now();
            echo.round_trip(&mut buf);
            let raw_ns = start.elapsed().as_nanos() as u64;
            let start = Instant::now();
            client.request_vehicle_speed().await.unwrap();
            loop {
                match client.poll(WAIT).await.unwrap() {
                    Some(ChassisFrame::VehicleSpeed(_)) => break,
                    Some(_) => {}
                    None => panic!("the simulator did not answer 0xB3"),
                }
            }
            if i >= 200 {
                trip.push(start.elapsed().as_nanos() as u64);
                raw.push(raw_ns);
            }
        }
    });
    (raw, trip)
}

fn main() {
    // `cargo bench` passes harness arguments (`--bench`, criterion's options): not ours.
    let quick = std::env::var_os("ROBOWIRE_BENCH_QUICK").is_some();
    let (rounds, per_round) = if quick { (2, 500) } else { (5, 1000) };
    pin(CLIENT_CPU);
    let (mut raw, mut trip) = (Vec::new(), Vec::new());
    for _ in 0..rounds {
        let (r, t) = round_trips(per_round);
        raw.extend(r);
        trip.extend(t);
    }
    let ((raw50, raw99), (trip50, trip99)) = (percentiles(raw), percentiles(trip));
    let json = format!(
        "{{\"raw_echo_p50_ns\":{raw50},\"raw_echo_p99_ns\":{raw99},\"round_trip_p50_ns\":{trip50},\"round_trip_p99_ns\":{trip99}}}"
    );
    println!("kmc serial: {json}");
    if let Ok(path) = std::env::var("ROBOWIRE_BENCH_META_KMC") {
        std::fs::write(path, json).unwrap();
    }
}
