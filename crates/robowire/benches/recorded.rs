//! What recording costs a stream, measured against the simulated devices through the facades,
//! each stream run alternately with its link recorded to MCAP (`robowire-record`) and without:
//!
//! - the ZSL-1 HighLevel command stream's send lateness (2 ms period, the client's own figures)
//!   against the simulated ZSL-1 (UDP);
//! - the KMC driver's 100 Hz stream (serial, on a pty);
//! - the spline daemon simulator's 1 kHz stream (shared memory).
//!
//! An app's bench, since it drives the facades and the simulators (the recorder's own
//! throughput is `robowire-record`'s bench). Figures to `ROBOWIRE_BENCH_META_RECORDED` for
//! `cargo xtask bench`.

use std::time::{Duration, Instant};

use robowire_record::Recorder;
use robowire_sim::kmc::{ChassisSim, ChassisSimConfig};
use robowire_sim::spline::{SplineSim, SplineSimConfig};
use robowire_sim::zsl1::{Zsl1Sim, Zsl1SimConfig};
use serde_json::json;
use zsl::udp::{ClientOptions, Device, HighLevel};
use zsl_proto::description::HIGH_LEVEL;

fn temp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("robowire-bench-{}-{name}.mcap", std::process::id()))
}

/// The stream's lateness over `seconds`, recorded or not: (p50 µs, p99 µs, frames dropped).
fn stream(runtime: &tokio::runtime::Runtime, seconds: f64, record: bool) -> (u32, u32, u64) {
    let sim = Zsl1Sim::spawn(Zsl1SimConfig::loopback()).unwrap();
    let recorder = record.then(|| Recorder::create(temp("stream"), "bench").unwrap());
    let (lateness, dropped) = runtime.block_on(async {
        let mut options = ClientOptions {
            dog: sim.high_level_addr(),
            ..ClientOptions::high_level([127, 0, 0, 1].into(), 0, [127, 0, 0, 1].into())
        };
        if let Some(recorder) = &recorder {
            options = options.with_tap(recorder.link("zsl1/high_level", &HIGH_LEVEL));
        }
        let zsl1 = HighLevel::open(options).unwrap();
        assert!(zsl1.wait_connected(Duration::from_secs(2)).await);
        tokio::time::sleep(Duration::from_secs_f64(seconds)).await;
        let lateness = zsl1.stats().stream_lateness;
        zsl1.close();
        (lateness, recorder.as_ref().map_or(0, Recorder::dropped))
    });
    if let Some(recorder) = recorder {
        recorder.finish().unwrap();
        let _ = std::fs::remove_file(temp("stream"));
    }
    (lateness.p50_us, lateness.p99_us, dropped)
}

/// The KMC driver's 100 Hz 0xA5 stream over `seconds` against the chassis simulator on a pty,
/// its serial link recorded or not: (p50 µs, p99 µs, frames dropped).
fn kmc_stream(seconds: f64, record: bool) -> (u32, u32, u64) {
    use kmc::{Device, Driver, DriverOptions, SerialTaps};
    let sim = ChassisSim::spawn(ChassisSimConfig::default()).unwrap();
    let recorder = record.then(|| Recorder::create(temp("kmc"), "bench").unwrap());
    let taps = SerialTaps {
        frames: recorder.as_ref().map(|r| r.link("kmc/serial", &kmc_proto::description::HOST)),
        skipped: recorder.as_ref().map(|r| r.link("kmc/serial_skipped", &robowire_core::json::SKIPPED_BYTES)),
    };
    let options = DriverOptions { command_timeout: Duration::from_secs(3600), taps, ..DriverOptions::default() };
    let driver = Driver::open(sim.path(), options).unwrap();
    driver.set_command(0.3, 0.0).unwrap();
    let end = Instant::now() + Duration::from_secs_f64(seconds);
    while Instant::now() < end {
        for _frame in driver.messages_until(Instant::now() + Duration::from_millis(50)) {}
    }
    let lateness = driver.stats().control_lateness;
    driver.close().unwrap();
    let dropped = recorder.map_or(0, |r| r.finish().unwrap().dropped);
    let _ = std::fs::remove_file(temp("kmc"));
    (lateness.p50_us, lateness.p99_us, dropped)
}

/// The spline daemon simulator's 1 kHz state stream over `seconds`, its shared memory (states
/// and IMU samples written, commands taken) recorded or not: (p50 µs, p99 µs, frames dropped).
fn spline_stream(seconds: f64, record: bool) -> (u32, u32, u64) {
    let recorder = record.then(|| Recorder::create(temp("spline"), "bench").unwrap());
    let config = SplineSimConfig {
        tap: recorder.as_ref().map(|r| r.link("spline/spline", &zsl_proto::description::SPLINE_DAEMON)),
        imu_tap: recorder.as_ref().map(|r| r.link("spline/imu", &zsl_proto::description::IMU)),
        ..SplineSimConfig::private(&format!("bench-record-{}", std::process::id()))
    };
    let sim = SplineSim::spawn(config).unwrap();
    std::thread::sleep(Duration::from_secs_f64(seconds));
    let lateness = sim.stats().lateness;
    drop(sim);
    let dropped = recorder.map_or(0, |r| r.finish().unwrap().dropped);
    let _ = std::fs::remove_file(temp("spline"));
    (lateness.p50_us, lateness.p99_us, dropped)
}

/// `rounds` alternating runs of `stream` plain and recorded: the medians of each, as JSON.
fn alternate(rounds: usize, seconds: f64, stream: fn(f64, bool) -> (u32, u32, u64)) -> serde_json::Value {
    let (mut plain, mut recorded, mut dropped) = (Vec::new(), Vec::new(), 0);
    for _ in 0..rounds {
        plain.push(stream(seconds, false));
        let r = stream(seconds, true);
        dropped += r.2;
        recorded.push(r);
    }
    let median = |v: &[(u32, u32, u64)], pick: fn(&(u32, u32, u64)) -> u32| {
        let mut xs: Vec<u32> = v.iter().map(pick).collect();
        xs.sort_unstable();
        xs[xs.len() / 2]
    };
    json!({
        "plain_p50_us": median(&plain, |r| r.0), "plain_p99_us": median(&plain, |r| r.1),
        "recorded_p50_us": median(&recorded, |r| r.0), "recorded_p99_us": median(&recorded, |r| r.1),
        "dropped": dropped,
    })
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    let quick = std::env::var_os("ROBOWIRE_BENCH_QUICK").is_some();
    let (rounds, seconds) = if quick { (2, 1.0) } else { (5, 3.0) };
    let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
    let (mut plain, mut recorded, mut dropped) = (Vec::new(), Vec::new(), 0);
    for _ in 0..rounds {
        plain.push(stream(&runtime, seconds, false));
        let r = stream(&runtime, seconds, true);
        dropped += r.2;
        recorded.push(r);
    }
    let median = |v: &mut Vec<(u32, u32, u64)>, pick: fn(&(u32, u32, u64)) -> u32| {
        let mut xs: Vec<u32> = v.iter().map(pick).collect();
        xs.sort_unstable();
        xs[xs.len() / 2]
    };
    let kmc = alternate(rounds, seconds, kmc_stream);
    let spline = alternate(rounds, seconds, spline_stream);
    let meta = json!({
        "lateness_plain_p50_us": median(&mut plain, |r| r.0), "lateness_plain_p99_us": median(&mut plain, |r| r.1),
        "lateness_recorded_p50_us": median(&mut recorded, |r| r.0), "lateness_recorded_p99_us": median(&mut recorded, |r| r.1),
        "stream_frames_dropped": dropped, "kmc_stream": kmc, "spline_stream": spline,
    });
    println!("recorded: {meta}");
    if let Ok(path) = std::env::var("ROBOWIRE_BENCH_META_RECORDED") {
        std::fs::write(path, meta.to_string()).unwrap();
    }
}
