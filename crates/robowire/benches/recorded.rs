//! What recording costs a stream, measured against the simulated devices through the facades,
//! each stream run alternately with its link recorded to MCAP (`robowire-record`) and without:
//!
//! - the ZSL-1 HighLevel command stream's send lateness (2 ms period, the client's own figures)
//!   against the simulated ZSL-1 (UDP);
//! - the KMC driver's 100 Hz stream (serial, on a pty);
//! - the spline daemon simulator's 1 kHz stream (shared memory);
//! - the ZSL-1 stream again, its link streamed live (`robowire-live`, every frame let through)
//!   to a viewer that subscribed to everything and then reads nothing, beside the same live view
//!   with no viewer.
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

/// A viewer that subscribes to every channel of the live view at `addr` and then reads nothing:
/// the WebSocket handshake and Foxglove's `subscribe` by hand, on a blocking socket.
fn stalled_viewer(addr: std::net::SocketAddr) -> std::net::TcpStream {
    use std::io::{BufRead, BufReader, Read, Write};
    let mut socket = std::net::TcpStream::connect(addr).unwrap();
    // A small window: it fills sooner than the kernel's autotuned one.
    rustix::net::sockopt::set_socket_recv_buffer_size(&socket, 4096).unwrap();
    let request = format!(
        "GET / HTTP/1.1\r\nHost: {addr}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\
         Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\
         Sec-WebSocket-Protocol: foxglove.sdk.v1\r\n\r\n"
    );
    socket.write_all(request.as_bytes()).unwrap();
    let mut reader = BufReader::new(socket.try_clone().unwrap());
    let mut line = String::new();
    while line != "\r\n" {
        line.clear();
        reader.read_line(&mut line).unwrap();
    }
    // Server frames are unmasked: read text frames until an advertisement names channels.
    let mut ids = Vec::new();
    while ids.is_empty() {
        let mut head = [0u8; 2];
        reader.read_exact(&mut head).unwrap();
        let len = match head[1] & 0x7F {
            126 => {
                let mut b = [0u8; 2];
                reader.read_exact(&mut b).unwrap();
                u64::from(u16::from_be_bytes(b))
            }
            127 => {
                let mut b = [0u8; 8];
                reader.read_exact(&mut b).unwrap();
                u64::from_be_bytes(b)
            }
            n => u64::from(n),
        };
        let mut payload = vec![0; usize::try_from(len).unwrap()];
        reader.read_exact(&mut payload).unwrap();
        let Ok(message) = serde_json::from_slice::<serde_json::Value>(&payload) else { continue };
        if message["op"] == "advertise" {
            ids.extend(message["channels"].as_array().unwrap().iter().filter_map(|c| c["id"].as_u64()));
        }
    }
    let subscriptions: Vec<_> = ids.iter().enumerate().map(|(i, id)| json!({ "id": i, "channelId": id })).collect();
    let subscribe = json!({ "op": "subscribe", "subscriptions": subscriptions }).to_string();
    // A client frame: text, masked with a zero key (the payload as it is).
    let mut frame = vec![0x81, 0xFE];
    frame.extend_from_slice(&u16::try_from(subscribe.len()).unwrap().to_be_bytes());
    frame.extend_from_slice(&[0; 4]);
    frame.extend_from_slice(subscribe.as_bytes());
    socket.write_all(&frame).unwrap();
    socket
}

/// The ZSL-1 stream's lateness over `seconds` with its link streamed live at 1 kHz (every
/// frame), to a stalled viewer or to none: (p50 µs, p99 µs, messages dropped for the viewer).
fn live_stream(runtime: &tokio::runtime::Runtime, seconds: f64, stalled: bool) -> (u32, u32, u64) {
    use robowire_live::{LiveOptions, LiveServer};
    let sim = Zsl1Sim::spawn(Zsl1SimConfig::loopback()).unwrap();
    let options = LiveOptions { rate_hz: 1000.0, ..LiveOptions::default() };
    let live = LiveServer::start("127.0.0.1:0".parse().unwrap(), options).unwrap();
    let lateness = runtime.block_on(async {
        let options = ClientOptions {
            dog: sim.high_level_addr(),
            ..ClientOptions::high_level([127, 0, 0, 1].into(), 0, [127, 0, 0, 1].into())
        }
        .with_tap(live.links().link("zsl1/high_level", &HIGH_LEVEL));
        let zsl1 = HighLevel::open(options).unwrap();
        assert!(zsl1.wait_connected(Duration::from_secs(2)).await);
        let viewer = stalled.then(|| {
            let addr = live.addr();
            std::thread::spawn(move || stalled_viewer(addr)).join().unwrap()
        });
        tokio::time::sleep(Duration::from_secs_f64(seconds)).await;
        let lateness = zsl1.stats().stream_lateness;
        zsl1.close();
        drop(viewer);
        lateness
    });
    let dropped = live.stop().viewers.iter().map(|v| v.dropped).sum();
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
    let (mut alone, mut stalled, mut viewer_dropped) = (Vec::new(), Vec::new(), 0);
    for _ in 0..rounds {
        alone.push(live_stream(&runtime, seconds, false));
        let s = live_stream(&runtime, seconds, true);
        viewer_dropped += s.2;
        stalled.push(s);
    }
    let live = json!({
        "plain_p50_us": median(&mut alone, |r| r.0), "plain_p99_us": median(&mut alone, |r| r.1),
        "stalled_p50_us": median(&mut stalled, |r| r.0), "stalled_p99_us": median(&mut stalled, |r| r.1),
        "viewer_dropped": viewer_dropped,
    });
    let kmc = alternate(rounds, seconds, kmc_stream);
    let spline = alternate(rounds, seconds, spline_stream);
    let meta = json!({
        "lateness_plain_p50_us": median(&mut plain, |r| r.0), "lateness_plain_p99_us": median(&mut plain, |r| r.1),
        "lateness_recorded_p50_us": median(&mut recorded, |r| r.0), "lateness_recorded_p99_us": median(&mut recorded, |r| r.1),
        "stream_frames_dropped": dropped, "kmc_stream": kmc, "spline_stream": spline, "live_stream": live,
    });
    println!("recorded: {meta}");
    if let Ok(path) = std::env::var("ROBOWIRE_BENCH_META_RECORDED") {
        std::fs::write(path, meta.to_string()).unwrap();
    }
}
