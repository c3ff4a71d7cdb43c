//! The Go2 and the G1 over DDS on loopback (a private network namespace), beside CycloneDDS's own
//! `ddsperf` measured in the same run with a payload of the same size (812 bytes; 1000 for the
//! G1's 1004-byte HG LowCmd), the two taking turns (a slice each per round):
//!
//! - round trip: a LowCmd published → the LowState answer received, through the simulated Go2
//!   or G1 (which answers each applied LowCmd at once; its periodic stream slowed to 1 Hz, as
//!   ddsperf's pong has none), one at a time; beside `ddsperf ping size N`
//!   against `ddsperf pong`, whose printed latency is half the round trip (it divides by 2), so
//!   it is doubled here;
//! - one way: a LowCmd written (encode, CRC, RTPS) → decoded and verified at a reader in
//!   another participant, beside `ddsperf`'s half round trip.
//!
//! - a stalled reader: the send lateness of a `unitree::LowLevel` client's 500 Hz LowCmd stream
//!   (`set_joints` latched once, nothing else) while a RELIABLE reader of `rt/lowcmd`, a process
//!   of its own (this program run again), is healthy; stops taking samples for 1 s (its
//!   participant still acknowledges what arrives: acknowledgements come from its background
//!   thread, not from takes); is stopped (`SIGSTOP`: it neither reads nor acknowledges) for 1 s;
//!   is stopped for 5 s (2500 samples). The client's writer (`Qos::STREAM_WRITER`, keep last 1)
//!   never waits: a reader that does not acknowledge holds back at most the newest sample, and
//!   there is no send window to fill however long it stalls. The stream's lateness is its
//!   wake-up lateness on each tick (a write that waited would make the next ticks late); beside
//!   it, a bare `clock_nanosleep` loop at the same rate on the same CPU in the same run (what the
//!   VM itself does to a sleeping thread's wake-ups).
//!
//! - with MuJoCo (feature `mujoco`): the Go2 round trip with the simulator's 500 Hz stream on,
//!   its body the kinematic joint model, then physics (1 kHz MuJoCo on the stream's thread).
//!
//! Each side has a CPU of its own (client CPU 0, peer CPU 1), ddsperf's as ours. Figures to
//! `ROBOWIRE_BENCH_META_DDS` for `cargo xtask bench`. Runs where loopback carries multicast
//! (`robowire_dds::netns`); needs `ddsperf` (Debian's cyclonedds-tools).

use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use robowire_core::cdr::CdrType;
use robowire_dds::qos::Qos;
use robowire_dds::{Participant, ParticipantOptions};
use robowire_sim::g1::{G1Sim, G1SimConfig};
use robowire_sim::go2::{Go2Sim, Go2SimConfig};
use serde_json::{Value, json};
use unitree_proto::api::motion_switcher;
use unitree_proto::{HgLowCmd, HgLowState, LowCmd, LowState, Message};

mod stalled;

use stalled::{READER_ENV, reliable_reader, stalled_reader};

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

/// `ddsperf ping size SIZE` (CPU 0) against `ddsperf pong` (CPU 1) for `seconds`: its per-second
/// p50 and p99 lines, µs (its figures: half the round trip). An unpinned ping
/// wanders onto the pong's CPU, where a round trip costs no cross-CPU wake-up (half of it ~9 µs
/// on the development VM against ~20-35 µs across CPUs): both are pinned, as ours are.
fn ddsperf(seconds: u32, size: usize) -> (Vec<f64>, Vec<f64>) {
    let mut pong = Command::new("taskset")
        .args(["-c", &PEER_CPU.to_string(), "ddsperf", "-D", &(seconds + 3).to_string(), "pong"])
        .stdout(Stdio::null())
        .spawn()
        .expect("ddsperf (apt install cyclonedds-tools)");
    std::thread::sleep(Duration::from_millis(300));
    let out = Command::new("taskset")
        .args(["-c", &CLIENT_CPU.to_string(), "ddsperf", "-D", &seconds.to_string(), "ping", "size", &size.to_string()])
        .output()
        .expect("ddsperf");
    let _ = pong.kill();
    let _ = pong.wait();
    let text = String::from_utf8_lossy(&out.stdout);
    let field = |line: &str, key: &str| {
        let rest = &line[line.find(key)? + key.len()..];
        rest.trim_start().split("us").next()?.trim().parse::<f64>().ok()
    };
    let (mut p50s, mut p99s) = (Vec::new(), Vec::new());
    let size = format!("size {size}");
    for line in text.lines().filter(|l| l.contains(&size) && l.contains("50%")) {
        if let (Some(p50), Some(p99)) = (field(line, "50%"), field(line, "99%")) {
            p50s.push(p50);
            p99s.push(p99);
        }
    }
    assert!(!p50s.is_empty(), "no ddsperf latency lines:\n{text}");
    (p50s, p99s)
}

/// A round's slice of ddsperf, s: its first second is often lost to discovery.
const DDSPERF_SLICE_S: u32 = 3;

/// The simulators' settings for round trips: each applied LowCmd answered at once; the 500 Hz
/// stream slowed to 1 Hz so that the round trip is the answer alone, as ddsperf's pong is.
const STATE_PERIOD: Duration = Duration::from_secs(1);

/// A Go2 LowCmd tagged by its `reserve` (the simulator echoes it in its answer).
fn tagged(tag: u32) -> LowCmd {
    let mut cmd = LowCmd::default();
    cmd.reserve = tag.into();
    cmd
}

/// Round trips through the simulated Go2, its state stream at 1 Hz.
async fn go2_round_trips(seconds: u32, taker: Taker) -> Vec<f64> {
    go2_round_trips_beside(seconds, taker, Go2SimConfig { state_period: STATE_PERIOD, ..Go2SimConfig::default() }).await
}

/// Round trips through the simulated Go2 of `config` (its participant and answers set here).
async fn go2_round_trips_beside(seconds: u32, taker: Taker, config: Go2SimConfig) -> Vec<f64> {
    let participant = ParticipantOptions::new(0, Some("lo"));
    let config = Go2SimConfig { participant, answer_lowcmd: true, ..config };
    let _sim = on_cpu(PEER_CPU, || Go2Sim::spawn(config).expect("simulator"));
    round_trips::<LowCmd, LowState>(seconds, taker, tagged, |s| s.reserve.get()).await
}

/// With MuJoCo (feature `mujoco`): round trips through the Go2 with its 500 Hz stream on, its
/// body the kinematic joint model and then physics (1 kHz MuJoCo on the stream's thread): what
/// the physics costs a client.
#[cfg(feature = "mujoco")]
async fn go2_physics_round_trips(seconds: u32) -> Value {
    let kinematic = percentiles(go2_round_trips_beside(seconds, Taker::Listener, Go2SimConfig::default()).await);
    let physics = Some(robowire_sim::physics::PhysicsOptions::default());
    let physics = percentiles(
        go2_round_trips_beside(seconds, Taker::Listener, Go2SimConfig { physics, ..Go2SimConfig::default() }).await,
    );
    println!(
        "Go2 round trip, 500 Hz stream: kinematic p50 {:.1} p99 {:.1} µs, physics p50 {:.1} p99 {:.1} µs",
        kinematic.0, kinematic.1, physics.0, physics.1
    );
    json!({"kinematic_us": {"p50": kinematic.0, "p99": kinematic.1}, "physics_us": {"p50": physics.0, "p99": physics.1}})
}

/// Round trips through the simulated 29-dof G1 (mode_machine 5; `reserve[0]` tags).
async fn g1_round_trips(seconds: u32) -> Vec<f64> {
    let participant = ParticipantOptions::new(0, Some("lo"));
    let config = G1SimConfig { participant, answer_lowcmd: true, state_period: STATE_PERIOD, ..G1SimConfig::default() };
    let _sim = on_cpu(PEER_CPU, || G1Sim::spawn(config).expect("simulator"));
    let tagged = |tag: u32| {
        let mut cmd = HgLowCmd::default();
        cmd.mode_machine = unitree_proto::g1::G1Variant::Dof29.mode_machine();
        cmd.reserve[0] = tag.into();
        cmd
    };
    round_trips::<HgLowCmd, HgLowState>(seconds, Taker::Listener, tagged, |s| s.reserve[0].get()).await
}

/// After ReleaseMode, `seconds` of round trips one at a time: the command `tagged(n)` published,
/// the first state with `tag_of(state) >= n` taken by `taker`.
async fn round_trips<C, S>(
    seconds: u32,
    taker: Taker,
    tagged: impl Fn(u32) -> C,
    tag_of: impl Fn(&S) -> u32 + Send + 'static,
) -> Vec<f64>
where
    C: Message + CdrType + Send + Sync + 'static,
    S: Message + CdrType + Send + Sync + 'static,
{
    let us = Participant::new(ParticipantOptions::new(0, Some("lo"))).expect("participant");
    let switcher = unitree::services::ServiceClient::new(&us, motion_switcher::SERVICE).unwrap();
    let released = switcher.call(motion_switcher::RELEASE_MODE, "{}", Duration::from_secs(20)).await.unwrap();
    assert_eq!(released.code, 0);
    let writer = us.writer::<C>(C::TOPIC, Qos::WRITER).unwrap();
    let reader = us.reader::<S>(S::TOPIC, Qos::READER).unwrap();
    let end = Instant::now() + Duration::from_secs(u64::from(seconds));
    match taker {
        Taker::Listener => {
            let (arrivals, arrived) = mpsc::sync_channel(64);
            let _listener = reader.listen(move |s| {
                let _ = arrivals.try_send((tag_of(&s.value), Instant::now()));
            });
            timed(end, |tag| writer.write(tagged(tag)).unwrap(), &arrived)
        }
        Taker::Task => task_round_trips(end, |tag| writer.write(tagged(tag)).unwrap(), reader, tag_of).await,
    }
}

/// Who takes the answers: a listener on the participant's background thread, which notes the
/// time the answer is handed over (as `ddsperf ping`'s listener does), or a task woken by it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Taker {
    Listener,
    Task,
}

/// Until `end`, one at a time: `send(n)`, then the first `(tag, time)` with `tag >= n` from
/// `arrived` (a listener's); the times between, µs. The first 50 are lost to discovery, and a
/// lost one (200 ms without) is not a sample.
fn timed(end: Instant, send: impl Fn(u32), arrived: &mpsc::Receiver<(u32, Instant)>) -> Vec<f64> {
    let mut samples = Vec::new();
    let mut tag = 0u32;
    while Instant::now() < end {
        tag += 1;
        let sent = Instant::now();
        send(tag);
        let deadline = sent + Duration::from_millis(200);
        let at = loop {
            match arrived.recv_timeout(deadline.saturating_duration_since(Instant::now())) {
                Ok((t, at)) if t >= tag => break Some(at),
                Ok(_) => {}
                Err(_) => break None,
            }
        };
        if let Some(at) = at
            && tag > 50
        {
            samples.push(at.duration_since(sent).as_secs_f64() * 1e6);
        }
    }
    samples
}

/// As [`timed`], the answers taken by this task with `Reader::recv` (the background thread
/// wakes it).
async fn task_round_trips<S: CdrType + Send + 'static>(
    end: Instant,
    send: impl Fn(u32),
    mut reader: robowire_dds::Reader<S>,
    tag_of: impl Fn(&S) -> u32,
) -> Vec<f64> {
    let mut samples = Vec::new();
    let mut tag = 0u32;
    while Instant::now() < end {
        tag += 1;
        let sent = Instant::now();
        send(tag);
        let answered = tokio::time::timeout(Duration::from_millis(200), async {
            loop {
                match reader.recv().await {
                    Ok(s) if tag_of(&s.value) >= tag => return,
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

/// A LowCmd written → decoded and verified at a listener of another participant (the time it is
/// handed over, as `ddsperf`'s listener notes it).
fn one_way(seconds: u32) -> Vec<f64> {
    let lo = ParticipantOptions::new(0, Some("lo"));
    let a = Participant::new(lo.clone()).unwrap();
    let b = on_cpu(PEER_CPU, || Participant::new(lo).unwrap());
    let writer = a.writer::<LowCmd>(LowCmd::TOPIC, Qos::WRITER).unwrap();
    let reader = b.reader::<LowCmd>(LowCmd::TOPIC, Qos::READER).unwrap();
    let (arrivals, arrived) = mpsc::sync_channel(64);
    let _listener = reader.listen(move |s| {
        let _ = arrivals.try_send((s.value.reserve.get(), Instant::now()));
    });
    let end = Instant::now() + Duration::from_secs(u64::from(seconds));
    timed(end, |tag| writer.write(tagged(tag)).unwrap(), &arrived)
}

fn main() {
    // `cargo bench` passes harness arguments: not ours.
    if std::env::var_os(READER_ENV).is_some() {
        return reliable_reader();
    }
    let quick = std::env::var_os("ROBOWIRE_BENCH_QUICK").is_some();
    let seconds = if quick { 3 } else { 10 };
    // The round trips: `rounds` slices of `slice_s` each.
    let (rounds, slice_s) = if quick { (3, 1) } else { (5, 2) };
    let meta = robowire_dds::netns::for_this_process().run(|| {
        robowire_rt::pin_current_thread(CLIENT_CPU).expect("pinning (needs 2 CPUs)");
        let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
        // ddsperf and ours take turns, each of ours right after ddsperf's slice of its size, so
        // that the machine's slow and fast moments fall on both alike.
        let (mut half, mut hg_half) = ((Vec::new(), Vec::new()), (Vec::new(), Vec::new()));
        let (mut trips, mut task_trips, mut g1_trips) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..rounds {
            let (p50s, p99s) = ddsperf(DDSPERF_SLICE_S, 812);
            half.0.extend(p50s);
            half.1.extend(p99s);
            trips.extend(runtime.block_on(go2_round_trips(slice_s, Taker::Listener)));
            let (p50s, p99s) = ddsperf(DDSPERF_SLICE_S, 1000);
            hg_half.0.extend(p50s);
            hg_half.1.extend(p99s);
            g1_trips.extend(runtime.block_on(g1_round_trips(slice_s)));
            task_trips.extend(runtime.block_on(go2_round_trips(slice_s, Taker::Task)));
        }
        let median = |lines: Vec<f64>| percentiles(lines).0;
        let (half50, half99) = (median(half.0), median(half.1));
        let (hg_half50, hg_half99) = (median(hg_half.0), median(hg_half.1));
        let ways = one_way(seconds);
        let stalled = stalled_reader(seconds);
        #[cfg(feature = "mujoco")]
        let physics = runtime.block_on(go2_physics_round_trips(seconds));
        #[cfg(not(feature = "mujoco"))]
        let physics = Value::Null;
        let ((r50, r99), (w50, w99)) = (percentiles(trips.clone()), percentiles(ways.clone()));
        let (g50, g99) = percentiles(g1_trips.clone());
        let (t50, t99) = percentiles(task_trips.clone());
        println!("round trip, the answer taken by a task: p50 {t50:.1} p99 {t99:.1} µs ({} samples)", task_trips.len());
        println!(
            "G1 round trip p50 {g50:.1} p99 {g99:.1} µs ({} samples); ddsperf 1000 B half round trip p50 {hg_half50:.1} p99 {hg_half99:.1} µs",
            g1_trips.len()
        );
        println!(
            "round trip p50 {r50:.1} p99 {r99:.1} µs ({} samples); one way p50 {w50:.1} p99 {w99:.1} µs; ddsperf half round trip p50 {half50:.1} p99 {half99:.1} µs",
            trips.len()
        );
        json!({
            "seconds": seconds,
            "round_trip_rounds": rounds,
            "round_trip_seconds": rounds * slice_s,
            "round_trip_us": {"p50": r50, "p99": r99, "count": trips.len()},
            "round_trip_task_us": {"p50": t50, "p99": t99, "count": task_trips.len()},
            "one_way_us": {"p50": w50, "p99": w99, "count": ways.len()},
            "ddsperf_half_round_trip_us": {"p50": half50, "p99": half99},
            "g1_round_trip_us": {"p50": g50, "p99": g99, "count": g1_trips.len()},
            "ddsperf_1000_half_round_trip_us": {"p50": hg_half50, "p99": hg_half99},
            "stalled_reader": stalled,
            "go2_500hz_round_trip": physics,
        })
    })
    .unwrap_or_else(|e| panic!("DDS on one machine needs multicast on lo: {e}"));
    println!("{meta}");
    if let Ok(path) = std::env::var("ROBOWIRE_BENCH_META_DDS") {
        std::fs::write(path, meta.to_string()).expect("writing the bench metadata");
    }
}
