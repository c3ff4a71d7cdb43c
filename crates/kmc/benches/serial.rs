//! The KMC stack on a pseudo-terminal, against baselines measured in the same run.
//!
//! - *Request → response*: `UartClient::request_vehicle_speed()` until the decoded `0xB3`
//!   speed frame comes back from the chassis simulator (1 byte out, 5 back), sample by sample
//!   alternating with the baseline, a *raw pty echo*: the same 1 byte written and 5 bytes read
//!   back on plain blocking file descriptors, answered by a thread that does nothing else.
//!   The client side runs on CPU 0, the peers on CPU 1.
//! - *Loop jitter*: the `Driver`'s 100 Hz `0xA5` stream for some seconds (send lateness against
//!   the absolute deadlines, and the interval jitter as the chassis saw it), beside a bare
//!   thread sleeping to the same absolute deadlines.
//!
//! The figures go to `$ROBOWIRE_BENCH_META_KMC` for `cargo xtask bench`.

#![allow(missing_docs)]

use std::io::{Read, Write};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use kmc::{ChassisFrame, Driver, DriverOptions, SerialPortOptions, UartClient};
use kmc_proto::HostFrame;
use robowire_core::timing::{LatenessRing, LatenessSummary};
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

/// The Driver's 100 Hz stream for `seconds`: its send lateness and the interval jitter at the
/// chassis (|interval − 10 ms|).
fn driver_stream(seconds: f64) -> (LatenessSummary, LatenessSummary, f64) {
    let sim = on_cpu(PEER_CPU, || ChassisSim::spawn(ChassisSimConfig::default()).expect("chassis simulator"));
    let options = DriverOptions { cpu_affinity: Some(CLIENT_CPU), ..DriverOptions::default() };
    let period_us = 1e6 / options.control_rate_hz;
    let mut driver = Driver::new(sim.path(), options).unwrap();
    driver.start().unwrap();
    let end = Instant::now() + Duration::from_secs_f64(seconds);
    while Instant::now() < end {
        driver.set_command(0.3, 0.0).unwrap();
        for _frame in driver.messages_until(Instant::now() + Duration::from_millis(50)) {}
    }
    let stats = driver.stats();
    // The stop burst at the end is back to back by design: the stream is measured up to it.
    let stopping_at = Instant::now();
    driver.stop().unwrap();
    let stream: Vec<Instant> = sim
        .received()
        .iter()
        .filter(|r| matches!(r.frame, HostFrame::PcControl(_)) && r.at < stopping_at)
        .map(|r| r.at)
        .collect();
    let mut jitter: LatenessRing<16384> = LatenessRing::new();
    for w in stream.windows(2) {
        jitter.record(((w[1] - w[0]).as_micros() as f64 - period_us).abs() as u32);
    }
    let rate_hz = stream.len().saturating_sub(1) as f64
        / stream.last().zip(stream.first()).map_or(1.0, |(l, f)| (*l - *f).as_secs_f64().max(1e-9));
    (stats.control_lateness, jitter.summary(), rate_hz)
}

/// The baseline loop: a bare thread on the client CPU sleeping to absolute 10 ms deadlines.
fn sleep_loop(seconds: f64) -> LatenessSummary {
    on_cpu(CLIENT_CPU, || {
        let period = Duration::from_millis(10);
        let mut ring: LatenessRing<4096> = LatenessRing::new();
        let start = Instant::now();
        let mut next = start + period;
        while start.elapsed().as_secs_f64() < seconds {
            std::thread::sleep(next.saturating_duration_since(Instant::now()));
            ring.record(u32::try_from(next.elapsed().as_micros()).unwrap_or(u32::MAX));
            next += period;
        }
        ring.summary()
    })
}

fn summary_json(s: &LatenessSummary) -> String {
    format!("{{\"count\":{},\"p50_us\":{},\"p99_us\":{},\"max_us\":{}}}", s.count, s.p50_us, s.p99_us, s.max_us)
}

fn main() {
    // `cargo bench` passes harness arguments (`--bench`, criterion's options): not ours.
    let quick = std::env::var_os("ROBOWIRE_BENCH_QUICK").is_some();
    let (rounds, per_round, seconds) = if quick { (2, 500, 2.0) } else { (5, 1000, 10.0) };
    pin(CLIENT_CPU);
    let (mut raw, mut trip) = (Vec::new(), Vec::new());
    for _ in 0..rounds {
        let (r, t) = round_trips(per_round);
        raw.extend(r);
        trip.extend(t);
    }
    let ((raw50, raw99), (trip50, trip99)) = (percentiles(raw), percentiles(trip));
    let baseline = sleep_loop(seconds);
    let (lateness, jitter, rate_hz) = driver_stream(seconds);
    let json = format!(
        "{{\"raw_echo_p50_ns\":{raw50},\"raw_echo_p99_ns\":{raw99},\"round_trip_p50_ns\":{trip50},\"round_trip_p99_ns\":{trip99},\"stream_seconds\":{seconds},\"stream_rate_hz\":{rate_hz:.2},\"stream_lateness\":{},\"stream_jitter_at_chassis\":{},\"sleep_loop_lateness\":{}}}",
        summary_json(&lateness),
        summary_json(&jitter),
        summary_json(&baseline)
    );
    println!("kmc serial: {json}");
    if let Ok(path) = std::env::var("ROBOWIRE_BENCH_META_KMC") {
        std::fs::write(path, json).unwrap();
    }
}
