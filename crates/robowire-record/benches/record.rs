//! Recording's cost, measured in one run:
//!
//! - the ZSL-1 HighLevel command stream's send lateness (2 ms period, the client's own figures)
//!   with its link recorded and without, against the simulated dog, alternating; the same for
//!   the KMC driver's 100 Hz stream (serial, on a pty) and the spline daemon simulator's 1 kHz
//!   stream (shared memory);
//! - the recorder's throughput: 560-byte states tapped as fast as one thread can, written raw
//!   and decoded to JSON (frames/s and MB/s of what was written, what the ring dropped); tapped
//!   at 1 M frames/s (560-byte and 64-byte frames, raw); 100 links at 1 kHz each, with JSON
//!   (what was dropped, what went without JSON).
//!
//! Figures to `ROBOWIRE_BENCH_META_RECORD` for `cargo xtask bench`.

use std::time::{Duration, Instant};

use robowire_record::{Compression, Direction, Recorder, RecorderOptions};
use robowire_sim::kmc::{ChassisSim, ChassisSimConfig};
use robowire_sim::spline::{SplineSim, SplineSimConfig};
use robowire_sim::zsl1::{Zsl1Sim, Zsl1SimConfig};
use serde_json::json;
use zsl::udp::{ClientOptions, Device, HighLevel};
use zsl_proto::description::HIGH_LEVEL;
use zsl_proto::udp::{HIGH_LEVEL_STATE_HEADER, HighLevelState};

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
        let dog = HighLevel::open(options).unwrap();
        assert!(dog.wait_connected(Duration::from_secs(2)).await);
        tokio::time::sleep(Duration::from_secs_f64(seconds)).await;
        let lateness = dog.stats().stream_lateness;
        dog.close();
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
    let (rounds, seconds, frames) = if quick { (2, 1.0, 50_000) } else { (5, 3.0, 300_000) };
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

    let state =
        HighLevelState { header: HIGH_LEVEL_STATE_HEADER, control_mode: 18.into(), ..Default::default() }.encode();
    let kmc = alternate(rounds, seconds, kmc_stream);
    let spline = alternate(rounds, seconds, spline_stream);
    let unpaced_raw = throughput(&state, frames, 1, None, false);
    let unpaced_json = throughput(&state, frames, 1, None, true);
    let million = throughput(&state, 2_000_000, 1, Some(1e6), false);
    let million_small = throughput(&state[..64], 2_000_000, 1, Some(1e6), false);
    let hundred_links = throughput(&state, if quick { 100_000 } else { 1_000_000 }, 100, Some(100e3), true);
    let zstd = RecorderOptions { compression: Compression::Zstd, ..Default::default() };
    let hundred_links_zstd = throughput_with(&state, if quick { 100_000 } else { 1_000_000 }, 100, Some(100e3), zstd);
    let meta = json!({
        "lateness_plain_p50_us": median(&mut plain, |r| r.0), "lateness_plain_p99_us": median(&mut plain, |r| r.1),
        "lateness_recorded_p50_us": median(&mut recorded, |r| r.0), "lateness_recorded_p99_us": median(&mut recorded, |r| r.1),
        "stream_frames_dropped": dropped,
        "frame_bytes": state.len(), "kmc_stream": kmc, "spline_stream": spline,
        "unpaced_raw": unpaced_raw, "unpaced_json": unpaced_json, "paced_1m_raw": million, "paced_1m_raw_64b": million_small, "links_100_at_1khz": hundred_links, "links_100_at_1khz_zstd": hundred_links_zstd,
    });
    println!("record: {meta}");
    if let Ok(path) = std::env::var("ROBOWIRE_BENCH_META_RECORD") {
        std::fs::write(path, meta.to_string()).unwrap();
    }
}

/// `frames` copies of `frame` tapped by one thread over `links` links in turn, as fast as it can
/// or at `rate` frames/s (a busy wait to each frame's due time), into a recorder with its JSON
/// thread or without: what was written per second of the run, and what was dropped or skipped.
fn throughput(frame: &[u8], frames: u64, links: u16, rate: Option<f64>, json: bool) -> serde_json::Value {
    throughput_with(frame, frames, links, rate, RecorderOptions { json, ..Default::default() })
}

/// As [`throughput`], with `options`; also the file's size.
fn throughput_with(
    frame: &[u8],
    frames: u64,
    links: u16,
    rate: Option<f64>,
    options: RecorderOptions,
) -> serde_json::Value {
    let path = temp("throughput");
    let json = options.json;
    let recorder = Recorder::create_with(&path, "bench", options).unwrap();
    let taps: Vec<_> = (0..links).map(|n| recorder.link(&format!("dog{n}/high_level"), &HIGH_LEVEL)).collect();
    let start = Instant::now();
    for n in 0..frames {
        if let Some(rate) = rate {
            let due = Duration::from_secs_f64(n as f64 / rate);
            while start.elapsed() < due {
                std::hint::spin_loop();
            }
        }
        taps[(n % u64::from(links)) as usize].record(Direction::Received, frame);
    }
    let tapped_s = start.elapsed().as_secs_f64();
    let summary = recorder.finish().unwrap();
    let elapsed = start.elapsed().as_secs_f64();
    let bytes = std::fs::metadata(&path).map_or(0, |m| m.len());
    let _ = std::fs::remove_file(&path);
    json!({
        "offered": frames, "offered_per_s": frames as f64 / tapped_s, "written": summary.frames,
        "written_per_s": summary.frames as f64 / elapsed, "mb_per_s": bytes as f64 / elapsed / 1e6,
        "dropped": summary.dropped, "json_skipped": summary.json_skipped, "links": links, "json": json,
        "file_bytes": bytes,
    })
}
