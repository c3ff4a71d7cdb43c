//! The stalled-reader rows: a `unitree::LowLevel` client's 500 Hz LowCmd stream while a
//! RELIABLE reader of `rt/lowcmd` (this program run again) is healthy, stops taking, is stopped
//! for 1 s and for 5 s; beside a bare `clock_nanosleep` loop at the same rate on the same CPU.

use std::io::{BufRead, BufReader, Write};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use robowire_dds::qos::Qos;
use robowire_dds::{Participant, ParticipantOptions};
use serde_json::{Value, json};
use unitree::{Device, JointCommand, LowLevel, LowLevelOptions};
use unitree_proto::{LowCmd, Message};

use crate::{CLIENT_CPU, PEER_CPU};

/// Set in the environment of this program run again as the reliable LowCmd reader.
pub(crate) const READER_ENV: &str = "ROBOWIRE_BENCH_DDS_RELIABLE_READER";
/// The reader's QoS: reliable (it acknowledges, so the writer keeps what it has not), keep last 1.
const RELIABLE_READER: Qos = Qos { reliable: true, ..Qos::READER };
/// The long stall: far more samples than any send window would hold (2500 at 500 Hz); the
/// writer keeps the newest only.
const LONG_STALL: Duration = Duration::from_secs(5);
/// The Go2's LowCmd period.
const LOWCMD_PERIOD: Duration = Duration::from_millis(2);

/// This program as the reader: a RELIABLE reader of `rt/lowcmd` on the peer's CPU taking every
/// sample. It prints `receiving` at its first sample; on stdin, `stop` stops taking (its
/// participant still receives and acknowledges), `go` takes again; at the end of stdin it prints
/// `taken N` and returns.
pub(crate) fn reliable_reader() {
    robowire_rt::pin_current_thread(PEER_CPU).expect("pinning (needs 2 CPUs)");
    let taking = Arc::new(AtomicBool::new(true));
    let done = Arc::new(AtomicBool::new(false));
    std::thread::spawn({
        let (taking, done) = (taking.clone(), done.clone());
        move || {
            for line in std::io::stdin().lock().lines().map_while(Result::ok) {
                taking.store(line.trim() != "stop", Ordering::Relaxed);
            }
            done.store(true, Ordering::Relaxed);
        }
    });
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    let taken = runtime.block_on(async {
        let participant = Participant::new(ParticipantOptions::new(0, Some("lo"))).expect("participant");
        let mut reader = participant.reader::<LowCmd>(LowCmd::TOPIC, RELIABLE_READER).expect("reader");
        let mut taken = 0u64;
        while !done.load(Ordering::Relaxed) {
            if !taking.load(Ordering::Relaxed) {
                tokio::time::sleep(Duration::from_millis(1)).await;
                continue;
            }
            // Bounded, so that `stop` and the end are seen while nothing arrives.
            if let Ok(sample) = tokio::time::timeout(Duration::from_millis(10), reader.recv()).await {
                sample.expect("the reader");
                taken += 1;
                if taken == 1 {
                    println!("receiving");
                }
            }
        }
        taken
    });
    println!("taken {taken}");
}

/// What the reader does in the middle of a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stall {
    /// Nothing: it takes every sample.
    None,
    /// It stops taking samples (its participant still acknowledges them).
    StopTaking,
    /// Its process is stopped: it neither reads nor acknowledges.
    StopProcess,
}

/// The reader process, started.
struct ReaderProcess {
    child: Child,
    stdin: Option<ChildStdin>,
    lines: mpsc::Receiver<String>,
}

impl ReaderProcess {
    fn spawn() -> Self {
        let mut child = Command::new(std::env::current_exe().expect("this program"))
            .env(READER_ENV, "1")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .expect("the reader process");
        let stdout = child.stdout.take().expect("its stdout");
        let (tx, lines) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                let _ = tx.send(line);
            }
        });
        Self { stdin: child.stdin.take(), child, lines }
    }

    /// The first line of the reader that starts with `prefix`; panics after `timeout`.
    fn line(&self, prefix: &str, timeout: Duration) -> String {
        let end = Instant::now() + timeout;
        loop {
            let left = end.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left) {
                Ok(line) if line.starts_with(prefix) => return line,
                Ok(_) => {}
                Err(e) => panic!("the reader said no `{prefix}` within {timeout:?}: {e}"),
            }
        }
    }

    fn say(&mut self, word: &str) {
        writeln!(self.stdin.as_mut().expect("the reader's stdin"), "{word}").expect("telling the reader");
    }

    fn signal(&self, signal: rustix::process::Signal) {
        let pid = rustix::process::Pid::from_raw(self.child.id() as i32).expect("a pid");
        rustix::process::kill_process(pid, signal).expect("signalling the reader");
    }

    fn stall(&mut self, stall: Stall) {
        match stall {
            Stall::None => {}
            Stall::StopTaking => self.say("stop"),
            Stall::StopProcess => self.signal(rustix::process::Signal::STOP),
        }
    }

    fn resume(&mut self, stall: Stall) {
        match stall {
            Stall::None => {}
            Stall::StopTaking => self.say("go"),
            Stall::StopProcess => self.signal(rustix::process::Signal::CONT),
        }
    }

    /// Ends the reader: the samples it took.
    fn finish(mut self) -> u64 {
        drop(self.stdin.take());
        let line = self.line("taken ", Duration::from_secs(10));
        let _ = self.child.wait();
        line["taken ".len()..].parse().expect("a count")
    }
}

fn summary(s: &robowire_core::timing::LatenessSummary) -> Value {
    json!({"count": s.count, "p50_us": s.p50_us, "p99_us": s.p99_us, "max_us": s.max_us})
}

/// A Go2 client's LowCmd stream against the reader process: `before`, then the reader's `stall`
/// for `stall_for`, then `after`. The client's send lateness (over its ring: the last 4096
/// ticks, 8.2 s; max since the start), its counters, and the samples the reader took.
fn lowcmd_stream(stall: Stall, before: Duration, stall_for: Duration, after: Duration) -> Value {
    lowcmd_stream_recorded(stall, before, stall_for, after, false)
}

/// As [`lowcmd_stream`], the client's low-level link recorded to MCAP if `record`.
fn lowcmd_stream_recorded(stall: Stall, before: Duration, stall_for: Duration, after: Duration, record: bool) -> Value {
    let capture = std::env::temp_dir().join(format!("robowire-bench-dds-{}.mcap", std::process::id()));
    let recorder = record.then(|| robowire_record::Recorder::create(&capture, "bench").expect("a recorder"));
    let mut reader = ReaderProcess::spawn();
    let options = LowLevelOptions {
        low_level_tap: recorder.as_ref().map(|r| r.link("go2/low_level", &unitree_proto::description::GO2_LOW_LEVEL)),
        ..LowLevelOptions::on(Some("lo"), 0)
    };
    let client = LowLevel::<unitree::Go2>::open(options).expect("Go2 client");
    client.set_joints(&[JointCommand::hold(0.0, 0.0, 1.0); 12]).expect("a command");
    reader.line("receiving", Duration::from_secs(30));
    std::thread::sleep(before);
    reader.stall(stall);
    std::thread::sleep(stall_for);
    reader.resume(stall);
    std::thread::sleep(after);
    let stats = client.stats();
    drop(client);
    let taken = reader.finish();
    let recorded = recorder.map(|r| r.finish().expect("the capture"));
    let _ = std::fs::remove_file(&capture);
    let lateness = stats.send_lateness;
    println!(
        "LowCmd stream, reader {stall:?} for {stall_for:?}: lateness p50 {} p99 {} max {} µs; sent {}, dropped {}, write drops {}; reader took {taken}",
        lateness.p50_us, lateness.p99_us, lateness.max_us, stats.commands_sent, stats.lowcmd.dropped, stats.write_drops
    );
    json!({
        "stall": format!("{stall:?}"),
        "stall_s": stall_for.as_secs_f64(),
        "run_s": (before + stall_for + after).as_secs_f64(),
        "lateness": summary(&lateness),
        "sent": stats.commands_sent,
        "written": stats.lowcmd.samples,
        "dropped": stats.lowcmd.dropped,
        "write_errors": stats.lowcmd.write_errors,
        "reader_took": taken,
        "recorded": recorded.map(|r| json!({"frames": r.frames, "dropped": r.dropped})),
    })
}

/// The baseline: a bare thread on the client's CPU sleeping with
/// `clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME)` to each deadline of a `period` grid for
/// `run`, its lateness as the stream's is summarised.
fn bare_loop(period: Duration, run: Duration) -> Value {
    let summary_of = std::thread::spawn(move || {
        robowire_rt::pin_current_thread(CLIENT_CPU).expect("pinning (needs 2 CPUs)");
        robowire_rt::set_fine_timer_slack();
        let mut ring: Box<robowire_core::timing::LatenessRing<4096>> =
            Box::new(robowire_core::timing::LatenessRing::new());
        let start = robowire_rt::now();
        let end = start + run;
        let mut next = start + period;
        while next < end {
            let ns = next.as_nanos();
            let at =
                rustix::time::Timespec { tv_sec: (ns / 1_000_000_000) as i64, tv_nsec: (ns % 1_000_000_000) as i64 };
            let _ = rustix::thread::clock_nanosleep_absolute(rustix::thread::ClockId::Monotonic, &at);
            ring.record(robowire_rt::stats::micros(robowire_rt::now().saturating_duration_since(next)));
            next = next + period;
        }
        ring.summary()
    })
    .join()
    .expect("the baseline loop");
    let lateness = summary(&summary_of);
    println!("bare clock_nanosleep loop, 500 Hz, {run:?}: {lateness}");
    json!({"run_s": run.as_secs_f64(), "lateness": lateness})
}

/// The stalled-reader cases, each against a fresh client and reader: healthy, stops taking 1 s,
/// stopped 1 s (each over `seconds`), stopped [`LONG_STALL`]; and a bare loop as long as a run.
pub(crate) fn stalled_reader(seconds: u32) -> Value {
    let stall = Duration::from_secs(1);
    let side = (Duration::from_secs(u64::from(seconds)).saturating_sub(stall) / 2).max(Duration::from_secs(1));
    let healthy = lowcmd_stream(Stall::None, side, stall, side);
    let bare = bare_loop(LOWCMD_PERIOD, side * 2 + stall);
    let recorded = lowcmd_stream_recorded(Stall::None, side, stall, side, true);
    let stop_taking = lowcmd_stream(Stall::StopTaking, side, stall, side);
    let stopped = lowcmd_stream(Stall::StopProcess, side, stall, side);
    let stopped_long = lowcmd_stream(Stall::StopProcess, Duration::from_secs(1), LONG_STALL, Duration::from_secs(2));
    json!({
        "healthy": healthy,
        "bare_loop": bare,
        "healthy_recorded": recorded,
        "stops_taking": stop_taking,
        "stopped": stopped,
        "stopped_long": stopped_long,
    })
}
