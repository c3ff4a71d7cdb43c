//! The Go2 over DDS on loopback (a private network namespace), beside CycloneDDS's own `ddsperf`
//! measured in the same run with a payload of the same size (812 bytes):
//!
//! - round trip: a LowCmd published → the LowState answer received, through the simulated Go2
//!   (which answers each accepted LowCmd at once; its periodic stream slowed to 1 Hz, as ddsperf's
//!   pong has none), one at a time; beside `ddsperf ping size 812`
//!   against `ddsperf pong`, whose printed latency is half the round trip (it divides by 2), so
//!   it is doubled here;
//! - one way: a LowCmd written (encode, CRC, rustdds) → decoded and verified at a reader in
//!   another participant, beside `ddsperf`'s half round trip.
//!
//! Each side has a CPU of its own (client CPU 0, peer CPU 1), ddsperf's as ours. Figures to
//! `ROBOWIRE_BENCH_META_DDS` for `cargo xtask bench`. Runs where loopback carries multicast
//! (`robowire_dds::netns`); needs `ddsperf` (Debian's cyclonedds-tools).

use std::process::Command;
use std::time::{Duration, Instant};

use lowcmd_proto::api::motion_switcher;
use lowcmd_proto::{LowCmd, LowState, Message};
use robowire_dds::qos::Qos;
use robowire_dds::{Participant, ParticipantOptions};
use robowire_sim::go2::{Go2Sim, Go2SimConfig};
use serde_json::json;

/// Both sides get a CPU of their own, ddsperf's and ours alike: the client side on CPU 0, the
/// peer (pong, the simulator, the second participant) on CPU 1.
const CLIENT_CPU: usize = 0;
const PEER_CPU: usize = 1;

/// Runs `f` on a thread pinned to `cpu`; threads it starts (DDS's, a simulator's) stay there.
fn on_cpu<T: Send>(cpu: usize, f: impl FnOnce() -> T + Send) -> T {
    std::thread::scope(|s| {
        s.spawn(|| {
            robowire_rt::pin_current_thread(cpu).expect("pinning (needs 2 CPUs)");
            f()
        })
        .join()
        .expect("the pinned thread")
    })
}

/// p50 and p99 of `samples`, µs.
fn percentiles(mut samples: Vec<f64>) -> (f64, f64) {
    samples.sort_by(f64::total_cmp);
    let at = |p: usize| samples[((p * samples.len()).div_ceil(100)).saturating_sub(1).min(samples.len() - 1)];
    (at(50), at(99))
}

/// `ddsperf ping size 812` against `ddsperf pong` for `seconds`: the medians of its per-second
/// p50 and p99 lines, µs (its figures: half the round trip).
fn ddsperf(seconds: u32) -> (f64, f64) {
    let mut pong = Command::new("taskset")
        .args(["-c", &PEER_CPU.to_string(), "ddsperf", "-D", &(seconds + 3).to_string(), "pong"])
        .stdout(std::process::Stdio::null())
        .spawn()
        .expect("ddsperf (apt install cyclonedds-tools)");
    std::thread::sleep(Duration::from_millis(300));
    let out =
        Command::new("ddsperf").args(["-D", &seconds.to_string(), "ping", "size", "812"]).output().expect("ddsperf");
    let _ = pong.kill();
    let _ = pong.wait();
    let text = String::from_utf8_lossy(&out.stdout);
    let field = |line: &str, key: &str| {
        let rest = &line[line.find(key)? + key.len()..];
        rest.trim_start().split("us").next()?.trim().parse::<f64>().ok()
    };
    let (mut p50s, mut p99s) = (Vec::new(), Vec::new());
    for line in text.lines().filter(|l| l.contains("size 812") && l.contains("50%")) {
        if let (Some(p50), Some(p99)) = (field(line, "50%"), field(line, "99%")) {
            p50s.push(p50);
            p99s.push(p99);
        }
    }
    assert!(!p50s.is_empty(), "no ddsperf latency lines:\n{text}");
    (percentiles(p50s).0, percentiles(p99s).0)
}

fn tagged(tag: u32) -> LowCmd {
    let mut cmd = LowCmd::default();
    cmd.reserve = tag.into();
    cmd
}

async fn round_trips(seconds: u32) -> Vec<f64> {
    let lo = ParticipantOptions::new(0, Some("lo"));
    // The simulator answers each LowCmd at once; its 500 Hz stream is slowed to 1 Hz so that the
    // round trip is the answer alone, as ddsperf's pong is.
    let config = Go2SimConfig {
        participant: lo.clone(),
        answer_lowcmd: true,
        state_period: Duration::from_secs(1),
        ..Go2SimConfig::default()
    };
    let _sim = on_cpu(PEER_CPU, || Go2Sim::spawn(config).expect("simulator"));
    let us = Participant::new(lo).expect("participant");
    let switcher = go2::services::ServiceClient::new(&us, motion_switcher::SERVICE).unwrap();
    let released = switcher.call(motion_switcher::RELEASE_MODE, "{}", Duration::from_secs(20)).await.unwrap();
    assert_eq!(released.code, 0);
    let writer = us.writer::<LowCmd>(LowCmd::TOPIC, Qos::WRITER).unwrap();
    let mut reader = us.reader::<LowState>(LowState::TOPIC, Qos::READER).unwrap();
    let mut samples = Vec::new();
    let end = Instant::now() + Duration::from_secs(u64::from(seconds));
    let mut tag = 0u32;
    while Instant::now() < end {
        tag += 1;
        let sent = Instant::now();
        writer.write(tagged(tag)).unwrap();
        let answered = tokio::time::timeout(Duration::from_millis(200), async {
            loop {
                match reader.recv().await {
                    Ok(s) if s.value.reserve.get() >= tag => return,
                    Ok(_) => {}
                    Err(e) => panic!("{e}"),
                }
            }
        })
        .await;
        // The first few are lost to discovery; a lost one is not a round trip.
        if answered.is_ok() && tag > 50 {
            samples.push(sent.elapsed().as_secs_f64() * 1e6);
        }
    }
    samples
}

async fn one_way(seconds: u32) -> Vec<f64> {
    let lo = ParticipantOptions::new(0, Some("lo"));
    let a = Participant::new(lo.clone()).unwrap();
    let b = on_cpu(PEER_CPU, || Participant::new(lo).unwrap());
    let writer = a.writer::<LowCmd>(LowCmd::TOPIC, Qos::WRITER).unwrap();
    let mut reader = b.reader::<LowCmd>(LowCmd::TOPIC, Qos::READER).unwrap();
    let mut samples = Vec::new();
    let end = Instant::now() + Duration::from_secs(u64::from(seconds));
    let mut tag = 0u32;
    while Instant::now() < end {
        tag += 1;
        let sent = Instant::now();
        writer.write(tagged(tag)).unwrap();
        let arrived = tokio::time::timeout(Duration::from_millis(200), async {
            loop {
                if reader.recv().await.is_ok_and(|s| s.value.reserve.get() == tag) {
                    return;
                }
            }
        })
        .await;
        if arrived.is_ok() && tag > 50 {
            samples.push(sent.elapsed().as_secs_f64() * 1e6);
        }
    }
    samples
}

fn main() {
    // `cargo bench` passes harness arguments: not ours.
    let seconds = if std::env::var_os("ROBOWIRE_BENCH_QUICK").is_some() { 3 } else { 10 };
    let meta = robowire_dds::netns::for_this_process().run(|| {
        let (half50, half99) = ddsperf(seconds);
        robowire_rt::pin_current_thread(CLIENT_CPU).expect("pinning (needs 2 CPUs)");
        let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
        let trips = runtime.block_on(round_trips(seconds));
        let ways = runtime.block_on(one_way(seconds));
        let ((r50, r99), (w50, w99)) = (percentiles(trips.clone()), percentiles(ways.clone()));
        println!(
            "round trip p50 {r50:.1} p99 {r99:.1} µs ({} samples); one way p50 {w50:.1} p99 {w99:.1} µs; ddsperf half round trip p50 {half50:.1} p99 {half99:.1} µs",
            trips.len()
        );
        json!({
            "seconds": seconds,
            "round_trip_us": {"p50": r50, "p99": r99, "count": trips.len()},
            "one_way_us": {"p50": w50, "p99": w99, "count": ways.len()},
            "ddsperf_half_round_trip_us": {"p50": half50, "p99": half99},
        })
    })
    .unwrap_or_else(|e| panic!("DDS on one machine needs multicast on lo: {e}"));
    println!("{meta}");
    if let Ok(path) = std::env::var("ROBOWIRE_BENCH_META_DDS") {
        std::fs::write(path, meta.to_string()).expect("writing the bench metadata");
    }
}
